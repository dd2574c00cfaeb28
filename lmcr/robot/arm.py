"""One Baxter arm: joint bookkeeping, inverse kinematics for planning, and driving the joints along a
planned joint-space path in the simulation.

Planning is kinematic (joints are set, nothing is simulated) and leaves the arm where it found it;
execution drives position-controlled motors through the planned configurations. A grasp closes the
fingers and attaches the object with a fixed constraint (stable friction grasps need per-object tuning
that says nothing about the instruction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from lmcr.robot.baxter import JOINTS

DOWN = p.getQuaternionFromEuler((math.pi, 0, 0))  # gripper pointing at the table
ORIENTATION_WEIGHT = 0.3  # metres of position error one radian of orientation error is worth
IK_POSITION = 0.003  # metres: a pose counts as reachable when IK gets this close ...
IK_ROTATION = 0.03  # ... and this close in orientation (radians)
JOINT_STEP = 0.012  # radians per control tick pair while following a path (about 1.4 rad/s)
SETTLED = 0.002  # radians: the joints have arrived
IK_RESTARTS, IK_RESTART_SEED = 4, 0  # other starts for a pose whose first IK solution clashes
# A solve whose pose error fell by under 1% over the last 30 steps is stuck (a joint limit, a local
# minimum) and ends there: such solves took 92% of the IK steps of the executor benchmark's plans, while
# 0.2% of the solves that would have come within IK_POSITION / IK_ROTATION were still creeping there.
IK_STALL_STEPS, IK_STALL_GAIN = 30, 0.99
IK_DAMPING = 0.03**2 * np.eye(6)
FINGER_THICKNESS = 0.01  # metres, both grippers' finger pads
FINGER_SLACK = 0.002  # metres a closing finger stops short of the object's side
GRASP_SLACK = 0.02  # metres: the fingertips must be at most this far outside the object's box to hold it


def rotation_error(current, target) -> np.ndarray:
    """World-frame rotation vector turning orientation `current` into `target` (quaternions, x y z w):
    the shortest turn, of at most half a turn. Plain arithmetic on the quaternion target * current^-1,
    since the IK loop calls it hundreds of thousands of times a plan."""
    x1, y1, z1, w1 = current
    x2, y2, z2, w2 = target
    w = w2 * w1 + x2 * x1 + y2 * y1 + z2 * z1
    x = -w2 * x1 + x2 * w1 - y2 * z1 + z2 * y1
    y = -w2 * y1 + x2 * z1 + y2 * w1 - z2 * x1
    z = -w2 * z1 - x2 * y1 + y2 * x1 + z2 * w1
    if w < 0:  # the same turn the short way round
        w, x, y, z = -w, -x, -y, -z
    sine = math.sqrt(x * x + y * y + z * z)
    if sine < 1e-12:
        return np.zeros(3)
    scale = 2.0 * math.atan2(sine, w) / sine
    return np.array((x * scale, y * scale, z * scale))


def relative_pose(frame_pos, frame_orn, pos, orn) -> tuple[tuple, tuple]:
    """The pose (`pos`, `orn`) expressed in the frame at (`frame_pos`, `frame_orn`)."""
    inv_pos, inv_orn = p.invertTransform(list(frame_pos), frame_orn)
    return p.multiplyTransforms(inv_pos, inv_orn, pos, orn)


def joint_index(robot: int) -> dict[str, int]:
    """Joint name -> pybullet joint index."""
    return {p.getJointInfo(robot, i)[1].decode(): i for i in range(p.getNumJoints(robot))}


@dataclass
class Arm:
    robot: int
    side: str
    held: int | None = None
    constraint: int | None = None
    on_waypoint: object = None  # called after each reached waypoint (rendering)
    on_step: object = None  # called after each step of a followed path (a video's frames)
    ik_calls: int = 0  # poses solved for (`solve`): what the planning search's budget counts
    log: list[dict] = field(default_factory=list)

    def __post_init__(self) -> None:
        names = joint_index(self.robot)
        self.joints = [names[f"{self.side}_{j}"] for j in JOINTS]
        # ours: left_gripper_l_finger_joint; the official electric gripper's: l_gripper_l_finger_joint
        self.fingers = [
            names.get(f"{self.side}_gripper_{f}_finger_joint", names.get(f"{self.side[0]}_gripper_{f}_finger_joint"))
            for f in "lr"
        ]
        self.ee = names[f"{self.side}_endpoint"]
        self.movable = [
            i for i in range(p.getNumJoints(self.robot)) if p.getJointInfo(self.robot, i)[2] != p.JOINT_FIXED
        ]
        self.columns = [self.movable.index(j) for j in self.joints]  # this arm's columns of the Jacobian
        self.limits = np.array([p.getJointInfo(self.robot, j)[8:10] for j in self.joints])
        sign = 1 if self.side == "left" else -1
        # Baxter's "untucked" pose: elbow bent, gripper over the near edge of the table (mirrored for the right arm)
        self.home = np.array([0.08 * sign, -1.0, -1.19 * sign, 1.94, 0.67 * sign, 1.03, -0.5 * sign])
        # out of the other arm's way: the shoulder turned outwards, the hand raised above the tallest
        # object (a blender near the robot's edge: 0.22 m; the fingers 5 cm above it, off the table's side)
        self.parked = np.array([0.9 * sign, -0.9, -1.19 * sign, 1.94, 0.67 * sign, 1.03, -0.5 * sign])
        # where IK starts again when a pose's solution clashes: seeded random configurations within the
        # limits (the same ones every run)
        rng = np.random.default_rng(IK_RESTART_SEED)
        self.ik_restarts = [rng.uniform(*self.limits.T) for _ in range(IK_RESTARTS)]
        self.finger_open, self.finger_shut, self.gaps = self._finger_range()
        self.opening = self.gaps[0] - FINGER_THICKNESS  # the widest object that fits between the open fingers
        self.shoulder, self.reach = self._reach()

    def _reach(self) -> tuple[np.ndarray, float]:
        """The first joint's origin (it turns about itself: it stays put) and the length of the chain from
        there to the gripper, joint origin to joint origin: the links are rigid, so no joint angles put
        the gripper farther from the shoulder than that (the triangle inequality)."""
        origins = [np.asarray(p.getLinkState(self.robot, j, computeForwardKinematics=True)[4]) for j in self.joints]
        reach = sum(float(np.linalg.norm(b - a)) for a, b in zip(origins, [*origins[1:], self.ee_pose()[0]]))
        return origins[0], reach

    def beyond_reach(self, position) -> float:
        """How far `position` lies outside the sphere the gripper can reach (`_reach`); > 0: no joint
        angles reach it, whatever the orientation."""
        return float(np.linalg.norm(np.asarray(position) - self.shoulder)) - self.reach

    def _finger_range(self) -> tuple[list[float], list[float], tuple[float, float]]:
        """Finger joint targets that open and shut the gripper, and the distance between the fingers'
        middles open and shut (measured: grippers differ in which way their joints move)."""
        limits = [p.getJointInfo(self.robot, j)[8:10] for j in self.fingers]
        saved = [p.getJointState(self.robot, j)[0] for j in self.fingers]

        def gap(targets) -> float:
            for j, v in zip(self.fingers, targets):
                p.resetJointState(self.robot, j, v)
            a, b = (np.mean(p.getAABB(self.robot, j), axis=0) for j in self.fingers)
            return float(np.linalg.norm(a - b))

        one, other = [limits[0][0], limits[1][1]], [limits[0][1], limits[1][0]]
        (wide, d_wide), (narrow, d_narrow) = sorted([(one, gap(one)), (other, gap(other))], key=lambda t: -t[1])
        for j, v in zip(self.fingers, saved):
            p.resetJointState(self.robot, j, v)
        return wide, narrow, (d_wide, d_narrow)

    # kinematics (planning)
    def config(self) -> np.ndarray:
        return np.array([s[0] for s in p.getJointStates(self.robot, self.joints)])

    def set_config(self, q) -> None:
        # one call for the seven joints (the IK loop sets them hundreds of thousands of times a plan)
        p.resetJointStatesMultiDof(self.robot, self.joints, [[float(v)] for v in q], [[0.0]] * len(self.joints))

    def ee_pose(self) -> tuple[np.ndarray, tuple]:
        state = p.getLinkState(self.robot, self.ee, computeForwardKinematics=True)
        return np.asarray(state[4]), state[5]

    def solve(self, position, orientation, seeds) -> tuple[np.ndarray, float, float]:
        """Joint angles within the limits reaching the pose: damped least squares from each seed in turn
        until one converges; (joints, position error m, orientation error rad) of the best. From the first
        seed the pose is also approached in stages (a large turn of the wrist, as in tilting to pour,
        defeats a single local solve). A position beyond the arm's reach is not searched: the error is then
        how far beyond it lies, the least any joints would leave."""
        self.ik_calls += 1
        beyond = self.beyond_reach(position)
        if beyond > IK_POSITION:
            return np.asarray(seeds[0], dtype=float), beyond, math.pi
        best = None
        for seed in [*seeds, "staged"]:
            if isinstance(seed, str):
                seed = self._staged_seed(seeds[0], position, orientation)
            q, err_pos, err_rot = self._dls(np.asarray(seed, dtype=float), np.asarray(position), orientation)
            if best is None or err_pos + ORIENTATION_WEIGHT * err_rot < best[1] + ORIENTATION_WEIGHT * best[2]:
                best = (q, err_pos, err_rot)
            if err_pos <= IK_POSITION and err_rot <= IK_ROTATION:
                break
        return best

    def _staged_seed(self, seed, position, orientation, stages: int = 4) -> np.ndarray:
        """Joints reached by solving for poses part of the way from `seed`'s pose to the goal."""
        q = np.asarray(seed, dtype=float)
        self.set_config(q)
        start_pos, start_orn = self.ee_pose()
        for k in range(1, stages):
            f = k / stages
            orn = p.getQuaternionSlerp(start_orn, orientation, f)
            q, _, _ = self._dls(q, start_pos + (np.asarray(position) - start_pos) * f, orn, iterations=60)
        return q

    def _dls(self, q: np.ndarray, target: np.ndarray, orientation, iterations: int = 150):
        """Damped least squares on the 6-D pose error, clipped to the joint limits at every step, until
        it converges, `iterations` steps or a stall (IK_STALL_STEPS). Leaves the arm at the result."""
        lo, hi = self.limits.T
        all_q = [s[0] for s in p.getJointStates(self.robot, self.movable)]
        zeros = [0.0] * len(self.movable)
        goal = tuple(np.asarray(orientation, dtype=float) / np.linalg.norm(orientation))
        errors: list[float] = []
        for step_no in range(iterations + 1):
            self.set_config(q)
            pos, orn = self.ee_pose()
            err_pos, err_rot = target - pos, rotation_error(orn, goal)
            d_pos, d_rot = math.sqrt(err_pos @ err_pos), math.sqrt(err_rot @ err_rot)
            errors.append(d_pos + ORIENTATION_WEIGHT * d_rot)
            stalled = step_no >= IK_STALL_STEPS and errors[-1] > IK_STALL_GAIN * errors[-1 - IK_STALL_STEPS]
            if step_no == iterations or (d_pos < 2e-4 and d_rot < 2e-3) or stalled:
                break
            for c, v in zip(self.columns, q):
                all_q[c] = float(v)
            lin, ang = p.calculateJacobian(self.robot, self.ee, [0, 0, 0], all_q, zeros, zeros)
            jac = np.array((*lin, *ang))[:, self.columns]
            jac[3:] *= ORIENTATION_WEIGHT
            err = np.concatenate((err_pos, ORIENTATION_WEIGHT * err_rot))
            step = jac.T @ np.linalg.solve(jac @ jac.T + IK_DAMPING, err)
            # clipped to 0.3 rad a step and to the limits (np.minimum/maximum: np.clip costs 10x more here)
            q = np.minimum(np.maximum(q + np.minimum(np.maximum(step, -0.3), 0.3), lo), hi)
        return q, float(d_pos), float(d_rot)

    # control (execution)
    def hold(self, q) -> None:
        """Position-control the joints to `q` (no stepping)."""
        p.setJointMotorControlArray(
            self.robot,
            self.joints,
            p.POSITION_CONTROL,
            targetPositions=list(map(float, q)),
            forces=[150.0] * 7,
            positionGains=[0.3] * 7,
        )

    def follow(self, path: list[np.ndarray]) -> None:
        """Drive through a joint-space path at a steady joint speed, then wait for the joints to arrive."""
        for a, b in zip(path, path[1:]):
            n = max(1, math.ceil(float(np.max(np.abs(b - a))) / JOINT_STEP))
            for k in range(1, n + 1):
                self.hold(a + (b - a) * k / n)
                p.stepSimulation()
                p.stepSimulation()
                if self.on_step:
                    self.on_step()
        for _ in range(240):
            if float(np.max(np.abs(self.config() - path[-1]))) < SETTLED:
                break
            p.stepSimulation()

    def record(self, name: str, target) -> float:
        """Log how far the gripper ended from the waypoint `target` (metres)."""
        error = float(np.linalg.norm(self.ee_pose()[0] - np.asarray(target)))
        self.log.append({"name": name, "error_m": round(error, 4)})
        if self.on_waypoint:
            self.on_waypoint()
        return error

    def grasp(self, body: int, half_width: float) -> bool:
        """Close the fingers on an object `half_width` wide and attach it where it is; False when the
        object is not under the fingertips (knocked away or never reached)."""
        if not self.close_on(body, half_width):
            return False
        self.attach(body)
        return True

    def close_on(self, body: int, half_width: float) -> bool:
        """Close the fingers on an object `half_width` wide; whether it is under the fingertips then."""
        p.setJointMotorControlArray(
            self.robot, self.fingers, p.POSITION_CONTROL, targetPositions=self.finger_targets(half_width)
        )
        for _ in range(60):
            p.stepSimulation()
        ee_pos, _ = self.ee_pose()
        lo, hi = p.getAABB(body)
        return all(lo[k] - GRASP_SLACK <= ee_pos[k] <= hi[k] + GRASP_SLACK for k in range(3))

    def finger_targets(self, half_width: float | None) -> list[float]:
        """Finger joint targets that stop FINGER_SLACK short of both sides of an object `half_width`
        wide (as open as they go when it is wider, or for None)."""
        if half_width is None:
            return list(self.finger_open)
        wide, narrow = self.gaps
        shut = float(np.clip((wide - FINGER_THICKNESS - 2 * half_width - 2 * FINGER_SLACK) / (wide - narrow), 0.0, 1.0))
        return [o + (s - o) * shut for o, s in zip(self.finger_open, self.finger_shut)]

    def shape_fingers(self, targets: list[float], now: bool = False) -> None:
        """Drive the fingers to joint `targets` (no stepping); `now`: also put them there (planning)."""
        p.setJointMotorControlArray(self.robot, self.fingers, p.POSITION_CONTROL, targetPositions=targets)
        if now:
            for j, v in zip(self.fingers, targets):
                p.resetJointState(self.robot, j, v)

    def fingers_at(self, targets: list[float], tolerance: float = 0.001) -> bool:
        """Whether the finger joints are within `tolerance` of `targets`."""
        return all(abs(p.getJointState(self.robot, j)[0] - t) <= tolerance for j, t in zip(self.fingers, targets))

    def open_fingers(self) -> None:
        """Drive the fingers open (no stepping)."""
        self.shape_fingers(self.finger_open)

    def attach(self, body: int) -> None:
        """Hold `body` rigidly where it is relative to the gripper."""
        rel_pos, rel_orn = relative_pose(*self.ee_pose(), *p.getBasePositionAndOrientation(body))
        self.constraint = p.createConstraint(
            self.robot, self.ee, body, -1, p.JOINT_FIXED, [0, 0, 0], rel_pos, [0, 0, 0], rel_orn
        )
        p.changeConstraint(self.constraint, maxForce=500)
        robot_collisions(self.robot, body, False)  # held in the hand, it must not push the arm around
        self.held = body

    def hook(self, body: int, link: int, turns: bool = False) -> None:
        """Hold a link of `body` (a drawer or a lid, by its handle's bar) where it is relative to the gripper:
        the arm's motion then pulls or pushes it along its joint. A drawer is held rigidly; a lid's bar
        (`turns`) only at the gripper's point, so that it turns in the hold as the lid turns about its
        hinge (a rigid hold would fight the hinge)."""
        com_pos, com_orn = p.getLinkState(body, link)[:2]
        if turns:
            here = relative_pose(com_pos, com_orn, *self.ee_pose())[0]
            self.constraint = p.createConstraint(
                self.robot, self.ee, body, link, p.JOINT_POINT2POINT, [0, 0, 0], [0, 0, 0], here
            )
        else:
            rel_pos, rel_orn = relative_pose(*self.ee_pose(), com_pos, com_orn)
            self.constraint = p.createConstraint(
                self.robot, self.ee, body, link, p.JOINT_FIXED, [0, 0, 0], rel_pos, [0, 0, 0], rel_orn
            )
        p.changeConstraint(self.constraint, maxForce=500)

    def unhook(self) -> None:
        """Let go of what `hook` holds."""
        if self.constraint is not None:
            p.removeConstraint(self.constraint)
        self.constraint = None

    def release(self, fingers: list[float] | None = None) -> None:
        """Let go, the fingers back to `fingers` (the shape they approached in; open by default); the
        object touches the robot again only once it has dropped away (turned back on while it still
        overlaps the fingers, contact would throw it off the table)."""
        if self.constraint is not None:
            p.removeConstraint(self.constraint)
        self.shape_fingers(fingers or self.finger_open)
        settle(240)
        if self.held is not None:
            robot_collisions(self.robot, self.held, True)
        self.constraint, self.held = None, None


def robot_collisions(robot: int, body: int, enable: bool) -> None:
    for link in range(-1, p.getNumJoints(robot)):
        p.setCollisionFilterPair(robot, body, link, -1, int(enable))


def settle(steps: int = 240) -> None:
    for _ in range(steps):
        p.stepSimulation()
