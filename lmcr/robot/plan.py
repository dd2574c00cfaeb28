"""Feasibility before acting: a task's whole motion is planned before the robot moves. Every waypoint
needs an inverse-kinematics solution and a collision-free configuration, every motion between them a
collision-free joint-space path (OMPL); the arm, the grasp yaw and the tilt direction are chosen by what
is feasible. When no arm can do the task as the table stands, an object is first set down elsewhere
(the one in the hand, the held one nearer the other arm, the one in the way) and the task planned afresh
from there. An infeasible task gives the reason and leaves the world untouched.

Over 400 lines on purpose: `Planner` and the helpers below it search one task's variants together,
saving and restoring the same objects' poses and the hand's contents; split apart, each part would reach
back into the others' state. Joint-space paths are `joint_paths.py`, acting the plan out is `act.py`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import pybullet as p

from lmcr.robot.arm import IK_POSITION, IK_ROTATION, Arm, relative_pose, rotation_error
from lmcr.robot.budget import Budget
from lmcr.robot.collision import Carried, Clearance
from lmcr.robot.household import household
from lmcr.robot.joint_paths import PLAN_CHECKS, joint_path, segment_clash, smooth_path
from lmcr.robot.scene import TABLE_TOP, Scene, SceneObject, height, world_xy
from lmcr.robot.tasks import (
    GRIP_GAP,
    OPENING,
    Geometry,
    Step,
    Task,
    Variant,
    opening_point,
    opening_steps,
    put_down,
    variants,
)

SIDES = ("left", "right")
# an object the grasp pushed further than this (or turned more) is not where the plan has it in the hand
SHIFTED, TURNED = 0.005, 0.05
# an object put into a container passes its walls this far clear, on a straight line through waypoints
# this far apart (a joint-space segment between far-apart poses bows off the line by millimetres)
FIT_MARGIN, INTO_STEP = 0.002, 0.01
BRANCH_JUMP = 0.3  # radians: a joint turning this much between two waypoints 1 cm apart is another arm configuration


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
    task: Task
    first: Plan | None = None  # run before: an object set down elsewhere (`plan_via`)
    instead_of: Infeasible | None = None  # with `first`: why the task alone was not planned
    opens: Plan | None = None  # run before the task: the target drawer or lid opened (`plan_shut_receptacle`)
    shuts: Plan | None = None  # run after it: shut again

    @property
    def fingers(self) -> list[float]:
        """The finger joint targets the hand approaches the grasp with (and goes back to on letting go)."""
        return approach_fingers(self.arm, self.variant, self.geometry.held.shape)

    @property
    def half_width(self) -> float:
        """Half the held object's width between the fingers as they hold it."""
        return self.variant.half_across(self.geometry.held.shape)

    @property
    def moving_arms(self) -> list[Arm]:
        """The arms that move, in order: the first part's, then the task's (once when they are one)."""
        lead = self.first.arm if self.first else self.arm
        return [lead] + ([self.arm] if self.arm is not lead else [])  # a drawer's parts use the task's arm


@dataclass
class Infeasible:
    reason: str
    progress: int = 0  # steps planned before the one that failed (the best attempt's reason is reported)
    out_of_reach: bool = False  # it failed for want of an IK solution (not an obstacle in the way)
    blocker: str = ""  # else what was in the way, as a clash names it ("the pot")
    unreachable: str = ""  # with out_of_reach: the object the pose out of reach is at, named so ("the soup")


