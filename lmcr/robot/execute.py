"""One instruction in simulation: build the scene, detect the objects, complete the instruction with
the detected labels, plan and execute the predicate's motion, and check the outcome.

The completion names labels; the executor picks the objects. When several objects have a label (three
cups), their combinations for the task's two roles are planned nearest first (the least reach to the held
object plus carry to the target) until one is feasible, and the result names the one acted on by id."""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace
from pathlib import Path

import pybullet as p

from lmcr.complete import Candidate, Completion, CompletionConfig, complete
from lmcr.errors import LMCRError, one_line
from lmcr.frame import Frame
from lmcr.jsonl import InputError, check_text, read_jsonl_lines
from lmcr.lexicon import Lexicon
from lmcr.robot.act import run_plan
from lmcr.robot.budget import Budget
from lmcr.robot.detect import detect
from lmcr.robot.household import household
from lmcr.robot.plan import Infeasible, Plan, Planner
from lmcr.robot.render import Recorder
from lmcr.robot.reply import say
from lmcr.robot.scene import X_LIMIT, Scene, SceneObject, free_spots, load_scene, scene_from_json
from lmcr.robot.tasks import COOK, MOTIONS, SERVE, TASKS, TOOL_MOTIONS, Task, scoops, task_for, unfit_tool
from lmcr.robot.world import build_world
from lmcr.srl.instruction import NoPredicateError

MAX_TRIED = 4  # candidates planned at most, in the language model's order, to find one the robot can do
MAX_INSTANCES = 3  # of one candidate, the object combinations planned at most (nearest first)
ROBOT_EDGE = (-X_LIMIT, 0.0)  # the middle of the table's edge at the robot (table frame): both arms reach there


# the motions a learned verb may have: by its Destination's kind, and its class's with a tool or a ladle,
# or putting the Theme where it cooks
LEARNED_MOTIONS = sorted({*MOTIONS, *TOOL_MOTIONS, SERVE.motion, *(task.motion for task in COOK.values())})


class NoMotionError(NoPredicateError):
    """A predicate the robot understands (learned from the corpora) but has no motion for with the objects
    it sees: none yet for the verb's class, or none that the candidates fit (no tool on the table). `unfit`:
    (what it was asked to do, why the tool cannot) when its class has a tool motion the chosen tool cannot
    do ("cut the cake with the knife", "the knife's blade cannot saw through the cake, 0.18 m across")."""

    def __init__(self, predicate: str, unfit: tuple[str, str] | None = None):
        can, learned = ", ".join(sorted(TASKS)), ", ".join(LEARNED_MOTIONS[:-1]) + " or " + LEARNED_MOTIONS[-1]
        super().__init__(
            f"the simulated Baxter cannot {unfit[0]}: {unfit[1]}"
            if unfit
            else f"the simulated Baxter has no motion for {predicate!r} with the objects it sees (it can {can}; "
            f"and {learned} for a verb learned as one of those, its tool on the table)"
        )
        self.predicate = predicate
        self.unfit = unfit


def _with_tasks(
    completion: Completion, options: list[tuple[Frame, Candidate | None]], lex: Lexicon, shapes: dict[str, str]
) -> list:
    """The options with the task that carries each out (None when the robot has no motion for it: a
    learned verb whose class has none, "cut the bread into the bowl"; that one is refused as the robot
    cannot do it, and the others are offered); NoMotionError when none has one. The task is that of what
    the frame's objects are built as (`shapes`, label -> shape: a closet built like a storage box is placed
    into)."""
    found = [
        (frame, candidate, task_for(_as_built(frame, shapes), _verb_motion(frame, lex))) for frame, candidate in options
    ]
    if all(task is None for _, _, task in found):
        # why the first option with a tool cannot ("whisk the eggs": into the bowl has no motion, and the
        # whisk cannot stir an egg that is in nothing)
        unfit = next((u for frame, _ in options if (u := _unfit(frame, shapes, lex)) is not None), None)
        raise NoMotionError(completion.frame.predicate, unfit)
    return found


