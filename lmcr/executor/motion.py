"""Arm control and one motion plan per predicate, parameterised by the completed frame.

An `Arm` solves inverse kinematics within the joint limits (pybullet's damped least squares, refined
from the reached state), drives the joints with position control and reports how far the gripper
ended from each waypoint. A grasp closes the fingers and attaches the object with a fixed constraint
(stable friction grasps need per-object tuning that says nothing about the instruction).

Each plan is a list of end-effector waypoints defined relative to the task objects: pick up the held
object, carry it above the target, then the verb's own motion (tilt to pour, shake to sprinkle, lower
to dip, stroke to brush or rub, invert to dump, place to heat or fry, load and press to blend).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from lmcr.executor.baxter import FINGER_TRAVEL, JOINTS
from lmcr.executor.scene import CONTAINERS, TABLE_CENTRE, TABLE_TOP, Scene, SceneObject, footprint, height

DOWN = p.getQuaternionFromEuler((math.pi, 0, 0))  # gripper pointing at the table
SAFE = TABLE_TOP + 0.40  # carry height
TOLERANCE = 0.02  # metres: a waypoint counts as reached within this


ORIENTATION_WEIGHT = 0.3  # metres of position error one radian of orientation error is worth


def rotation_error(current, target) -> np.ndarray:
    """World-frame rotation vector turning orientation `current` into `target` (quaternions)."""
    rc = np.asarray(p.getMatrixFromQuaternion(current)).reshape(3, 3)
    rt = np.asarray(p.getMatrixFromQuaternion(target)).reshape(3, 3)
    r = rt @ rc.T
    angle = math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2)))
    if angle < 1e-9:
        return np.zeros(3)
    axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    norm = np.linalg.norm(axis)
    if norm < 1e-9:  # half a turn: any axis orthogonal to the symmetric part's
        w, v = np.linalg.eigh(r + np.eye(3))
        axis = v[:, -1]
        return axis * math.pi
    return axis / norm * angle


@dataclass
class Arm:
    robot: int
    side: str
    log: list[dict] = field(default_factory=list)
    held: int | None = None
    constraint: int | None = None
    grasps_ok: bool = True  # every grasp found its object between the fingers

    def __post_init__(self) -> None:
        names = {p.getJointInfo(self.robot, i)[1].decode(): i for i in range(p.getNumJoints(self.robot))}
        self.joints = [names[f"{self.side}_{j}"] for j in JOINTS]
        self.fingers = [names[f"{self.side}_gripper_l_finger_joint"], names[f"{self.side}_gripper_r_finger_joint"]]
        self.ee = names[f"{self.side}_endpoint"]
        self.movable = [i for i in range(p.getNumJoints(self.robot)) if p.getJointInfo(self.robot, i)[2] != p.JOINT_FIXED]
        info = [p.getJointInfo(self.robot, i) for i in self.movable]
        self.lower = [i[8] for i in info]
        self.upper = [i[9] for i in info]
        self.limits = [(self.lower[self.movable.index(j)], self.upper[self.movable.index(j)]) for j in self.joints]
        sign = 1 if self.side == "left" else -1
        # Baxter's "untucked" pose: elbow bent, gripper over the table (mirrored for the right arm)
        self.home = [0.08 * sign, -1.0, -1.19 * sign, 1.94, 0.67 * sign, 1.03, -0.5 * sign]
        self.on_waypoint = None  # called after each waypoint (rendering)

    def position(self) -> np.ndarray:
        return np.asarray(p.getLinkState(self.robot, self.ee, computeForwardKinematics=True)[4])

    def go_home(self) -> None:
        for j, v in zip(self.joints, self.home):
            p.resetJointState(self.robot, j, v)
            p.setJointMotorControl2(self.robot, j, p.POSITION_CONTROL, targetPosition=v, force=80.0)

    def solve(self, target, orientation=DOWN) -> list[float]:
        """Joint angles (this arm's seven) reaching the pose, within the joint limits: the better of
        damped least squares started from the current configuration and from the home pose."""
        current = [p.getJointState(self.robot, j)[0] for j in self.joints]
        best, best_err = None, math.inf
        for seed in (current, self.home):
            q, err = self._dls(seed, target, orientation)
            if err < best_err:
                best, best_err = q, err
        return best

    def _dls(self, seed, target, orientation, iterations: int = 300) -> tuple[list[float], float]:
        """Damped least squares on the 6-D pose error, clipped to the joint limits at every step;
        returns the joints and the weighted pose error. The arm is left where it was."""
        state = p.saveState()
        err = np.full(6, np.inf)
        try:
            q = np.array(seed, dtype=float)
            for j, v in zip(self.joints, q):
                p.resetJointState(self.robot, j, v)
            lo, hi = np.array(self.limits).T
            for _ in range(iterations):
                pos, orn = p.getLinkState(self.robot, self.ee, computeForwardKinematics=True)[4:6]
                err_pos = np.asarray(target) - pos
                err_rot = rotation_error(orn, orientation)
                err = np.concatenate([err_pos, ORIENTATION_WEIGHT * err_rot])
                if np.linalg.norm(err_pos) < 1e-4 and np.linalg.norm(err_rot) < 1e-3:
                    break
                zeros = [0.0] * len(self.movable)
                all_q = [p.getJointState(self.robot, j)[0] for j in self.movable]
                lin, ang = p.calculateJacobian(self.robot, self.ee, [0, 0, 0], all_q, zeros, zeros)
                cols = [self.movable.index(j) for j in self.joints]
                jac = np.vstack([np.asarray(lin)[:, cols], ORIENTATION_WEIGHT * np.asarray(ang)[:, cols]])  # (6, 7)
                step = jac.T @ np.linalg.solve(jac @ jac.T + 0.05 ** 2 * np.eye(6), err)
                q = np.clip(q + np.clip(step, -0.2, 0.2), lo, hi)
                for j, v in zip(self.joints, q):
                    p.resetJointState(self.robot, j, v)
            pos, orn = p.getLinkState(self.robot, self.ee, computeForwardKinematics=True)[4:6]
            err = np.concatenate([np.asarray(target) - pos, ORIENTATION_WEIGHT * rotation_error(orn, orientation)])
            return [float(v) for v in q], float(np.linalg.norm(err))
        finally:
            p.restoreState(state)
            p.removeState(state)

    def residual(self, target, orientation=DOWN) -> float:
        """How close IK gets to `target` (metres), tried without moving the arm."""
        state = p.saveState()
        try:
            for j, v in zip(self.joints, self.solve(target, orientation)):
                p.resetJointState(self.robot, j, v)
            return float(np.linalg.norm(self.position() - np.asarray(target)))
        finally:
            p.restoreState(state)
            p.removeState(state)

    def move(self, name: str, target, orientation=DOWN, steps: int = 360) -> float:
        """Drive to `target`; the reached error is logged under `name` and returned."""
        for attempt in range(4):  # re-solve from where the arm got to: IK is local
            q = self.solve(target, orientation)
            for j, v in zip(self.joints, q):
                p.setJointMotorControl2(self.robot, j, p.POSITION_CONTROL, targetPosition=v, force=120.0,
                                        positionGain=0.3, maxVelocity=2.0)
            for _ in range(steps if attempt == 0 else steps // 2):
                p.stepSimulation()
        error = float(np.linalg.norm(self.position() - np.asarray(target)))
        self.log.append({"name": name, "error_m": round(error, 4)})
        if self.on_waypoint:
            self.on_waypoint()
        return error

    def grasp(self, body: int, half_width: float) -> None:
        """Close the fingers onto an object `half_width` wide (each finger travels inwards from 4.5 cm)."""
        close = float(np.clip(0.045 - half_width - 0.003, 0.0, FINGER_TRAVEL))
        p.setJointMotorControlArray(self.robot, self.fingers, p.POSITION_CONTROL, targetPositions=[close, -close])
        for _ in range(60):
            p.stepSimulation()
        ee_pos, ee_orn = p.getLinkState(self.robot, self.ee)[4:6]
        obj_pos, obj_orn = p.getBasePositionAndOrientation(body)
        lo, hi = p.getAABB(body)
        reach = np.hypot(ee_pos[0] - obj_pos[0], ee_pos[1] - obj_pos[1])
        if reach > max(hi[0] - lo[0], hi[1] - lo[1]) / 2 or abs(ee_pos[2] - hi[2]) > 0.03:
            self.grasps_ok = False  # knocked away or never reached: nothing to hold
            return
        inv_pos, inv_orn = p.invertTransform(ee_pos, ee_orn)
        rel_pos, rel_orn = p.multiplyTransforms(inv_pos, inv_orn, obj_pos, obj_orn)
        self.constraint = p.createConstraint(self.robot, self.ee, body, -1, p.JOINT_FIXED, [0, 0, 0], rel_pos, [0, 0, 0],
                                             rel_orn)
        p.changeConstraint(self.constraint, maxForce=500)
        self._robot_collisions(body, False)  # held in the hand, it must not push the arm around
        self.held = body

    def _robot_collisions(self, body: int, enable: bool) -> None:
        for link in range(-1, p.getNumJoints(self.robot)):
            p.setCollisionFilterPair(self.robot, body, link, -1, int(enable))

    def release(self) -> None:
        if self.constraint is not None:
            p.removeConstraint(self.constraint)
            self._robot_collisions(self.held, True)
        self.constraint, self.held = None, None
        p.setJointMotorControlArray(self.robot, self.fingers, p.POSITION_CONTROL, targetPositions=[0.0, 0.0])  # open
        settle(240)


def settle(steps: int = 240) -> None:
    for _ in range(steps):
        p.stepSimulation()


def top(obj: SceneObject) -> np.ndarray:
    """The top centre of an object as it stands now."""
    pos, _ = p.getBasePositionAndOrientation(obj.body)
    lo, hi = p.getAABB(obj.body)
    return np.array([pos[0], pos[1], hi[2]])


def carry_height(arm: Arm, xy) -> float:
    """SAFE, or lower where the arm cannot reach that high (the far edge of the table)."""
    for z in (SAFE, SAFE - 0.08, SAFE - 0.15):
        if arm.residual([xy[0], xy[1], z]) <= TOLERANCE / 4:
            return z
    return SAFE - 0.15


def pick(arm: Arm, obj: SceneObject) -> None:
    """Approach from above, grip the object's top, lift to carrying height."""
    t = top(obj)
    z = carry_height(arm, t)
    arm.move(f"above {obj.label}", [t[0], t[1], z])
    arm.move(f"grip {obj.label}", [t[0], t[1], t[2] + 0.005])  # fingertips at the top: the grasp attaches
    arm.grasp(obj.body, footprint(obj.label))
    arm.move(f"lift {obj.label}", [t[0], t[1], z])


def over(arm: Arm, target: SceneObject, clearance: float, name: str = "") -> np.ndarray:
    t = top(target)
    goal = [t[0], t[1], t[2] + clearance]
    arm.move(name or f"over {target.label}", [t[0], t[1], carry_height(arm, t)])
    arm.move(f"down to {target.label}", goal)
    return np.asarray(goal)


def mouth(held: SceneObject) -> np.ndarray:
    """Just outside the held container's opening (its top, wherever the motion turned it)."""
    pos, orn = p.getBasePositionAndOrientation(held.body)
    return np.asarray(p.multiplyTransforms(pos, orn, [0, 0, height(held.label) / 2 + 0.012], [0, 0, 0, 1])[0])


def align_spout(arm: Arm, held: SceneObject, target: SceneObject, goal, orientation) -> np.ndarray:
    """Shift the tilted gripper so that the opening, not the hand, is over the target's centre."""
    t = top(target)
    goal = np.asarray(goal, dtype=float)
    for k in range(2):
        offset = t[:2] - mouth(held)[:2]
        goal[:2] += offset
        arm.move(f"align spout {k + 1}", goal, orientation)
    return goal


def spill(held: SceneObject, n: int) -> list[int]:
    """A stream of particles (liquid or powder) leaving the held container's opening, one at a time
    (particles created on top of each other would push each other apart)."""
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.006)
    visual = p.createVisualShape(p.GEOM_SPHERE, radius=0.006, rgbaColor=[0.2, 0.4, 0.9, 1])
    rng = np.random.default_rng(n)
    bodies = []
    for _ in range(n):
        body = p.createMultiBody(0.002, shape, visual, list(mouth(held) + rng.normal(0, 0.002, 3)))
        p.changeDynamics(body, -1, lateralFriction=1.0, rollingFriction=0.02, spinningFriction=0.02)  # grains stay put
        bodies.append(body)
        settle(12)
    return bodies


