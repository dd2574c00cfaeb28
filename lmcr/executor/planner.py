"""Joint-space paths that keep clear of the table, the objects and the robot: OMPL's RRT-Connect (the
planner MoveIt! uses by default) over the arm's seven joints, with the pybullet clearance check as
OMPL's state validity checker. A straight segment that is already clear is taken as it is."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from ompl import base as ob
from ompl import geometric as og
from ompl import util as ou

ou.setLogLevel(ou.LogLevel.LOG_NONE)  # OMPL's console chatter is no use to a CLI user
# One seed before any planner exists: a process then plans the same paths for the same scenes in the
# same order (a run, the bench) instead of new random ones each time.
SEED = 1
ou.RNG.setSeed(SEED)

RESOLUTION = 0.04  # radians between checked states along a motion
# RRT-Connect's budget for one segment, in clearance checks (about 1.5 s on one core) rather than in
# seconds: a time budget makes the found paths, and so the robot's motions, depend on the machine's load.
PLAN_CHECKS = 6000


def joint_path(clash: Callable[[np.ndarray], str | None], q0, q1, limits: np.ndarray,
               budget: int = PLAN_CHECKS) -> list[np.ndarray] | None:
    """A clear path q0 -> q1 (a list of configurations, q0 first), or None when OMPL finds none within
    `budget` clearance checks (0: only the straight segment). `clash(q)` names what the configuration hits,
    None when it is clear."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    if segment_clash(clash, q0, q1) is None:
        return [q0, q1]
    if budget <= 0:  # the straight motion or none
        return None
    space = ob.RealVectorStateSpace(len(q0))
    bounds = ob.RealVectorBounds(len(q0))
    for k, (lo, hi) in enumerate(limits):
        bounds.setLow(k, float(lo))
        bounds.setHigh(k, float(hi))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    checks = 0

    def valid(state) -> bool:
        nonlocal checks
        checks += 1
        return clash(np.array([state[k] for k in range(len(q0))])) is None

    si.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(RESOLUTION / space.getMaximumExtent())
    si.setup()
    start, goal = space.allocState(), space.allocState()
    for k in range(len(q0)):
        start[k], goal[k] = float(q0[k]), float(q1[k])
    problem = ob.ProblemDefinition(si)
    problem.setStartAndGoalStates(start, goal)
    planner = og.RRTConnect(si)
    planner.setProblemDefinition(problem)
    planner.setup()
    path = None
    while path is None and checks < budget:
        if not (planner.solve(ob.PlannerTerminationCondition(lambda: checks >= budget)) and problem.hasExactSolution()):
            break
        geometric = problem.getSolutionPath()
        og.PathSimplifier(si).simplifyMax(geometric)
        path = [np.array([s[k] for k in range(len(q0))]) for s in geometric.getStates()]
        # OMPL checks a motion at points spaced along its length, ours every RESOLUTION of the largest
        # joint step: a thin obstacle one misses the other may catch. A path is kept only when clear by
        # the check the rest of the planner uses; else planning goes on within the budget.
        if any(segment_clash(clash, a, b) for a, b in zip(path, path[1:])):
            path = None
            planner.clear()
            problem.clearSolutionPaths()
    del planner, problem, si  # released here: nanobind reports objects still alive at exit as leaks
    return path


def segment_clash(clash, q0, q1) -> str | None:
    """The first clash on the straight joint-space segment q0 -> q1, checked every RESOLUTION radians."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    n = max(1, int(np.ceil(np.max(np.abs(q1 - q0)) / RESOLUTION)))
    for k in range(1, n + 1):
        hit = clash(q0 + (q1 - q0) * k / n)
        if hit:
            return hit
    return None