def _unfit(frame: Frame, shapes: dict[str, str], lex: Lexicon) -> tuple[str, str] | None:
    """(what the frame asks, why its tool cannot do it: `tasks.unfit_tool` on what its objects are built
    as), in the frame's own words; None when that is not why."""
    why = unfit_tool(_as_built(frame, shapes), _verb_motion(frame, lex))
    if why is None:
        return None
    tool, theme = frame.role_map["Instrument"], frame.role_map["Theme"]
    return f"{frame.predicate} the {theme} with the {tool}", why.format(tool=tool, theme=theme)


def _as_built(frame: Frame, shapes: dict[str, str]) -> Frame:
    """The frame with each role's label replaced by what that object is built as (`Scene.shapes`)."""
    return Frame.of(frame.predicate, {role: shapes.get(value, value) for role, value in frame.role_map.items()})


def _verb_motion(frame: Frame, lex: Lexicon) -> str | None:
    """The class of motion learned for the frame's predicate (None for the eleven, and unknown ones)."""
    spec = lex.predicates.get(frame.predicate)
    return spec.motion if spec is not None else None


def _no_motion(frame: Frame) -> Infeasible:
    """Why a frame the robot has no motion for is not planned (its open role is not one it can act on)."""
    roles = ", ".join(f"{role} {value}" for role, value in frame.role_map.items())
    return Infeasible(f"the robot has no motion to {frame.predicate} with {roles}")


class ExecutionError(LMCRError, ValueError):
    """The completed frame names something the robot cannot act on here; `absent` is the label not on the table."""

    def __init__(self, message: str, absent: str | None = None):
        super().__init__(message)
        self.absent = absent


def _connect() -> None:
    if not p.isConnected():
        p.connect(p.DIRECT)


def execute(
    instruction: str,
    scene: Scene,
    parser,
    scorer: Callable,
    config: CompletionConfig,
    cache_dir: Path,
    recorder: Recorder | None = None,
    answer: dict[str, str] | None = None,
    urdf: Path | None = None,
    budget: Budget | None = None,
) -> dict:
    """The CLI contract's result: frame, chosen object (`chosen_object` its label, `chosen_id` which of the
    objects with that label; `role_ids` the object of every role), waypoint errors, per-verb checks,
    success, whether the plan was feasible, and what the robot says (`reply`). The robot moves only when
    the whole plan is feasible. When the language model's choice is not but another candidate is, nothing
    moves and the result asks (`question`, `suggestion`). A `recorder` takes a picture at the start, at
    every waypoint and at the end. `answer` (role -> object) is what a person answered: it fills those
    roles instead. `urdf`: the official Baxter description to use instead of ours. The planning search
    stops when its `budget` (default `Budget()`) is spent: the refusal then says so (`budget_exhausted`)."""
    started = time.perf_counter()
    _connect()
    robot = build_world(scene, cache_dir, urdf)
    seen = detect(scene.bodies)
    held = (scene.holding.label,) if scene.holding else ()
    completion = complete(parser, scorer, instruction, [d.label for d in seen], config, [d.id for d in seen], held)
    if not answer:
        _check_someone_there(completion, parser.lex, seen)
    options = _with_tasks(completion, _options(completion, answer), parser.lex, scene.shapes())[:MAX_TRIED]
    completed = time.perf_counter()
    planner = Planner(robot, scene, scene.table, budget or Budget())
    tried = _search(planner, scene, options, {d.id for d in seen})
    planned = time.perf_counter()
    # the language model's choice, as the first of its objects the robot can act on (else the nearest)
    first = [t for t in tried if t[0] is options[0][0]]
    frame, candidate, objects, result = next((t for t in first if isinstance(t[3], Plan)), first[0])
    task = next(t for f, _, t in options if f is frame)
    role = _chosen_role(completion, candidate, answer)
    out = {
        "frame": frame.to_json(),
        "motion": None if task is None else task.motion or frame.predicate,  # a learned verb's: place, ...
        "chosen_object": _chosen(candidate, answer),
        "chosen_id": objects[role].id if role in objects else None,
        "role_ids": {r: o.id for r, o in objects.items()},
        "feasible": isinstance(result, Plan),
        "success": False,
        "waypoints": [],
        "checks": {},
        "missing": completion.missing,
        "question": completion.question,
        "holding": scene.holding.label if scene.holding else None,
        "built_like": {o.label: o.like for o in scene.present if o.like},  # objects built as a known one
        "ranking": _ranking(completion, tried),
        "detections": [{"label": d.label, "id": d.id, "position": [round(v, 3) for v in d.position]} for d in seen],
        "budget_exhausted": isinstance(result, Infeasible) and bool(planner.stopped),
        "ik_calls": sum(arm.ik_calls for arm in planner.arms.values()),  # the planning search's, as budgeted
    }
    if isinstance(result, Infeasible):
        if planner.stopped:
            result = replace(result, reason=f"{result.reason} ({planner.stopped})")
        out.update(_refusal(out, result, tried, parser.lex))
    else:
        held, target = objects[task.held_role], objects[task.target_role]
        if recorder is not None:
            recorder.target, recorder.held = target.id, held.id
            for arm in result.moving_arms:
                arm.on_waypoint = lambda log=arm.log: recorder.shot(
                    f"{log[-1]['name']} ({1000 * log[-1]['error_m']:.0f} mm)"
                )
                arm.on_step = recorder.tick
            recorder.shot(f"{frame.predicate} {held.id} -> {target.id}: start")
        out.update(run_plan(result, held, target, [o for o in scene.present if o not in (held, target)], planner))
        out.update(_set_down(result))
        if recorder is not None:  # what was poured or put down, once it has come to rest
            recorder.shot(f"after: {'success' if out['success'] else 'failed'}")
        out["arm"] = result.arm.side
    out["reply"] = say(out, parser.lex)
    done = time.perf_counter()
    out["seconds"] = {
        "perceive_and_complete": round(completed - started, 3),
        "plan": round(planned - completed, 3),
        "execute": round(done - planned, 3),
        "plan_and_execute": round(done - completed, 3),
    }
    return out