@dataclass
class Planner:
    """Plans tasks in a built world: `robot`, the scene's objects and the table body; its searches together
    stop when the `budget` is spent (from the planner's making): `stopped` then says after how much."""

    robot: int
    scene: Scene
    table: int
    budget: Budget = field(default_factory=Budget)
    arms: dict[str, Arm] = field(default_factory=dict)
    stopped: str = ""  # "search stopped after 20 s / 2,000 IK calls" once the budget ended the search
    started: float = field(default_factory=time.perf_counter)

    def __post_init__(self) -> None:
        self.arms = {side: Arm(self.robot, side) for side in SIDES}

    def spent(self) -> bool:
        """Whether the budget is spent (from now on every search returns at once, with what it found)."""
        if not self.stopped:
            seconds, solved = time.perf_counter() - self.started, sum(a.ik_calls for a in self.arms.values())
            if seconds >= self.budget.seconds or solved >= self.budget.ik_calls:
                self.stopped = f"search stopped after {seconds:.0f} s / {solved:,} IK call{'s' * (solved != 1)}"
        return bool(self.stopped)

    def plan(
        self,
        task: Task,
        held: SceneObject,
        target: SceneObject,
        holding: bool,
        arms: tuple[str, ...] = SIDES,
        start: str | np.ndarray = "home",
    ) -> Plan | Infeasible:
        """The first feasible plan over the `arms` (the nearer one first) and the task's variants, or the
        reason of the attempt that got furthest. The arm starts at its `start` configuration ("home",
        "parked": then it first moves home, or joints: where opening a door left it), the other one parked.
        A spent budget ends the search."""
        sides = _nearer_first(held if not holding else target, arms)
        best = Infeasible("nothing was tried", -1)
        for side in sides:
            arm, other = self.arms[side], self.arms[SIDES[1 - SIDES.index(side)]]
            saved = _save(held)
            try:
                other.set_config(other.parked)
                other.shape_fingers(other.finger_open, now=True)
                begin = getattr(arm, start) if isinstance(start, str) else start
                arm.set_config(begin)
                if holding:
                    _put_in_hand(arm, held)
                g = Geometry.measure(held, target, task.source)
                standing = _save(held)
                clearance = Clearance(arm, self._obstacles(held))
                failed_grasps = set()
                for variant in _variants(held, task, holding, arm.opening):
                    if self.spent():
                        return best
                    grasp = (variant.yaw, variant.pitch, variant.side, variant.shift, variant.narrow)
                    if grasp in failed_grasps:
                        continue  # the same pick-up failed already: only the later steps differ
                    # the last attempt's checks left the held object in its hand: it stands where it started
                    _restore(held, standing)
                    # the fingers as they will be on the way: collision checks see them so
                    arm.shape_fingers(approach_fingers(arm, variant, held.shape), now=True)
                    planned = Carried(held.body, *g.in_hand(variant))  # held as this grasp will hold it
                    carried = planned if holding else None
                    steps = [
                        *([Step("home", "to its start")] if isinstance(start, str) and start != "home" else []),
                        *task.program(g, variant, holding),
                    ]
                    result = _hemmed_in(arm, clearance, steps, held, target, planned)
                    result = result or self._plan_variant(arm, clearance, steps, held, target, carried, begin)
                    _restore(held, standing)  # the checks of carried motions left it in the hand
                    found = g
                    if isinstance(result, list) and not holding:
                        result, found = self._as_grasped(arm, other, begin, result, steps, task, g, variant)
                        _restore(held, standing)
                    if isinstance(result, list):
                        return Plan(arm, other, variant, result, carried, found, task)
                    if result.progress < pick_steps(steps):
                        failed_grasps.add(grasp)
                    if result.progress > best.progress:
                        best = result
            finally:
                arm.set_config(arm.home)
                arm.shape_fingers(arm.finger_open, now=True)
                _restore(held, saved)
        return best

    def plan_via(
        self,
        task: Task,
        held: SceneObject,
        target: SceneObject,
        moved: SceneObject,
        holding: bool,
        spots: list[tuple[float, float]],
    ) -> Plan | Infeasible:
        """Set `moved` (in the hand when `holding`, else on the table) down at the first of the free `spots`
        where that works and park that arm, then do the task with either arm: what the hand holds is out
        of the way, or the held object is passed from one arm's reach to the other's. Both parts are
        planned before anything moves, the task in the world as the first part leaves it. A spent budget
        ends the search."""
        best = Infeasible(f"found no free spot to put {_named(moved)} down", -1)
        for xy in spots:
            for side in SIDES:
                if self.spent():
                    return best
                first = self.plan(put_down(xy), moved, moved, holding, arms=(side,))
                if isinstance(first, Infeasible):
                    best = first if first.progress > best.progress else best
                    continue
                saved, was_at, on_table = _save(moved), moved.xy, moved in self.scene.objects
                _stand_at(moved, xy)
                moved.xy = xy
                if not on_table:
                    self.scene.objects.append(moved)
                try:
                    rest = self.plan_as_it_stands(task, held, target, holding=False, start="parked")
                finally:
                    if not on_table:
                        self.scene.objects.remove(moved)
                    moved.xy = was_at
                    _restore(moved, saved)
                if isinstance(rest, Plan):
                    return replace(rest, first=first)
                best = rest if rest.progress >= best.progress else best
        return best

    def plan_as_it_stands(
        self, task: Task, held: SceneObject, target: SceneObject, holding: bool, start: str = "home"
    ) -> Plan | Infeasible:
        """The task planned with nothing set down first: into a shut receptacle (a drawer, a fridge, a cupboard) through
        its opening (`plan_shut_receptacle`), else directly (`plan`), the arm from its `start`."""
        if target.joint >= 0:
            return self.plan_shut_receptacle(task, held, target, holding, start)
        return self.plan(task, held, target, holding, start=start)

    def plan_shut_receptacle(
        self, task: Task, held: SceneObject, target: SceneObject, holding: bool, start: str = "home"
    ) -> Plan | Infeasible:
        """Into a drawer, a chest fridge or a cupboard: open it, do the task with it open, shut it, all three
        with one arm (the nearer first; the other parked), each part planned in the world the one before
        leaves (the held object lying in it for the shutting), the arm from its `start` ("home" or
        "parked"). Refused at once when the held object is too tall to shut the drawer or the lid over it,
        or to stand in the cupboard. A spent budget ends the search."""
        found = household()[target.shape].opening
        if height(held.shape) > found.headroom:
            room = f"to stand in {_named(target)}" if found.entry == "front" else f"to shut {_named(target)} over it"
            return Infeasible(f"{_named(held)} is too tall {room}", 0, False, _named(target))
        best = Infeasible("nothing was tried", -1)
        for side in _nearer_first(target, SIDES):
            if self.spent():
                return best
            result = self._opened_with(side, task, held, target, holding, start)
            if isinstance(result, Plan):
                return result
            best = result if result.progress > best.progress else best
        return best

    def _opened_with(
        self, side: str, task: Task, held: SceneObject, target: SceneObject, holding: bool, start: str
    ) -> Plan | Infeasible:
        arm, other = self.arms[side], self.arms[SIDES[1 - SIDES.index(side)]]
        other.set_config(other.parked)
        opening = self._open_or_shut(arm, other, target, True, getattr(arm, start))
        if isinstance(opening, Infeasible):
            return opening
        saved = _save(held)
        p.resetJointState(target.body, target.joint, household()[target.shape].opening.joint_at(True))
        # on from its start, or from above the handle when the open door stood in the way back there
        resume = "home" if opening.segments[-1].step.kind == "home" else opening.segments[-1].path[-1]
        try:
            rest = self.plan(task, held, target, holding, arms=(side,), start=resume)
            if isinstance(rest, Infeasible):
                return replace(rest, progress=rest.progress + len(opening.segments))
            bottom = opening_point(target, "middle") + [0, 0, 0.002]  # as it will lie in it, upright
            p.resetBasePositionAndOrientation(
                held.body, [*bottom[:2], bottom[2] + height(held.shape) / 2], (0, 0, 0, 1)
            )
            end = next(s.path[-1] for s in reversed(rest.segments) if s.path is not None)
            shutting = self._open_or_shut(arm, other, target, False, end, moving=held)
        finally:
            p.resetJointState(target.body, target.joint, household()[target.shape].opening.joint_at(False))
            _restore(held, saved)
            arm.set_config(arm.home)
        if isinstance(shutting, Infeasible):
            return replace(shutting, progress=shutting.progress + len(opening.segments) + len(rest.segments))
        return replace(rest, opens=opening, shuts=shutting)

    def _open_or_shut(
        self,
        arm: Arm,
        other: Arm,
        target: SceneObject,
        opening: bool,
        start: np.ndarray,
        moving: SceneObject | None = None,
    ) -> Plan | Infeasible:
        """The drawer, lid or door opened (then the arm back at its start, or, where the open door leaves it
        no clear way there, up from the handle) or shut, from joints `start`; `moving`: what lies in it (a
        drawer carries it along, no obstacle). What follows the motion along the joint is planned with the
        drawer, lid or door where that motion leaves it (an open lid stands in the way home); the joint is
        left as it was."""
        away = opening and not np.array_equal(start, arm.home)  # parked: it comes to its start first
        steps = [
            *([Step("home", "to its start")] if away else []),
            *opening_steps(target, opening),
            *([Step("home", "to its start")] if opening else []),
        ]
        moved = next(i for i, step in enumerate(steps) if step.kind == "unhook")
        obstacles = {
            body: name for body, name in self._obstacles(target).items() if moving is None or body != moving.body
        }
        clearance, was = Clearance(arm, obstacles), p.getJointState(target.body, target.joint)[0]
        arm.set_config(start)
        found = self._plan_variant(arm, clearance, steps[:moved], target, target, None, start)
        if isinstance(found, Infeasible):
            return found
        p.resetJointState(target.body, target.joint, household()[target.shape].opening.joint_at(opening))
        try:
            rest = self._plan_variant(arm, clearance, steps[moved:], target, target, None, found[-1].path[-1])
            if isinstance(rest, Infeasible) and opening and rest.progress == len(steps) - moved - 1:
                rest = self._plan_variant(arm, clearance, steps[moved:-1], target, target, None, found[-1].path[-1])
        finally:
            p.resetJointState(target.body, target.joint, was)
        if isinstance(rest, Infeasible):
            return replace(rest, progress=rest.progress + moved)
        return Plan(arm, other, Variant(), found + rest, None, Geometry.measure(target, target), OPENING)

    def replan_in_hand(self, plan: Plan, in_hand: tuple) -> Plan | None:
        """The rest of `plan` (after the pick-up) planned afresh from where its arm is, for the held object
        at pose `in_hand` relative to the gripper (as found): a grasp can push the object before the
        fingers hold it, and the planned motions then carry it somewhere else (into the target's rim).
        None when no plan is found; the simulation is left as it was."""
        state = p.saveState()
        try:
            g = replace(plan.geometry, grasped=in_hand)
            result = self._rest_in_hand(plan.arm, plan.task, plan.variant, g, plan.arm.config())
        finally:
            p.restoreState(state)
            p.removeState(state)
        carried = Carried(g.held.body, *in_hand)
        return replace(plan, segments=result, carried=carried, geometry=g) if isinstance(result, list) else None

    def _rest_in_hand(
        self, arm: Arm, task: Task, variant: Variant, g: Geometry, start: np.ndarray
    ) -> list[Segment] | Infeasible:
        """The task's steps after the pick-up, planned from joints `start` for the held object in the hand
        at `g`'s grasped pose."""
        held = g.held
        return self._plan_variant(
            arm,
            Clearance(arm, self._obstacles(held)),
            task.program(g, variant, True),
            held,
            g.target,
            Carried(held.body, *g.grasped),
            start,
        )

    def _as_grasped(
        self,
        arm: Arm,
        other: Arm,
        start: np.ndarray,
        segments: list[Segment],
        steps: list[Step],
        task: Task,
        g: Geometry,
        variant: Variant,
    ) -> tuple[list[Segment] | Infeasible, Geometry]:
        """A planned pick-up checked by simulating it as it will run (`_simulated_grasp`), and the
        geometry the rest of the plan holds for. A grasp that would leave the object outside the fingers
        is infeasible; one whose fingers would push it (more than `shifted` allows) has the rest planned
        before acting for the object as it will sit in the hand (infeasible when no such plan exists:
        the old one would carry it into the target's rim, or pour beside the target)."""
        picked = pick_steps(steps)
        in_hand = _simulated_grasp(arm, other, start, segments, g.held, variant)
        if in_hand is None:
            return Infeasible(f"{_named(g.held)} would slip from the {arm.side} hand's grasp", picked - 2), g
        if not shifted(g.in_hand(variant), in_hand):
            return segments, g
        found = replace(g, grasped=in_hand)
        rest = self._rest_in_hand(arm, task, variant, found, segments[picked - 1].path[-1])
        if isinstance(rest, Infeasible):
            return replace(
                rest,
                reason=f"{rest.reason} (with {_named(g.held)} as the fingers would push it)",
                progress=picked + rest.progress,
            ), g
        return segments[:picked] + rest, found

    def on_table(self, name: str) -> SceneObject | None:
        """The object on the table a clash names ("the pot"; None for the table or the robot)."""
        return next((o for o in self.scene.objects if _named(o) == name), None)

    def _obstacles(self, held: SceneObject) -> dict[int, str]:
        # what the robot was handed counts too: once set down it stands on the table (planning again
        # after a later grasp must keep clear of it)
        things = {o.body: _named(o) for o in self.scene.present if o.body != held.body}
        return {self.table: "the table", **things, held.body: _named(held)}

    def _plan_variant(  # noqa: C901 - a case per step kind, each failing its own way
        self,
        arm: Arm,
        clearance: Clearance,
        steps: list[Step],
        held: SceneObject,
        target: SceneObject,
        carried: Carried | None,
        start: np.ndarray,
    ) -> list[Segment] | Infeasible:
        # a pose beyond the arm's reach fails the variant before any motion to the steps ahead of it is
        # planned (for an object out of reach, most of the search's time went into those)
        for i, step in enumerate(steps):
            short = min((arm.beyond_reach(x) for x in step.positions), default=0.0)
            if short > IK_POSITION:
                return _out_of_reach(arm, steps, i, short, held, target)
        q, segments, released = start, [], False
        searched: list[tuple[int, Callable]] = []  # segments a search found, each with its clearance check
        standing = _save(held)
        for i, step in enumerate(steps):
            if self.spent():
                return Infeasible(f"the {arm.side} arm's plan stopped before '{step.name}'", i)
            if step.kind == "grasp":
                carried = Carried(held.body, *_grasped(arm, q, held))
            elif step.kind == "release":
                carried, released = None, True
            if not step.moves:
                segments.append(Segment(step))
                continue
            # a motion that touches something (the held object, the target, the table it lifts from) may
            # pass close over the table; the other objects it keeps CLEARANCE from, as every motion does
            touched = {"held": {held.body}, "target": {target.body}}.get(step.touches, set())
            ignore = frozenset(touched | ({held.body} if released else set()))
            tight = frozenset({self.table} if step.touches else ())

            def clash(x, carried=carried, ignore=ignore, tight=tight):
                return clearance.clash(x, carried, ignore, tight=tight)

            if step.kind in ("home", "park"):
                to = arm.home if step.kind == "home" else arm.parked
                path = joint_path(clash, q, to, arm.limits, budget=PLAN_CHECKS, smooth=False)
                if path is None:
                    return Infeasible(f"no clear way for the {arm.side} arm {step.name}", i)
                searched.append((len(segments), clash))
                segments.append(Segment(step, path, _gripper_at(arm, to)))
                q = to
                continue
            found, why, reach, blocker = None, "", False, ""
            for position in step.positions:
                goal, err_pos, err_rot = arm.solve(position, step.orientation, [q, arm.home])
                if err_pos > IK_POSITION or err_rot > IK_ROTATION:
                    why, reach = _cannot_reach(arm, step, err_pos), True
                    continue
                hit = clash(goal)
                if hit:
                    goal = _other_solution(arm, position, step.orientation, clash)
                if goal is None:
                    why, reach, blocker = f"'{step.name}' would put the {arm.side} arm against {hit}", False, hit
                    continue
                # a motion that may touch what it reaches for goes there straight: a detour found with the
                # object ignored could sweep through it
                into = step.into and carried is not None
                straight = into or step.straight
                path = (
                    _straight_line(arm, q, position, step.orientation)
                    if straight
                    else joint_path(clash, q, goal, arm.limits, budget=0 if touched else PLAN_CHECKS, smooth=False)
                )
                if straight and path is None:
                    way = "straight down" if into else "straight"  # into a container, or along a slide, an arc or a row
                    why, reach = f"the {arm.side} arm cannot go {way} to '{step.name}'", False
                    continue
                blocker = _path_clash(clash, path) if straight else None
                if path is None or blocker:
                    blocker = blocker or segment_clash(clash, q, goal)
                    why, reach = (
                        f"no clear way for the {arm.side} arm to '{step.name}' ({blocker} is in the way)",
                        False,
                    )
                    continue
                if into and not _fits_through(arm, path, carried, target):
                    why, reach, blocker = f"{_named(held)} would not fit into {_named(target)}", False, _named(target)
                    continue
                # a straight line's end is its own (the goal's pose); a searched path is shortened later
                found = (path, path[-1], position, not straight)
                break
            if found is None:
                return Infeasible(why, i, reach, blocker, _at(steps, i, held, target) if reach else "")
            if found[3]:
                searched.append((len(segments), clash))
            segments.append(Segment(step, found[0], found[2]))
            q = found[1]
        _smooth(arm, held, standing, segments, searched)
        return segments


