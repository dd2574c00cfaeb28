"""Acting out a feasible plan in the simulation: follow each planned path with the joint motors, grasp,
pour or let go where the program says, then run the task's checks on what happened."""

from __future__ import annotations

import numpy as np
import pybullet as p

from lmcr.executor.arm import settle
from lmcr.executor.plan import Plan
from lmcr.executor.scene import SceneObject, footprint
from lmcr.executor.tasks import Outcome, Task

TOLERANCE = 0.02  # metres: a waypoint counts as reached within this
MOVED = 0.02  # metres: an object not in the task that moved further was knocked


def run_plan(plan: Plan, task: Task, held: SceneObject, target: SceneObject, others: list[SceneObject]) -> dict:
    """Execute `plan`; the result's `checks` hold the task's checks (and whether the `others`, the objects
    not in the task, stayed where they were) and `success` whether all passed."""
    arm, other = plan.arm, plan.other
    before = {o.label: p.getBasePositionAndOrientation(o.body)[0] for o in others}
    target_at = p.getBasePositionAndOrientation(target.body)[0]
    for a, q in ((other, other.parked), (arm, arm.home)):
        a.set_config(q)
        a.hold(q)
    if plan.carried is not None:
        plan.carried.place(arm)
        arm.attach(held.body)
    out, grasped, released = Outcome(), True, False
    knocked_during: dict[str, str] = {}  # object -> the step during which it was first found moved
    for segment in plan.segments:
        step = segment.step
        if step.kind == "move":
            arm.follow(segment.path)
            arm.record(step.name, segment.goal)
            if step.probe:
                out.probes[step.probe] = (p.getBasePositionAndOrientation(held.body)[0], p.getAABB(held.body))
        elif step.kind == "grasp":
            grasped = arm.grasp(held.body, footprint(held.label))
            if not grasped:
                break  # nothing in the hand: the rest of the program would act out nothing
        elif step.kind == "release":
            arm.release()
            released = True
        elif step.kind == "spill":
            out.particles += spill(held, plan.geometry.opening, step.particles)
        for label in _moved(others, before):
            knocked_during.setdefault(label, step.name)
    if out.particles or released:
        settle(480)  # let what was poured or let go come to rest
    checks = task.check(held, target, out) if grasped else {"ok": False}
    within = all(w["error_m"] <= TOLERANCE for w in arm.log)
    moved = _moved(others, before)
    # how far the target was pushed: not a check of its own (the task's checks fail when it matters),
    # but the reason to name when they do
    pushed = float(np.linalg.norm(np.subtract(p.getBasePositionAndOrientation(target.body)[0], target_at)))
    return {"success": bool(checks["ok"] and within and grasped and not moved), "waypoints": arm.log,
            "target_moved_m": round(pushed, 3),
            "checks": {**{k: v for k, v in checks.items() if k != "ok"}, "verb_check": bool(checks["ok"]),
                       "grasped": grasped, "waypoints_within_tolerance": within, "knocked": moved},
            **({"knocked_during": {k: knocked_during.get(k, "settling") for k in moved}} if moved else {})}


def _moved(others: list[SceneObject], before: dict[str, tuple]) -> list[str]:
    """The objects (not in the task) that are now more than MOVED from where they stood."""
    return sorted(o.label for o in others
                  if np.linalg.norm(np.subtract(p.getBasePositionAndOrientation(o.body)[0], before[o.label])) > MOVED)


def spill(held: SceneObject, opening: float, n: int) -> list[int]:
    """A stream of particles (liquid or powder) leaving the held container's opening (`opening` above
    its origin), one at a time: particles created on top of each other would push each other apart."""
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=0.006)
    visual = p.createVisualShape(p.GEOM_SPHERE, radius=0.006, rgbaColor=[0.2, 0.4, 0.9, 1])
    rng = np.random.default_rng(n)
    bodies = []
    for _ in range(n):
        pos, orn = p.getBasePositionAndOrientation(held.body)
        mouth = np.asarray(p.multiplyTransforms(pos, orn, [0, 0, opening], [0, 0, 0, 1])[0])
        body = p.createMultiBody(0.002, shape, visual, list(mouth + rng.normal(0, 0.002, 3)))
        p.changeDynamics(body, -1, lateralFriction=1.0, rollingFriction=0.02, spinningFriction=0.02)  # grains stay put
        bodies.append(body)
        settle(12)
    return bodies