def _check_someone_there(completion: Completion, lex: Lexicon, seen: list) -> None:
    """ExecutionError when the request is for a person ("can I have an apple?", "hand the cup to her") and
    the camera sees no one: what the completion filled in instead (a bowl) is no one's hands."""
    if any(word in lex.person_words for word in completion.unresolved.values()):
        person = min(lex.speaker_labels, default="person")
        there = ", ".join(d.id for d in seen) or "nothing"
        raise ExecutionError(
            f"cannot {completion.frame.predicate}: no one to hand it to (the camera sees: {there})", absent=person
        )


def _search(planner: Planner, scene: Scene, options: list, seen: set[str]) -> list[tuple]:
    """Plan the options (frame, candidate, task) in order, each with its nearest object combinations, until
    one is feasible or the budget is spent: (frame, candidate, role -> object, plan or why not) for each
    one tried. A frame the robot has no motion for is not planned (`_no_motion`)."""
    tried = []
    for frame, candidate, task in options:
        if task is None:
            tried.append((frame, candidate, {}, _no_motion(frame)))
            continue
        for objects in _assignments(scene, frame, task, seen)[:MAX_INSTANCES]:
            tried.append((frame, candidate, objects, plan_task(planner, scene, task, objects)))
            if isinstance(tried[-1][3], Plan) or planner.stopped:
                break
        if isinstance(tried[-1][3], Plan) or planner.stopped:
            break
    return tried


def _options(completion: Completion, answer: dict[str, str] | None) -> list[tuple[Frame, Candidate | None]]:
    """The frames worth planning, best first: the answered one, else one per candidate in the language
    model's order (just the completed frame when nothing was missing)."""
    frame = completion.frame
    if answer:  # the roles the person stated, and the answer (not the role the completion chose instead)
        stated = {r: v for r, v in frame.role_map.items() if r not in completion.missing_roles}
        return [(Frame.of(frame.predicate, {**stated, **answer}), None)]
    if not completion.candidates:
        return [(frame, None)]
    return [(Frame.of(frame.predicate, {**frame.role_map, **c.objects}), c) for c in completion.candidates]