def inside(target: SceneObject, point, above: float = 0.05) -> bool:
    """Whether a point lies within the target's horizontal outline, above the table and at most `above`
    over its rim (0.01: held in it, as a liquid must be; more: resting on top of it)."""
    lo, hi = p.getAABB(target.body)
    return lo[0] <= point[0] <= hi[0] and lo[1] <= point[1] <= hi[1] and TABLE_TOP - 0.01 <= point[2] <= hi[2] + above


def landed_in(target: SceneObject, bodies: list[int], above: float = 0.05) -> float:
    settle(480)
    hits = sum(inside(target, p.getBasePositionAndOrientation(b)[0], above) for b in bodies)
    return hits / max(len(bodies), 1)


def rests_in(obj: SceneObject, target: SceneObject) -> bool:
    settle(480)
    pos, _ = p.getBasePositionAndOrientation(obj.body)
    return inside(target, pos)


# The gripper turned about 110 degrees about one of four horizontal axes: what it holds by the top
# points its mouth down. Baxter's wrist reaches different ones at different places on the table.
TILTS = [p.getQuaternionFromEuler(e) for e in ((math.pi, -1.9, 0), (math.pi, 1.9, 0), (math.pi - 1.9, 0, 0),
                                                (math.pi + 1.9, 0, 0))]