def _smooth(
    arm: Arm, held: SceneObject, standing: tuple, segments: list[Segment], searched: list[tuple[int, Callable]]
) -> None:
    """The searched paths of a variant that holds, shortened (`smooth_path`) as each was checked: the held
    object standing where it stood at the variant's start (a carried motion's check places it in the hand
    itself); the arm and the object are left where they were."""
    saved, left = arm.config(), _save(held)
    _restore(held, standing)
    try:
        for k, clash in searched:
            segments[k].path = smooth_path(clash, segments[k].path, arm.limits)
    finally:
        arm.set_config(saved)
        _restore(held, left)


def _hemmed_in(
    arm: Arm, clearance: Clearance, steps: list[Step], held: SceneObject, target: SceneObject, carried: Carried
) -> Infeasible | None:
    """Why a step that `decides` the variant cannot be reached clear, the object held as planned (IK from
    the arm's start; the arm and the object are left where they were): planning the motions up to it
    first cost seconds a variant, in a search that tries dozens. None when every such step can."""
    deciding = [(i, step) for i, step in enumerate(steps) if step.decides]
    if not deciding:  # most programs: nothing to check, nothing to save and restore
        return None
    saved, standing = arm.config(), _save(held)
    try:
        for i, step in deciding:
            short, hit = _reached_clear(arm, clearance, step, carried, target)
            if short > IK_POSITION:
                return _out_of_reach(arm, steps, i, short, held, target)
            if hit:
                return Infeasible(f"'{step.name}' would put the {arm.side} arm against {hit}", i, False, hit)
        return None
    finally:
        arm.set_config(saved)
        _restore(held, standing)