def _assignments(scene: Scene, frame: Frame, task: Task, seen: set[str]) -> list[dict[str, SceneObject]]:
    """The objects the task's roles may be done with (role -> object; one per role, never one object for
    two), nearest first: the reach from the robot's edge to the held object (none when it is in the hand)
    plus its carry to the target (by way of the source, for a task with one). An object is one the camera
    saw or the one in the hand; a ladle the frame leaves unsaid is one the robot finds on the table."""
    roles = [task.held_role, task.target_role, *([task.source_role] if task.source_role else [])]
    choices = [_instances(scene, frame, task, role, seen) for role in roles]

    def effort(combo: tuple[SceneObject, ...]) -> float:
        held, target, *source = (ROBOT_EDGE if o is scene.holding else o.xy for o in combo)
        return math.dist(ROBOT_EDGE, held) + sum(
            math.dist(a, b) for a, b in itertools.pairwise([held, *source, target])
        )

    combos = sorted((c for c in itertools.product(*choices) if len({id(o) for o in c}) == len(c)), key=effort)
    if not combos:  # "pour the cup into the cup" with one cup
        raise ExecutionError(f"cannot {frame.predicate} here: there is one {choices[0][0].label}, not two")
    return [dict(zip(roles, combo)) for combo in combos]


def _instances(scene: Scene, frame: Frame, task: Task, role: str, seen: set[str]) -> list[SceneObject]:
    """The objects a role may be done with: those labelled as the frame says (seen by the camera, or in the
    hand, first); for a serving task's unsaid Instrument, the ladles on the table."""
    label = frame.role_map.get(role)
    if label is None and task.source_role:
        found = [o for o in scene.present if scoops(o.shape)]
        if not found:
            raise ExecutionError(f"cannot {frame.predicate} here: nothing to scoop with on the table")
        return found
    found = [o for o in scene.instances(label) if o is scene.holding or o.id in seen] or scene.instances(label)
    if not found:  # what the robot knows of the table is what its camera saw, not the scene file
        there = ", ".join(o.id for o in scene.present if o.id in seen or o is scene.holding) or "nothing"
        raise ExecutionError(
            f"cannot {frame.predicate} here: no {label!r} on the table (the camera sees: {there})", absent=label
        )
    return found


def plan_task(planner: Planner, scene: Scene, task: Task, objects: dict[str, SceneObject]) -> Plan | Infeasible:
    """The plan for a task with its objects (role -> object), or why there is none: the hand emptied first
    when it holds something else; a drawer, a fridge or a cupboard opened, filled and shut by one arm; else directly.
    Where that is refused, something is set down elsewhere first (`_set_aside`)."""
    task = task.with_source(objects)
    held, target = objects[task.held_role], objects[task.target_role]
    holding = scene.holding is not None and held is scene.holding
    if scene.holding is not None and not holding:  # the hand is needed: put down what it holds first
        return planner.plan_via(task, held, target, scene.holding, True, free_spots(scene, scene.holding.shape))
    direct = planner.plan_as_it_stands(task, held, target, holding)
    if isinstance(direct, Plan) or planner.stopped:
        return direct
    for moved in _set_aside(planner, direct, held, target, holding):
        rearranged = planner.plan_via(task, held, target, moved, holding, free_spots(scene, moved.shape))
        if isinstance(rearranged, Plan):
            return replace(rearranged, instead_of=direct)
        if planner.stopped:
            break
    return direct


def _set_aside(
    planner: Planner, refused: Infeasible, held: SceneObject, target: SceneObject, holding: bool
) -> list[SceneObject]:
    """What to set down elsewhere first, in the order to try, after `refused`: when no arm reaches all the
    task as it stands, the held object (from the table it may be picked up by either arm, in any grasp);
    else, with the hand free, the object on the table a pose would put the arm against (unless it is
    fixed), then the held object, moved away from it (a bin beside the banana, a fridge's open lid in the
    way to the milk). Last, with the hand free, the target when it is no fixed receptacle: the soup to
    stir brought nearer the robot, the bread to cut away from the stove beside it."""
    free = not holding and target is not held and target in planner.scene.objects  # a hand to move it
    last = [target] if free and not _fixed(target) else []
    if refused.out_of_reach:
        return [held, *last]
    blocking = None if holding else planner.on_table(refused.blocker)
    if blocking is None:
        return []
    first = [*([] if _fixed(blocking) else [blocking]), *([] if blocking is held else [held])]
    return [*first, *(o for o in last if o not in first)]


def _fixed(obj: SceneObject) -> bool:
    """Whether `obj` is a receptacle fixed in place (mass 0), which nothing sets down elsewhere."""
    return getattr(household().get(obj.shape), "mass", None) == 0