def tilt_for(arm: Arm, point) -> tuple[tuple, np.ndarray]:
    """The most reachable tilt at `point` or a little above it: (orientation, point)."""
    options = [(q, np.asarray(point) + [0, 0, dz]) for dz in (0.0, 0.05, 0.10) for q in TILTS]
    return min(options, key=lambda o: arm.residual(o[1], o[0]) + 0.05 * o[1][2])  # lower is better when tied


def plan_pour(arm: Arm, held: SceneObject, target: SceneObject) -> dict:
    """Pick up the liquid, hold it above the target, tilt, let it run; liquid must end in the target."""
    pick(arm, held)
    upright = over(arm, target, 0.12 + height(held.label) / 2)
    tilt, spout = tilt_for(arm, upright)
    arm.move("tilt to pour", spout, tilt)
    align_spout(arm, held, target, spout, tilt)
    share = landed_in(target, spill(held, 30), above=0.01)  # a liquid must stay inside, below the rim
    arm.move("tilt back", upright + [-0.05, 0, 0.05])  # up and a little towards the robot: easy to reach upright
    return {"liquid_in_target": round(share, 3), "ok": share >= 0.6}


def plan_sprinkle(arm: Arm, held: SceneObject, target: SceneObject) -> dict:
    """Pick up the shaker, hold it above the target, tilt and shake; powder must land on the target."""
    pick(arm, held)
    goal = over(arm, target, 0.15 + height(held.label) / 2)
    tilt, goal = tilt_for(arm, goal)
    arm.move("tilt", goal, tilt)
    goal = align_spout(arm, held, target, goal, tilt)
    particles = []
    for k in range(3):
        arm.move(f"shake {k + 1} down", goal - [0, 0, 0.02], tilt)
        particles += spill(held, 8)
        arm.move(f"shake {k + 1} up", goal, tilt)
    share = landed_in(target, particles)
    return {"powder_on_target": round(share, 3), "ok": share >= 0.6}


