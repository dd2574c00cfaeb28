"""The simulated world of a scene: a DIRECT pybullet world with the floor, the table, the robot and the
scene's objects built as bodies (containers as open boxes of a floor and four walls, the rest as solids),
sized and placed as `scene.py` says."""

from __future__ import annotations

import random
from pathlib import Path

import pybullet as p

from lmcr.robot.baxter import PEDESTAL_HEIGHT
from lmcr.robot.description import baxter_urdf
from lmcr.robot.household import HouseholdError, Receptacle, household, open_box
from lmcr.robot.scene import (
    CONTAINERS,
    TABLE_CENTRE,
    TABLE_SIZE,
    TABLE_TOP,
    TOOLS,
    WALL,
    Scene,
    height,
    solid_shape,
    world_xy,
)

# what holds a drawer or a lid where the hand left it: 3 newtons on a slide, 3 newton-metres on a hinge (a
# chest fridge's lid weighs under 0.5 N m held out flat; the hand pulls with up to 500 N)
JOINT_FRICTION = 3.0
ROLLING_RESISTANCE = 0.01  # of round food (spheres) on the table, metres: the lever of its contact patch


def _color(label: str) -> list[float]:
    rng = random.Random(label)
    return [rng.uniform(0.2, 0.9), rng.uniform(0.2, 0.9), rng.uniform(0.2, 0.9), 1.0]


def _container(label: str, x: float, y: float, z: float = TABLE_TOP) -> int:
    """An open box of a floor and four walls (a cup, a pot), or a household receptacle built from its
    parts (household.json) with its mass (0: fixed in place) and colour."""
    found = household().get(label)
    parts = found.parts if found else open_box(*CONTAINERS[label], wall=WALL)
    mass, colour = (found.mass, list(found.colour)) if found else (0.3, _color(label))
    return _boxes(parts, mass, colour, x, y, z)


def _tool(label: str, x: float, y: float, z: float = TABLE_TOP) -> int:
    """A tool built from its parts (household.json: a knife's handle and blade, a lid and its knob)."""
    tool = TOOLS[label]
    return _boxes(tool.parts, tool.mass, list(tool.colour), x, y, z)


def _boxes(parts: tuple, mass: float, colour: list[float], x: float, y: float, z: float) -> int:
    """One body of boxes (half extents, centre) in a frame at (x, y, z), the middle of its footprint."""
    col = p.createCollisionShapeArray(
        [p.GEOM_BOX] * len(parts), halfExtents=[h for h, _ in parts], collisionFramePositions=[c for _, c in parts]
    )
    vis = p.createVisualShapeArray(
        [p.GEOM_BOX] * len(parts),
        halfExtents=[h for h, _ in parts],
        visualFramePositions=[c for _, c in parts],
        rgbaColors=[colour] * len(parts),
    )
    return p.createMultiBody(mass, col, vis, [x, y, z])


def _solid(label: str, x: float, y: float, z: float = TABLE_TOP) -> int:
    shape = solid_shape(label)
    if shape[0] == "sphere":
        col = p.createCollisionShape(p.GEOM_SPHERE, radius=shape[1])
        vis = p.createVisualShape(p.GEOM_SPHERE, radius=shape[1], rgbaColor=_color(label))
    elif shape[0] == "cyl":
        col = p.createCollisionShape(p.GEOM_CYLINDER, radius=shape[1], height=shape[2])
        vis = p.createVisualShape(p.GEOM_CYLINDER, radius=shape[1], length=shape[2], rgbaColor=_color(label))
    else:
        half = [s / 2 for s in shape[1:]]
        col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half)
        vis = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=_color(label))
    body = p.createMultiBody(0.15, col, vis, [x, y, z + height(label) / 2 + 0.001])
    # real fruit and eggs do not roll on for ever: without rolling resistance a grazed sphere leaves the
    # table. They rest on a patch about a centimetre across, not a point: salt shaken onto an apple's top
    # off its middle rolled a 0.002-resisted sphere off under the grains (half of them then missed it).
    # Flat-bottomed things keep 0.002: a shaker that resists more is not nudged aside by a fish dipped in it
    resistance = ROLLING_RESISTANCE if shape[0] == "sphere" else 0.002
    p.changeDynamics(body, -1, rollingFriction=resistance, spinningFriction=resistance)
    return body


def _articulated(found: Receptacle, x: float, y: float) -> tuple[int, int, int]:
    """A receptacle described by a URDF (a drawer unit, a chest fridge), fixed when its mass is 0: its body,
    the link things go in (-1: the root) and the joint that opens it (-1 when it has no opening). The
    joint's motor is a little friction, so that a drawer or a lid stays where the hand leaves it."""
    body = p.loadURDF(str(found.urdf), [x, y, TABLE_TOP], useFixedBase=found.mass == 0)
    if found.opening is None:
        return body, -1, -1
    joints = {p.getJointInfo(body, j)[1].decode(): j for j in range(p.getNumJoints(body))}
    links = {p.getJointInfo(body, j)[12].decode(): j for j in range(p.getNumJoints(body))}
    links[p.getBodyInfo(body)[0].decode()] = -1
    if found.opening.joint not in joints or found.opening.link not in links:
        raise HouseholdError(f"{found.urdf}: has no joint {found.opening.joint!r} or link {found.opening.link!r}")
    joint = joints[found.opening.joint]
    p.setJointMotorControl2(body, joint, p.VELOCITY_CONTROL, targetVelocity=0, force=JOINT_FRICTION)
    return body, links[found.opening.link], joint


# how each kind of object is built (SceneObject.kind)
_MAKERS = {"container": _container, "tool": _tool, "bottle": _solid, "shaker": _solid, "food": _solid}


def build_world(scene: Scene, cache_dir: Path, urdf: Path | None = None) -> int:
    """Reset a DIRECT pybullet world with floor, table, robot (the official Baxter description at `urdf`,
    else ours) and the scene's objects; returns the robot."""
    p.resetSimulation()
    p.setGravity(0, 0, -9.81)
    p.setTimeStep(1 / 240)
    floor = p.createCollisionShape(p.GEOM_PLANE)
    p.createMultiBody(0, floor)
    half = [TABLE_SIZE[0] / 2, TABLE_SIZE[1] / 2, 0.02]
    scene.table = p.createMultiBody(
        0,
        p.createCollisionShape(p.GEOM_BOX, halfExtents=half),
        p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=[0.55, 0.4, 0.25, 1]),
        [TABLE_CENTRE[0], TABLE_CENTRE[1], TABLE_TOP - 0.02],
    )
    robot = p.loadURDF(str(baxter_urdf(cache_dir, urdf)), [0, 0, PEDESTAL_HEIGHT], useFixedBase=True)
    scene.bodies = {}
    for obj in scene.objects:
        x, y = world_xy(obj.xy)
        found = household().get(obj.shape)
        if found is not None and found.urdf is not None:
            obj.body, obj.link, obj.joint = _articulated(found, x, y)
        else:
            obj.body = _MAKERS[obj.kind](obj.shape, x, y)
        scene.bodies[obj.body] = obj
    if scene.holding is not None:
        x, y = world_xy(scene.holding.xy)
        scene.holding.body = _MAKERS[scene.holding.kind](scene.holding.shape, x, y, 0.0)  # on the floor
    for _ in range(120):  # let everything settle
        p.stepSimulation()
    return robot