def _reached_clear(
    arm: Arm, clearance: Clearance, step: Step, carried: Carried, target: SceneObject
) -> tuple[float, str]:
    """How far short of the nearest of a step's positions the gripper stays (0 when one is reached), and
    what the last one reached hits ("" when one is reached clear)."""
    ignore = frozenset({target.body} if step.touches == "target" else ())
    short, hit = math.inf, ""
    for position in step.positions:
        goal, err_pos, err_rot = arm.solve(position, step.orientation, [arm.home])
        if err_pos > IK_POSITION or err_rot > IK_ROTATION:
            short = min(short, err_pos)
            continue
        short, hit = 0.0, clearance.clash(goal, carried, ignore) or ""
        if not hit:
            return 0.0, ""
    return short, hit


def _cannot_reach(arm: Arm, step: Step, short: float) -> str:
    """Why a step is out of reach: the arm and how far short of it the gripper stays (metres)."""
    return f"the {arm.side} arm cannot reach '{step.name}' ({short * 100:.0f} cm short)"


def _out_of_reach(
    arm: Arm, steps: list[Step], i: int, short: float, held: SceneObject, target: SceneObject
) -> Infeasible:
    """Step `i` lies `short` metres beyond the arm's reach: why, and the object the pose is at."""
    return Infeasible(_cannot_reach(arm, steps[i], short), i, True, unreachable=_at(steps, i, held, target))


