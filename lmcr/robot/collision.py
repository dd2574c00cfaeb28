"""Collision checks of arm configurations for planning: the arm, and whatever it carries, against the
table, the objects and the rest of the robot, with pybullet's closest-point queries on joints set
kinematically (nothing is simulated)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet as p

from lmcr.robot.arm import Arm

CLEARANCE = 0.01  # metres kept from obstacles (the joints track a path only to a few millimetres)
CONTACT_CLEARANCE = 0.003  # ... but from the table while grasping, lifting or lowering into the target


@dataclass(frozen=True)
class Carried:
    """An object in the hand: its pose relative to the gripper."""

    body: int
    rel_pos: tuple
    rel_orn: tuple

    def place(self, arm: Arm) -> None:
        ee_pos, ee_orn = arm.ee_pose()
        pos, orn = p.multiplyTransforms(ee_pos.tolist(), ee_orn, self.rel_pos, self.rel_orn)
        p.resetBasePositionAndOrientation(self.body, pos, orn)


class Clearance:
    """`clash(q, ...)`: the first thing the arm at joints `q` (with what it carries) comes too close to."""

    def __init__(self, arm: Arm, obstacles: dict[int, str]):
        self.arm = arm
        self.obstacles = obstacles  # body -> name ("the table", "the cup")
        self.self_pairs = self._self_pairs()
        self._pair_boxes = SelfPairBoxes(arm.robot, self.self_pairs)

    def _self_pairs(self) -> list[tuple[int, int]]:
        """Links of this arm beyond the elbow against the torso, the pedestal and the other arm, less the
        pairs that touch in the home pose (the simple link shapes overlap at some joints)."""
        robot, arm = self.arm.robot, self.arm
        distal = [
            link
            for link in range(arm.joints[3], p.getNumJoints(robot))
            if p.getJointInfo(robot, link)[12].decode().startswith(arm.side)
        ]
        ours = set(range(arm.joints[0], distal[-1] + 1))
        others = [
            link
            for link in range(-1, p.getNumJoints(robot))
            if link not in ours
            and not (link >= 0 and p.getJointInfo(robot, link)[12].decode() == f"{arm.side}_arm_mount")
        ]
        saved = arm.config()
        arm.set_config(arm.home)
        pairs = [
            (a, b)
            for a in distal
            for b in others
            if not p.getClosestPoints(robot, robot, 0.0, linkIndexA=a, linkIndexB=b)
        ]
        arm.set_config(saved)
        return pairs

    def clash(
        self,
        q,
        carried: Carried | None = None,
        ignore: frozenset[int] = frozenset(),
        margin: float = CLEARANCE,
        tight: frozenset[int] = frozenset(),
    ) -> str | None:
        """What the arm at `q` is within `margin` of (None: clear). `ignore`: bodies allowed to touch
        (the object about to be grasped, the target the motion goes into); `tight`: bodies it may come
        within CONTACT_CLEARANCE of (the table under a grasp)."""
        arm = self.arm
        arm.set_config(q)
        if carried is not None:
            carried.place(arm)
        for body, name in self.obstacles.items():
            if body in ignore or (carried is not None and body == carried.body):
                continue
            gap = CONTACT_CLEARANCE if body in tight else margin
            if p.getClosestPoints(arm.robot, body, gap):
                return name
            if carried is not None and p.getClosestPoints(carried.body, body, gap):
                return name
        for a, b in self._pair_boxes.overlapping():
            if p.getClosestPoints(arm.robot, arm.robot, 0.0, linkIndexA=a, linkIndexB=b):
                return "the robot's own body"
        return None


class SelfPairBoxes:
    """Which of the self-collision pairs (a moving link of the arm, a link that stays put) could touch:
    those whose bounding boxes overlap. Two links that touch have overlapping boxes, so only those need
    the exact query; in a typical configuration that is about one of 144 pairs, and the box test costs
    one `getAABB` per moving link (pybullet updates the boxes when joints are reset) instead of a
    closest-point query per pair. Links without a collision shape have no box, and never touch."""

    def __init__(self, robot: int, pairs: list[tuple[int, int]]):
        self.robot = robot
        boxes = {link: _box(robot, link) for pair in pairs for link in pair}  # the still links' serve every query
        self.pairs = [(a, b) for a, b in pairs if boxes[a] is not None and boxes[b] is not None]
        self.moving = sorted({a for a, _ in self.pairs})
        row = {link: k for k, link in enumerate(self.moving)}
        self.rows = np.array([row[a] for a, _ in self.pairs], dtype=int)
        still = np.array([boxes[b] for _, b in self.pairs]).reshape(-1, 2, 3)
        self.still_lo, self.still_hi = still[:, 0], still[:, 1]

    def overlapping(self) -> list[tuple[int, int]]:
        """The pairs whose boxes overlap at the arm's current joints."""
        if not self.pairs:
            return []
        boxes = np.array([p.getAABB(self.robot, link) for link in self.moving])[self.rows]
        hit = np.all((boxes[:, 0] <= self.still_hi) & (self.still_lo <= boxes[:, 1]), axis=1)
        return [self.pairs[k] for k in np.flatnonzero(hit)]


def _box(robot: int, link: int) -> tuple | None:
    try:
        return p.getAABB(robot, link)
    except p.error:  # no collision shape
        return None
