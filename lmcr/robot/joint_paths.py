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
# Every search starts from this seed (OMPL's seed generator is re-seeded, so the samplers a search makes
# draw the same numbers): the same motion request gets the same path whatever was planned before it in
# the process, so a scene's plan does not depend on which scenes a run or the bench did first.
SEED = 1

RESOLUTION = 0.04  # radians between checked states along a motion
# RRT-Connect's budget for one segment, in clearance checks (about 1.5 s on one core) rather than in
# seconds: a time budget makes the found paths, and so the robot's motions, depend on the machine's load.
PLAN_CHECKS = 6000


def joint_path(
    clash: Callable[[np.ndarray], str | None],
    q0,
    q1,
    limits: np.ndarray,
    budget: int = PLAN_CHECKS,
    seed: int = SEED,
    smooth: bool = True,
) -> list[np.ndarray] | None:
    """A clear path q0 -> q1 (a list of configurations, q0 first), or None when OMPL finds none within
    `budget` clearance checks (0: only the straight segment). `clash(q)` names what the configuration hits,
    None when it is clear. The search is seeded with `seed`. Without `smooth`, a path found clear is
    returned as found, for `smooth_path` to shorten once the plan it is part of holds: shortening took most
    of a search's time (0.36 of 0.44 s), and most paths belong to variants that fail at a later step."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    if segment_clash(clash, q0, q1) is None:
        return [q0, q1]
    # the straight motion or none; and none to or from a configuration that clashes: RRT-Connect waits
    # for a valid goal state without counting a check, so the budget would never end its search
    if budget <= 0 or clash(q0) or clash(q1):
        return None
    ou.RNG.setSeed(seed)  # before the search makes its samplers (OMPL logs, unseen, that seeds were drawn before)
    checks = 0

    def valid(state) -> bool:
        nonlocal checks
        checks += 1
        return clash(_config(state, len(q0))) is None

    space, si = _space_information(valid, limits)
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
        raw = _states(geometric, len(q0))
        if not smooth and _clear(clash, raw):
            path = raw
            break
        og.PathSimplifier(si).simplifyMax(geometric)
        # OMPL checks a motion at points spaced along its length, ours every RESOLUTION of the largest
        # joint step: a thin obstacle one misses the other may catch (seen most after shortcutting). The
        # simplified path is kept when clear by the check the rest of the planner uses, else the path as
        # found; else planning goes on within the budget.
        path = next((c for c in (_states(geometric, len(q0)), raw) if _clear(clash, c)), None)
        if path is None:
            planner.clear()
            problem.clearSolutionPaths()
    del planner, problem, si  # released here: nanobind reports objects still alive at exit as leaks
    return path


def smooth_path(
    clash: Callable[[np.ndarray], str | None], path: list[np.ndarray], limits: np.ndarray, seed: int = SEED
) -> list[np.ndarray]:
    """`path` shortened by OMPL's simplifier (seeded with `seed`) when the shortened path is clear by
    `clash` as `joint_path` checks it, else `path` as it is (as `joint_path` keeps a path found clear)."""
    if len(path) <= 2:  # a straight segment: nothing to shorten
        return path
    ou.RNG.setSeed(seed)
    space, si = _space_information(lambda state: clash(_config(state, len(path[0]))) is None, limits)
    geometric = og.PathGeometric(si)
    for q in path:
        state = space.allocState()
        for k, value in enumerate(q):
            state[k] = float(value)
        geometric.append(state)
    og.PathSimplifier(si).simplifyMax(geometric)
    shortened = _states(geometric, len(path[0]))
    del geometric, si
    return shortened if _clear(clash, shortened) else path


def _space_information(valid: Callable, limits: np.ndarray):
    """The joint space within `limits` and OMPL's space information with `valid` as its state checker."""
    space = ob.RealVectorStateSpace(len(limits))
    bounds = ob.RealVectorBounds(len(limits))
    for k, (lo, hi) in enumerate(limits):
        bounds.setLow(k, float(lo))
        bounds.setHigh(k, float(hi))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(valid)
    si.setStateValidityCheckingResolution(RESOLUTION / space.getMaximumExtent())
    si.setup()
    return space, si


def _states(geometric, n: int) -> list[np.ndarray]:
    return [_config(s, n) for s in geometric.getStates()]


def _config(state, n: int) -> np.ndarray:
    """An OMPL state's n joint values."""
    return np.array([state[k] for k in range(n)])


def _clear(clash, path: list[np.ndarray]) -> bool:
    return not any(segment_clash(clash, a, b) for a, b in zip(path, path[1:]))


def segment_clash(clash, q0, q1) -> str | None:
    """The first clash on the straight joint-space segment q0 -> q1, checked every RESOLUTION radians."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    n = max(1, int(np.ceil(np.max(np.abs(q1 - q0)) / RESOLUTION)))
    for k in range(1, n + 1):
        hit = clash(q0 + (q1 - q0) * k / n)
        if hit:
            return hit
    return None