def _at(steps: list[Step], i: int, held: SceneObject, target: SceneObject) -> str:
    """The object step `i`'s pose is at, as a clash names it: the held one while it is picked up, the
    target after that ("stand it up over soup" out of reach: the soup is, not the spoon)."""
    return _named(held if i < pick_steps(steps) else target)


def _simulated_grasp(
    arm: Arm, other: Arm, start: np.ndarray, segments: list[Segment], held: SceneObject, variant: Variant
) -> tuple | None:
    """The held object's pose relative to the gripper once the planned pick-up, simulated as it will run
    (the arm from `start` along the planned paths, the other one parked, the fingers closing), has closed
    on it; None when it is then not under the fingertips. The paths keep clear of everything, but the
    joints track them to a few millimetres: a leaning grasp whose finger came down 2 mm beside a pasta
    box's rim pushed it out of the hand, and fingers closing on a bottle from a leaning hand turn it in
    the grasp. The simulation is left as it was, the fingers driven open (as `run_plan` starts them)."""
    state = p.saveState()
    try:
        for a, q, fingers in (
            (other, other.parked, other.finger_open),
            (arm, start, approach_fingers(arm, variant, held.shape)),
        ):
            a.set_config(q)
            a.hold(q)
            a.shape_fingers(fingers, now=True)
        for segment in segments:
            if segment.step.kind == "grasp":
                if not arm.close_on(held.body, variant.half_across(held.shape)):
                    return None
                return relative_pose(*arm.ee_pose(), *p.getBasePositionAndOrientation(held.body))
            if segment.step.moves:
                arm.follow(segment.path)
        raise ValueError("a pick-up without a grasp")  # a bug: every pick-up program grasps
    finally:
        p.restoreState(state)
        p.removeState(state)
        for a in (arm, other):
            a.open_fingers()