def plan_place(arm: Arm, held: SceneObject, target: SceneObject, press: bool = False) -> dict:
    """Pick up the object and set it down in or on the target (heat, fry; blend also presses)."""
    pick(arm, held)
    t = top(target)
    depth = CONTAINERS.get(target.label, (0, 0, 0))[2]
    # down to 2 cm above the floor of the target, but the hand stays above a deep container's rim:
    # from there the object drops in
    goal = [t[0], t[1], max(t[2] - depth + height(held.label) + 0.02, t[2] + 0.01)]
    arm.move(f"over {target.label}", [t[0], t[1], SAFE])
    arm.move(f"lower into {target.label}", goal)
    arm.release()
    checks = {"in_target": rests_in(held, target)}
    if press:
        arm.move("above lid", [t[0], t[1], t[2] + 0.06])
        checks["pressed"] = arm.move("press", [t[0], t[1], t[2] + 0.02]) <= TOLERANCE
    arm.move("retreat", [t[0], t[1], SAFE])
    checks["ok"] = all(checks.values())
    return checks


def plan_dump(arm: Arm, held: SceneObject, target: SceneObject) -> dict:
    """Pick up the object, carry it over the target, turn the gripper over and let go."""
    pick(arm, held)
    goal = over(arm, target, 0.15 + height(held.label))
    tilt, turned = tilt_for(arm, goal)
    arm.move("turn over", turned, tilt)
    arm.release()
    ok = rests_in(held, target)
    arm.move("retreat", [goal[0], goal[1], SAFE])
    return {"in_target": ok, "ok": ok}


