"""Acting out a feasible plan in the simulation: follow each planned path with the joint motors, grasp,
pour or let go where the program says, then run the task's checks on what happened."""

from __future__ import annotations

import numpy as np
import pybullet as p

from lmcr.robot.arm import relative_pose, settle
from lmcr.robot.pieces import cut_through
from lmcr.robot.plan import Plan, Planner, pick_steps, shifted
from lmcr.robot.scene import TOOLS, SceneObject, depth
from lmcr.robot.tasks import SCOOP_GRAINS, Outcome, hinged, in_palm

TOLERANCE = 0.02  # metres: a waypoint counts as reached within this
MOVED = 0.02  # metres: an object not in the task that moved further was knocked
# a poured drop or grain, 6 mm across: twice that, they piled up like marbles and rolled off round food
# (cinnamon shaken over an apple: 0.21-0.38 stayed on it, 0.75-0.96 at this size)
GRAIN_RADIUS = 0.003
FINGERS_SET = 60  # simulation steps (1/4 s) for the fingers to take their shape before the arm moves


def run_plan(
    plan: Plan, held: SceneObject, target: SceneObject, others: list[SceneObject], planner: Planner | None = None
) -> dict:
    """Execute `plan` (its task); the result's `checks` hold the task's checks (and `knocked`: the ids of the
    `others`, the objects not in the task, that did not stay where they were) and `success` whether all
    passed. With the `planner`, a grasp that left the object in the hand otherwise than planned has the
    rest planned afresh."""
    lead = plan.first or plan  # the arm that moves first starts at home, the other parked, both hands open
    for a, q in ((lead.other, lead.other.parked), (lead.arm, lead.arm.home)):
        a.set_config(q)
        a.hold(q)
        a.open_fingers()
    if plan.first is not None:  # an object set down out of the way or within reach; the checks start from there
        _act(plan.first, plan.first.geometry.held, Outcome(), planner=planner)
        settle(120)
    before = {o.id: p.getBasePositionAndOrientation(o.body)[0] for o in others}  # by id: two cups are two
    target_at = p.getBasePositionAndOrientation(target.body)[0]
    out = Outcome()
    knocked_during: dict[str, str] = {}
    if plan.opens is not None:  # a drawer or a lid opened first
        knocked_during = _act(plan.opens, target, Outcome(), others, before)[2]
    grasped, released, knocked = _act(plan, held, out, others, before, planner)
    knocked_during = {**knocked, **knocked_during}  # the step it was first seen moved in
    if out.particles or released:
        settle(480)  # let what was poured or let go come to rest
    if plan.shuts is not None and grasped:  # and shut over what was put in
        knocked_during = {**_act(plan.shuts, target, Outcome(), others, before)[2], **knocked_during}
        settle(120)
    checks = plan.task.check(held, target, out) if grasped else {"ok": False}
    log = [w for a in plan.moving_arms for w in a.log]  # both parts' waypoints, in order
    within = all(w["error_m"] <= TOLERANCE for w in log)
    moved = _moved(others, before)
    # how far the target was pushed: not a check of its own (the task's checks fail when it matters),
    # but the reason to name when they do
    pushed = float(np.linalg.norm(np.subtract(p.getBasePositionAndOrientation(target.body)[0], target_at)))
    return {
        "success": bool(checks["ok"] and within and grasped and not moved),
        "waypoints": log,
        "target_moved_m": round(pushed, 3),
        "replanned_after_grasp": out.replanned,
        "checks": {
            **{k: v for k, v in checks.items() if k != "ok"},
            "verb_check": bool(checks["ok"]),
            "grasped": grasped,
            "waypoints_within_tolerance": within,
            "knocked": moved,
        },
        **({"knocked_during": {k: knocked_during.get(k, "settling") for k in moved}} if moved else {}),
    }