def approach_fingers(arm: Arm, variant: Variant, label: str) -> list[float]:
    """The finger joint targets `arm` approaches a `label` object's grasp with, in this `variant`."""
    return arm.finger_targets(variant.approach_width(label))


def shifted(planned: tuple, found: tuple) -> bool:
    """Whether an object at pose `found` in the hand is further than SHIFTED (or turned more than TURNED)
    from the pose `planned` there."""
    turned = float(np.linalg.norm(rotation_error(found[1], planned[1])))
    return float(np.linalg.norm(np.subtract(found[0], planned[0]))) > SHIFTED or turned > TURNED


def _straight_line(arm: Arm, start: np.ndarray, position, orientation) -> list[np.ndarray] | None:
    """Joints that move the gripper from where it is at `start` to `position` along the straight line,
    a waypoint every INTO_STEP, each solved from the last (the end too: the goal, solved from elsewhere, may
    be another arm configuration); None when one is out of reach, or when one is another configuration
    than the last (a joint turns more than BRANCH_JUMP between them: the arm would swing off the line
    between them, and a ladle tipped so flung its content off the table)."""
    arm.set_config(start)
    here, turned = arm.ee_pose()
    n = max(1, int(np.ceil(np.linalg.norm(np.asarray(position) - here) / INTO_STEP)))
    path = [np.asarray(start, dtype=float)]
    for k in range(1, n + 1):
        f = k / n
        q, err_pos, err_rot = arm.solve(
            here + (np.asarray(position) - here) * f, p.getQuaternionSlerp(turned, orientation, f), [path[-1]]
        )
        if err_pos > IK_POSITION or err_rot > IK_ROTATION or np.max(np.abs(q - path[-1])) > BRANCH_JUMP:
            return None
        path.append(np.asarray(q, dtype=float))
    return path


