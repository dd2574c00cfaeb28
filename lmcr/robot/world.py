"""The simulated world of a scene: a DIRECT pybullet world with the floor, the table, the robot and the
scene's objects built as bodies (containers as open boxes of a floor and four walls, the rest as solids),
sized and placed as `scene.py` says."""

from __future__ import annotations

import random
from pathlib import Path

import pybullet as p

from lmcr.robot.baxter import PEDESTAL_HEIGHT
from lmcr.robot.description import baxter_urdf
from lmcr.robot.scene import CONTAINERS, TABLE_CENTRE, TABLE_SIZE, TABLE_TOP, Scene, height, solid_shape, world_xy

ROLLING_RESISTANCE = 0.01  # of round food (spheres) on the table, metres: the lever of its contact patch


def _color(label: str) -> list[float]:
    rng = random.Random(label)
    return [rng.uniform(0.2, 0.9), rng.uniform(0.2, 0.9), rng.uniform(0.2, 0.9), 1.0]


def _container(label: str, x: float, y: float, z: float = TABLE_TOP) -> int:
    w, d, h = CONTAINERS[label]
    t = 0.006  # wall thickness
    parts = [
        ([w / 2, d / 2, t / 2], [0, 0, t / 2]),
        ([t / 2, d / 2, h / 2], [w / 2 - t / 2, 0, h / 2]),
        ([t / 2, d / 2, h / 2], [-w / 2 + t / 2, 0, h / 2]),
        ([w / 2, t / 2, h / 2], [0, d / 2 - t / 2, h / 2]),
        ([w / 2, t / 2, h / 2], [0, -d / 2 + t / 2, h / 2]),
    ]
    col = p.createCollisionShapeArray(
        [p.GEOM_BOX] * 5, halfExtents=[e for e, _ in parts], collisionFramePositions=[o for _, o in parts]
    )
    vis = p.createVisualShapeArray(
        [p.GEOM_BOX] * 5,
        halfExtents=[e for e, _ in parts],
        visualFramePositions=[o for _, o in parts],
        rgbaColors=[_color(label)] * 5,
    )
    return p.createMultiBody(0.3, col, vis, [x, y, z])


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
        obj.body = _container(obj.label, x, y) if obj.kind == "container" else _solid(obj.label, x, y)
        scene.bodies[obj.body] = obj
    if scene.holding is not None:
        x, y = world_xy(scene.holding.xy)
        make = _container if scene.holding.kind == "container" else _solid
        scene.holding.body = make(scene.holding.label, x, y, 0.0)  # on the floor
    for _ in range(120):  # let everything settle
        p.stepSimulation()
    return robot