def _act(
    plan: Plan,
    held: SceneObject,
    out: Outcome,
    others: list[SceneObject] = (),
    before: dict[str, tuple] | None = None,
    planner: Planner | None = None,
) -> tuple[bool, bool, dict[str, str]]:
    """Follow the plan's segments: move, grasp, let go and pour where it says. Returns whether the grasp
    held, whether the object was let go, and for each of the `others` found moved (from `before`) the
    step during which it was first seen moved. Once the object is picked up, when it sits in the hand
    otherwise than planned, the rest is planned afresh (kept as planned when no new plan is found)."""
    arm = plan.arm
    _ready_hand(arm, plan, held)
    grasped, released = True, False
    knocked_during: dict[str, str] = {}
    segments, picked = list(plan.segments), pick_steps([s.step for s in plan.segments])
    k = 0
    while k < len(segments):
        grasped, let_go = _take_step(arm, segments[k], plan, held, out)
        if not grasped:
            break  # nothing in the hand: the rest of the program would act out nothing
        released = released or let_go
        for ident in _moved(others, before or {}):
            knocked_during.setdefault(ident, segments[k].step.name)
        k += 1
        if k == picked and planner is not None:
            again = _replan_if_shifted(arm, plan, held, planner)
            if again is not None:
                plan, segments[k:], out.replanned = again, again.segments, True
    return grasped, released, knocked_during


def _ready_hand(arm, plan: Plan, held: SceneObject) -> None:
    """Shape the hand before it moves: closed on the object when it is handed over, else in the shape
    the plan approaches in."""
    if plan.carried is not None:
        arm.shape_fingers(arm.finger_targets(plan.half_width), now=True)
        plan.carried.place(arm)
        arm.attach(held.body)
    else:
        arm.shape_fingers(plan.fingers)
        if not arm.fingers_at(plan.fingers):
            settle(FINGERS_SET)


def _take_step(arm, segment, plan: Plan, held: SceneObject, out: Outcome) -> tuple[bool, bool]:
    """Act out one segment: move, grasp, let go, or one of the other actions. Returns whether the hand still
    holds what it should (False only when a grasp failed) and whether the object was let go."""
    step = segment.step
    if step.moves:
        arm.follow(segment.path)
        arm.record(step.name, segment.goal)
        if step.probe:
            out.probes[step.probe] = (p.getBasePositionAndOrientation(held.body)[0], p.getAABB(held.body))
    elif step.kind == "grasp":
        return arm.grasp(held.body, plan.half_width), False
    elif step.kind == "release":
        arm.release(plan.fingers)
        return True, True
    else:
        _ACTIONS[step.kind](arm, step, plan, held, out)
    return True, False


