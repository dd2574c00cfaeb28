"""Feasibility before acting: a task's whole motion is planned before the robot moves. Every waypoint
needs an inverse-kinematics solution and a collision-free configuration, every motion between them a
collision-free joint-space path (OMPL); the arm, the grasp yaw and the tilt direction are chosen by what
is feasible. An infeasible task gives the reason and leaves the world untouched.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from lmcr.executor.arm import IK_POSITION, IK_ROTATION, Arm, relative_pose
from lmcr.executor.collision import Carried, Clearance
from lmcr.executor.planner import PLAN_CHECKS, joint_path, segment_clash
from lmcr.executor.scene import Scene, SceneObject
from lmcr.executor.tasks import GRIP_GAP, Geometry, Step, Task, Variant, variants

SIDES = ("left", "right")


@dataclass
class Segment:
    step: Step
    path: list[np.ndarray] | None = None  # joint-space path of a move, its first configuration where the last ended
    goal: np.ndarray | None = None  # the gripper position the move reaches


@dataclass
class Plan:
    arm: Arm
    other: Arm
    variant: Variant
    segments: list[Segment]
    carried: Carried | None  # what the hand holds at the start
    geometry: Geometry


@dataclass
class Infeasible:
    reason: str
    progress: int = 0  # steps planned before the one that failed (the best attempt's reason is reported)


@dataclass
class Planner:
    """Plans tasks in a built world: `robot`, the scene's objects and the table body."""

    robot: int
    scene: Scene
    table: int
    arms: dict[str, Arm] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.arms = {side: Arm(self.robot, side) for side in SIDES}

    def plan(self, task: Task, held: SceneObject, target: SceneObject, holding: bool) -> Plan | Infeasible:
        """The first feasible plan over the arms (the nearer one first) and the task's variants, or the
        reason of the attempt that got furthest."""
        near = held if not holding else target
        sides = sorted(SIDES, key=lambda s: (near.xy[1] >= 0) != (s == "left"))
        best = Infeasible("nothing was tried", -1)
        for side in sides:
            arm, other = self.arms[side], self.arms[SIDES[1 - SIDES.index(side)]]
            saved = _save(held)
            try:
                other.set_config(other.parked)
                arm.set_config(arm.home)
                if holding:
                    _put_in_hand(arm, held)
                g = Geometry.measure(held, target)
                start = _save(held)
                clearance = Clearance(arm, self._obstacles(held))
                failed_grasps = set()
                for variant in _variants(held, task, holding, arm.opening):
                    grasp = (variant.yaw, variant.pitch, variant.side, variant.shift)
                    if grasp in failed_grasps:
                        continue  # the same pick-up failed already: only the later steps differ
                    # the last attempt's checks left the held object in its hand: it stands where it started
                    _restore(held, start)
                    carried = Carried(held.body, *g.in_hand(variant)) if holding else None
                    steps = task.program(g, variant, holding)
                    result = self._plan_variant(arm, clearance, steps, held, target, carried)
                    if isinstance(result, list):
                        return Plan(arm, other, variant, result, carried, g)
                    if result.progress < _pick_steps(steps):
                        failed_grasps.add(grasp)
                    if result.progress > best.progress:
                        best = result
            finally:
                arm.set_config(arm.home)
                _restore(held, saved)
        return best

    def _obstacles(self, held: SceneObject) -> dict[int, str]:
        things = {o.body: f"the {o.label}" for o in self.scene.objects if o.body != held.body}
        return {self.table: "the table", **things, held.body: f"the {held.label}"}

    def _plan_variant(self, arm: Arm, clearance: Clearance, steps: list[Step], held: SceneObject,
                      target: SceneObject, carried: Carried | None) -> list[Segment] | Infeasible:
        q, segments, released = arm.home, [], False
        for i, step in enumerate(steps):
            if step.kind == "grasp":
                carried = Carried(held.body, *_grasped(arm, q, held))
            elif step.kind == "release":
                carried, released = None, True
            if step.kind != "move":
                segments.append(Segment(step))
                continue
            # a motion that touches something (the held object, the target, the table it lifts from) may
            # pass close over the table; the other objects it keeps CLEARANCE from, as every motion does
            touched = {"held": {held.body}, "target": {target.body}}.get(step.touches, set())
            ignore = frozenset(touched | ({held.body} if released else set()))
            tight = frozenset({self.table} if step.touches else ())

            def clash(x, carried=carried, ignore=ignore, tight=tight):
                return clearance.clash(x, carried, ignore, tight=tight)

            found, why = None, ""
            for position in step.positions:
                goal, err_pos, err_rot = arm.solve(position, step.orientation, [q, arm.home])
                if err_pos > IK_POSITION or err_rot > IK_ROTATION:
                    why = f"the {arm.side} arm cannot reach '{step.name}' ({err_pos * 100:.0f} cm short)"
                    continue
                hit = clash(goal)
                if hit:
                    why = f"'{step.name}' would put the {arm.side} arm against {hit}"
                    continue
                # a motion that may touch what it reaches for goes there straight: a detour found with the
                # object ignored could sweep through it
                path = joint_path(clash, q, goal, arm.limits, budget=0 if touched else PLAN_CHECKS)
                if path is None:
                    why = f"no clear way for the {arm.side} arm to '{step.name}' ({segment_clash(clash, q, goal)} is in the way)"
                    continue
                found = (path, goal, position)
                break
            if found is None:
                return Infeasible(why, i)
            segments.append(Segment(step, found[0], found[2]))
            q = found[1]
        return segments


def _pick_steps(steps: list[Step]) -> int:
    """How many of a program's steps pick the object up (up to and including the lift after the grasp)."""
    kinds = [s.kind for s in steps]
    return kinds.index("grasp") + 2 if "grasp" in kinds else 0


def _variants(held: SceneObject, task: Task, holding: bool, opening: float) -> list[Variant]:
    """The ways to try: all grasps, or, for an object already in the hand, the top grasp it was handed
    over in, by its middle (tilting either way)."""
    if holding:
        return [v for v in variants(held) if v.yaw == 0.0 and not v.side and v.shift == (0.0, 0.0)]
    return variants(held, task.pours, opening)


def _grasped(arm: Arm, q, held: SceneObject) -> tuple:
    """The held object's pose in the hand when grasped at joints `q`, as it stands now."""
    arm.set_config(q)
    return relative_pose(*arm.ee_pose(), *p.getBasePositionAndOrientation(held.body))


def _put_in_hand(arm: Arm, held: SceneObject) -> None:
    """Stand the held object upright with its top just under the gripper at its current pose, as if
    grasped there (the pose the robot was handed it in)."""
    ee_pos, _ = arm.ee_pose()
    pos, _ = p.getBasePositionAndOrientation(held.body)
    top = p.getAABB(held.body)[1][2] - pos[2]
    p.resetBasePositionAndOrientation(held.body, (ee_pos - [0, 0, GRIP_GAP + top]).tolist(), (0, 0, 0, 1))


def _save(obj: SceneObject) -> tuple:
    return p.getBasePositionAndOrientation(obj.body)


def _restore(obj: SceneObject, pose: tuple) -> None:
    p.resetBasePositionAndOrientation(obj.body, *pose)