def _path_clash(clash, path: list[np.ndarray]) -> str | None:
    """The first thing a motion through the waypoints of `path` comes too close to, or None."""
    return next((hit for a, b in zip(path, path[1:]) if (hit := segment_clash(clash, a, b))), None)


def _fits_through(arm: Arm, path: list[np.ndarray], carried: Carried, target: SceneObject) -> bool:
    """Whether the carried object, moved along the joint-space `path`, stays FIT_MARGIN clear of the
    target (its walls, as it goes in through the opening), checked as every motion is: a 12 cm chicken
    turned off a 12.8 cm bowl's axes meets the wall, sticks and pushes the bowl."""

    def near_walls(q) -> str | None:
        arm.set_config(q)
        carried.place(arm)
        return _named(target) if p.getClosestPoints(carried.body, target.body, FIT_MARGIN) else None

    return _path_clash(near_walls, path) is None


def _other_solution(arm: Arm, position, orientation, clash) -> np.ndarray | None:
    """A clear IK solution for a pose whose first solution clashes, from other starting configurations
    (the arm has seven joints: the elbow can often swing away from what it hit), or None."""
    for seed in arm.ik_restarts:
        goal, err_pos, err_rot = arm.solve(position, orientation, [seed])
        if err_pos <= IK_POSITION and err_rot <= IK_ROTATION and not clash(goal):
            return goal
    return None