def _spill(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    out.particles += spill(held, plan.geometry.opening, step.particles)


def _give(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    out.taken = take(held, plan.geometry.target)


def _hook(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    # what an opening plan holds is the target itself, by the link its joint moves (pybullet numbers them alike)
    arm.hook(held.body, held.joint, turns=hinged(held))


def _unhook(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    arm.unhook()


def _blade_in(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    """The simulation cannot cut: the blade passes through the food (whether it went through, `_cut`)."""
    p.setCollisionFilterPair(held.body, plan.geometry.target.body, -1, -1, 0)


def _cut(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    out.pieces, out.cut = cut_through(held, plan.geometry.target)


def _scoop(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    """Fill the ladle; what it took clings to it (as a grasp holds) until it is tipped out: loose grains on
    a floor open at the spout ratchet out of it as the arm starts and stops, which a thick soup does not."""
    out.particles += fill(held, plan.geometry.source)
    out.clinging = [fix_to(held.body, grain) for grain in out.particles]


def _run_out(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    """What the ladle carries is let go of: tipped, it runs out over the spout (or stays, tipped wrongly)."""
    for constraint in out.clinging:
        p.removeConstraint(constraint)
    out.clinging = []


def _empty(arm, step, plan: Plan, held: SceneObject, out: Outcome) -> None:
    settle(240)  # the hand held tipped while what the ladle carried runs out


# the steps that neither move the arm nor grasp or let go (tasks.Step.kind)
_ACTIONS = {
    "spill": _spill,
    "give": _give,
    "hook": _hook,
    "unhook": _unhook,
    "blade in": _blade_in,
    "cut": _cut,
    "scoop": _scoop,
    "run out": _run_out,
    "empty": _empty,
}


def take(held: SceneObject, person: SceneObject) -> bool:
    """The person's hand closes on the object when it lies in the hand (`tasks.in_palm`): it is then held
    where it is. False when it does not (the person cannot take what is not in their hand)."""
    if not in_palm(held, person):
        return False
    fix_to(person.body, held.body)
    return True


def fix_to(body: int, other: int) -> int:
    """Hold `other` rigidly where it now is relative to `body` (a hand that took it, a ladle it clings to);
    returns the constraint."""
    pose = p.getBasePositionAndOrientation
    rel_pos, rel_orn = relative_pose(*pose(body), *pose(other))
    return p.createConstraint(body, -1, other, -1, p.JOINT_FIXED, [0, 0, 0], rel_pos, [0, 0, 0], rel_orn)


def _replan_if_shifted(arm, plan: Plan, held: SceneObject, planner: Planner) -> Plan | None:
    """A new plan for the rest when the picked-up object sits in the hand otherwise than planned (None
    when it sits as planned, or when no new plan is found)."""
    in_hand = relative_pose(*arm.ee_pose(), *p.getBasePositionAndOrientation(held.body))
    if not shifted(plan.geometry.in_hand(plan.variant), in_hand):
        return None
    return planner.replan_in_hand(plan, in_hand)


def _moved(others: list[SceneObject], before: dict[str, tuple]) -> list[str]:
    """The ids of the objects (not in the task) that are now more than MOVED from where they stood."""
    return sorted(
        o.id
        for o in others
        if np.linalg.norm(np.subtract(p.getBasePositionAndOrientation(o.body)[0], before[o.id])) > MOVED
    )


def spill(held: SceneObject, opening: float, n: int) -> list[int]:
    """A stream of particles (liquid or powder) leaving the held container's opening (`opening` above
    its origin), one at a time: particles created on top of each other would push each other apart."""
    return _grains(held, [0, 0, opening], (0.002, 0.002, 0.002), n)


def fill(ladle: SceneObject, source: SceneObject) -> list[int]:
    """SCOOP_GRAINS of the source's content in the ladle's bowl when the bowl is in the source, below its
    rim and above its floor (the simulation has no liquid to scoop: what the source holds is made where the
    ladle takes it); none when it is not there."""
    scoop = TOOLS[ladle.shape].scoop
    pos, orn = p.getBasePositionAndOrientation(ladle.body)
    bowl = p.multiplyTransforms(pos, orn, scoop, [0, 0, 0, 1])[0]
    lo, hi = p.getAABB(source.body, source.link)
    within = lo[0] <= bowl[0] <= hi[0] and lo[1] <= bowl[1] <= hi[1]
    if not within or not hi[2] - depth(source.shape) < bowl[2] < hi[2]:
        return []
    # spread over the bowl's floor, a grain above it
    return _grains(ladle, np.add(scoop, [0, 0, 2 * GRAIN_RADIUS]), (0.008, 0.008, 0.001), SCOOP_GRAINS)


def _grains(held: SceneObject, at, spread: tuple[float, float, float], n: int) -> list[int]:
    """`n` grains made one at a time about the point `at` of the held object (its frame), strewn at random
    (`spread`: the standard deviation along x, y, z): grains made on top of each other would push each
    other apart."""
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=GRAIN_RADIUS)
    visual = p.createVisualShape(p.GEOM_SPHERE, radius=GRAIN_RADIUS, rgbaColor=[0.2, 0.4, 0.9, 1])
    rng = np.random.default_rng(n)
    bodies = []
    for _ in range(n):
        pos, orn = p.getBasePositionAndOrientation(held.body)
        point = np.asarray(p.multiplyTransforms(pos, orn, list(at), [0, 0, 0, 1])[0])
        body = p.createMultiBody(0.002, shape, visual, list(point + rng.normal(0, spread, 3)))
        p.changeDynamics(body, -1, lateralFriction=1.0, rollingFriction=0.02, spinningFriction=0.02)  # grains stay put
        bodies.append(body)
        settle(12)
    return bodies