def _set_down(plan: Plan) -> dict:
    """What was set down elsewhere first (`set_down_first`, None when nothing) and why the task alone was not
    planned (`set_down_because`: its reason, whether it was out of reach, what was in the way)."""
    if plan.first is None:
        return {"set_down_first": None}
    why = plan.instead_of
    because = {"reason": why.reason, "out_of_reach": why.out_of_reach, "blocker": why.blocker} if why else None
    return {"set_down_first": plan.first.geometry.held.id, "set_down_because": because}


def _chosen(candidate: Candidate | None, answer: dict[str, str] | None) -> str | None:
    if answer:
        return next(iter(answer.values()))
    return candidate.object if candidate else None


def _chosen_role(completion: Completion, candidate: Candidate | None, answer: dict[str, str] | None) -> str | None:
    """The role of the chosen object: the one answered, or the completion's missing one."""
    if answer:
        return next(iter(answer))
    return completion.missing if candidate else None


def _ranking(completion: Completion, tried: list) -> list[dict]:
    """The candidates by language-model probability x feasibility (1 planned feasible with one of its
    objects, 0 with none, unknown when not planned: those keep their probability and rank after the
    feasible ones)."""
    feasible: dict[str, bool] = {}
    for _, c, _, r in tried:
        if c is not None:
            feasible[c.object] = feasible.get(c.object, False) or isinstance(r, Plan)
    rows = [
        {"object": c.object, "probability": c.probability, "feasible": feasible.get(c.object)}
        for c in completion.candidates
    ]
    return sorted(rows, key=lambda r: -(r["probability"] * (r["feasible"] is not False)))


def _refusal(out: dict, result: Infeasible, tried: list, lexicon: Lexicon) -> dict:
    """Why nothing moved (`out` the result so far), and the question to ask when another candidate is
    feasible (`suggestion` its objects by label, `suggestion_ids` by id)."""
    why = {
        "reason": result.reason,
        "out_of_reach": result.out_of_reach,
        "unreachable": result.unreachable or None,
        "blocker": result.blocker or None,
    }
    alternative = next(((c, objects) for _, c, objects, r in tried if isinstance(r, Plan)), None)
    if alternative is None:
        return why
    c, objects = alternative
    offer = {"suggestion": dict(c.objects), "suggestion_ids": {role: objects[role].id for role in c.objects}}
    return {**why, **offer, "question": say({**out, **why, **offer}, lexicon)}


BATCH_FIELDS = {"id": (str, int), "instruction": str}


def read_batch(path: Path) -> list[tuple[int, dict | None, InputError | None]]:
    """The non-blank lines of a batch input, read (line number, record, the line's error or None); only an
    unreadable input file raises."""
    return list(read_jsonl_lines(path, BATCH_FIELDS))


def execute_batch(
    path: Path, run: Callable[[str, Scene], dict], lines: Sequence[tuple] | None = None
) -> Iterator[dict]:
    """The batch form of the CLI contract: one output line per input line (of `lines` of `read_batch(path)`
    when given), in order. Each line gives an instruction and a `scene` object or a `scene_file` (relative
    to the input's folder); `run` executes one. A bad line (not JSON, a bad scene, an instruction that
    cannot be completed or acted on) gets `{"id", "error"}` and the rest go on; only an unreadable input
    file raises."""
    for line_no, record, error in read_batch(path) if lines is None else lines:
        ident = record.get("id") if isinstance(record, dict) else None
        try:
            if error is not None:
                raise error
            scene = _batch_scene(record, Path(path).parent, f"{path}:{line_no}")
            yield {"id": ident, **run(check_text(record["instruction"], f"{path}:{line_no}"), scene)}
        # every LMCR error is a ValueError/RuntimeError; the simulator raises its own type
        except (ValueError, KeyError, RuntimeError, p.error) as exc:
            yield {"id": ident, "line": line_no, "error": one_line(exc)}


def _batch_scene(record: dict, base: Path, where: str) -> Scene:
    if "scene" in record:
        return scene_from_json(record["scene"], f"{where}: scene")
    if isinstance(record.get("scene_file"), str):
        return load_scene(base / record["scene_file"])
    raise InputError(f"{where}: needs a 'scene' object or a 'scene_file' path")