def plan_dip(arm: Arm, held: SceneObject, target: SceneObject) -> dict:
    """Lower the held object into the target below its rim, then lift it back out."""
    pick(arm, held)
    t = top(target)
    arm.move(f"over {target.label}", [t[0], t[1], SAFE])
    arm.move("dip", [t[0], t[1], t[2] - 0.015 + height(held.label) * 0.2])
    lowest = p.getAABB(held.body)[0][2]
    dipped = lowest < t[2] and inside(target, p.getBasePositionAndOrientation(held.body)[0])
    arm.move("lift out", [t[0], t[1], SAFE])
    out = p.getAABB(held.body)[0][2] > t[2]
    return {"dipped_below_rim": bool(dipped), "lifted_out": bool(out), "ok": bool(dipped and out)}


def plan_stroke(arm: Arm, held: SceneObject, target: SceneObject) -> dict:
    """Hold the object just above the target's surface and stroke across it three times."""
    pick(arm, held)
    t = top(target)
    lo, hi = p.getAABB(target.body)
    reach = max(0.02, (hi[0] - lo[0]) / 2 - 0.03)
    z = t[2] + height(held.label) + 0.01  # the held object skims the surface
    arm.move(f"over {target.label}", [t[0], t[1], SAFE])
    errors = [arm.move(f"stroke {k + 1}", [t[0] + (reach if k % 2 else -reach), t[1], z]) for k in range(4)]
    held_pos = p.getBasePositionAndOrientation(held.body)[0]
    arm.move("lift", [t[0], t[1], SAFE])
    on = lo[0] - 0.02 <= held_pos[0] <= hi[0] + 0.02 and lo[1] - 0.02 <= held_pos[1] <= hi[1] + 0.02
    ok = all(e <= TOLERANCE for e in errors) and on
    return {"strokes_reached": all(e <= TOLERANCE for e in errors), "over_target": bool(on), "ok": bool(ok)}


TILTING = frozenset({"pour", "fill", "sprinkle", "season", "dump"})
# predicate -> (role held by the gripper, role acted on, plan)
PLANS = {
    "pour": ("Theme", "Destination", plan_pour),
    "fill": ("Theme", "Destination", plan_pour),
    "sprinkle": ("Theme", "Destination", plan_sprinkle),
    "season": ("Instrument", "Theme", plan_sprinkle),
    "heat": ("Theme", "Instrument", plan_place),
    "fry": ("Theme", "Instrument", plan_place),
    "blend": ("Theme", "Destination", lambda arm, held, target: plan_place(arm, held, target, press=True)),
    "dump": ("Theme", "Destination", plan_dump),
    "dip": ("Theme", "Destination", plan_dip),
    "brush": ("Theme", "Destination", plan_stroke),
    "rub": ("Theme", "Destination", plan_stroke),
}


def choose_arm(robot: int, scene: Scene, held: SceneObject, target: SceneObject, tilts: bool = False) -> Arm:
    """The arm whose IK gets closest to both the pick and the target approach points (and, for plans
    that tilt, to a tilted pose above the target)."""
    best, best_cost = None, math.inf
    for side in ("left", "right"):
        arm = Arm(robot, side)
        arm.go_home()
        cost = max(arm.residual([*top(o)[:2], SAFE]) for o in (held, target))
        if tilts:
            t = top(target)
            orientation, point = tilt_for(arm, [t[0], t[1], t[2] + 0.12 + height(held.label) / 2])
            cost = max(cost, arm.residual(point, orientation))
        # reaching across the body sweeps the arm over the table: prefer the held object's side
        cost += 0.01 * ((top(held)[1] - TABLE_CENTRE[1] < 0) == (side == "left"))
        if cost < best_cost:
            best, best_cost = arm, cost
    return best