def pick_steps(steps: list[Step]) -> int:
    """How many of a program's steps pick the object up (up to and including the lift after the grasp)."""
    kinds = [s.kind for s in steps]
    return kinds.index("grasp") + 2 if "grasp" in kinds else 0


def _variants(held: SceneObject, task: Task, holding: bool, opening: float) -> list[Variant]:
    """The ways to try: all grasps, or, for an object already in the hand, the top grasp it was handed
    over in, by its middle (tilting either way); carried unturned when the task keeps it `square`."""
    if holding:
        found = variants(held, turns=task.turns, wide=task.wide, front=task.sideways)
        found = [v for v in found if v.yaw == 0.0 and not v.side and v.shift == (0.0, 0.0)]
    else:
        found = variants(held, task.pours or task.sideways, opening, task.turns, task.wide, task.sideways)
    return [v for v in found if v.turn == 0.0] if task.square else found


def _grasped(arm: Arm, q, held: SceneObject) -> tuple:
    """The held object's pose in the hand when grasped at joints `q`, as it stands now."""
    arm.set_config(q)
    return relative_pose(*arm.ee_pose(), *p.getBasePositionAndOrientation(held.body))


def _nearer_first(obj: SceneObject, arms: tuple[str, ...]) -> list[str]:
    """The `arms` with the one on the object's side of the table first."""
    return sorted(arms, key=lambda s: (obj.xy[1] >= 0) != (s == "left"))


def _named(obj: SceneObject) -> str:
    """How a clash names an object: by its id (the label when no other object has it)."""
    return f"the {obj.name}"


def _gripper_at(arm: Arm, q) -> np.ndarray:
    """The gripper's position with the arm at joints `q`."""
    arm.set_config(q)
    return arm.ee_pose()[0]


def _stand_at(obj: SceneObject, xy: tuple[float, float]) -> None:
    """Stand an object upright on the table at `xy` (table frame), as it would be once put down there."""
    pos, orn = p.getBasePositionAndOrientation(obj.body)
    p.resetBasePositionAndOrientation(obj.body, pos, (0, 0, 0, 1))
    underside = p.getAABB(obj.body)[0][2] - pos[2]
    p.resetBasePositionAndOrientation(obj.body, (*world_xy(xy), TABLE_TOP + 0.001 - underside), (0, 0, 0, 1))


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
