"""One instruction in simulation: build the scene, detect the objects, complete the instruction with
the detected labels, plan and execute the predicate's motion, and check the outcome."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pybullet as p

from lmcr.complete import CompletionConfig, complete
from lmcr.errors import LMCRError, one_line
from lmcr.executor.detect import detect
from lmcr.executor.plan import Infeasible, Plan, Planner
from lmcr.executor.render import Recorder
from lmcr.executor.run import run_plan
from lmcr.executor.scene import Scene, build_world, free_spots, load_scene, scene_from_json
from lmcr.executor.tasks import TASKS
from lmcr.jsonl import InputError, check_text, read_jsonl_lines

MAX_TRIED = 4  # candidates planned at most, in the language model's order, to find one the robot can do


class ExecutionError(LMCRError, ValueError):
    """The completed frame names something the robot cannot act on here."""


def _connect() -> None:
    if not p.isConnected():
        p.connect(p.DIRECT)


def execute(instruction: str, scene: Scene, parser, scorer: Callable, config: CompletionConfig, cache_dir: Path,
            recorder: Recorder | None = None, answer: dict[str, str] | None = None, urdf: Path | None = None) -> dict:
    """The CLI contract's result: frame, chosen object, waypoint errors, per-verb checks, success, and
    whether the plan was feasible. The robot moves only when the whole plan is feasible. When the
    language model's choice is not but another candidate is, nothing moves and the result asks
    (`question`, `suggestion`). A `recorder` takes a picture at the start, at every waypoint and at the
    end. `answer` (role -> object) is what a person answered: it fills those roles instead.
    `urdf`: the official Baxter description to use instead of ours."""
    started = time.perf_counter()
    _connect()
    robot = build_world(scene, cache_dir, urdf)
    seen = detect(scene.bodies)
    completion = complete(parser, scorer, instruction, [d.label for d in seen], config)
    completed = time.perf_counter()
    planner = Planner(robot, scene, scene.table)
    tried = []
    for frame, candidate in _options(completion, answer)[:MAX_TRIED]:
        tried.append((frame, candidate, _plan(planner, scene, frame)))
        if isinstance(tried[-1][2], Plan):
            break
    planned = time.perf_counter()
    frame, candidate, result = tried[0]
    out = {"frame": frame, "chosen_object": _chosen(candidate, answer), "feasible": isinstance(result, Plan),
           "success": False, "waypoints": [], "checks": {}, "missing": completion["missing"],
           "question": completion["question"], "holding": scene.holding.label if scene.holding else None,
           "ranking": _ranking(completion, tried),
           "detections": [{"label": d.label, "position": [round(v, 3) for v in d.position]} for d in seen]}
    if isinstance(result, Infeasible):
        out.update(_refusal(frame, result, tried, parser))
    else:
        task = TASKS[frame["predicate"]]
        roles = frame["roles"]
        if recorder is not None:
            recorder.target, recorder.held = roles[task.target_role], roles[task.held_role]
            for arm in result.moving_arms:
                arm.on_waypoint = lambda log=arm.log: recorder.shot(f"{log[-1]['name']} ({1000 * log[-1]['error_m']:.0f} mm)")
            recorder.shot(f"{frame['predicate']} {roles[task.held_role]} -> {roles[task.target_role]}: start")
        held, target = scene.find(roles[task.held_role]), scene.find(roles[task.target_role])
        out.update(run_plan(result, held, target, [o for o in scene.present if o not in (held, target)],
                            planner))
        out["set_down_first"] = result.first.geometry.held.label if result.first else None
        if recorder is not None:  # what was poured or put down, once it has come to rest
            recorder.shot(f"after: {'success' if out['success'] else 'failed'}")
        out["arm"] = result.arm.side
    done = time.perf_counter()
    out["seconds"] = {"perceive_and_complete": round(completed - started, 3), "plan": round(planned - completed, 3),
                      "execute": round(done - planned, 3), "plan_and_execute": round(done - completed, 3)}
    return out


def _options(completion: dict, answer: dict[str, str] | None) -> list[tuple[dict, dict | None]]:
    """The frames worth planning, best first: the answered one, else one per candidate in the language
    model's order (just the completed frame when nothing was missing)."""
    frame = completion["frame"]
    if answer:
        return [({"predicate": frame["predicate"], "roles": {**frame["roles"], **answer}}, None)]
    if not completion["candidates"]:
        return [(frame, None)]
    return [({"predicate": frame["predicate"], "roles": {**frame["roles"], **c["objects"]}}, c)
            for c in completion["candidates"]]


def _plan(planner: Planner, scene: Scene, frame: dict) -> Plan | Infeasible:
    task = TASKS[frame["predicate"]]
    roles = frame["roles"]
    try:
        held, target = scene.find(roles[task.held_role]), scene.find(roles[task.target_role])
    except KeyError as exc:
        raise ExecutionError(f"cannot {frame['predicate']} here: {exc.args[0]}") from exc
    holding = scene.holding is not None and held is scene.holding
    if scene.holding is not None and not holding:  # the hand is needed: put down what it holds first
        return planner.plan_via(task, held, target, scene.holding, True, free_spots(scene, scene.holding.label))
    direct = planner.plan(task, held, target, holding)
    if isinstance(direct, Plan):
        return direct
    # set down elsewhere first: the held object when no arm reaches all the task as it stands (from the
    # table it may be picked up by either arm, in any grasp), else, with the hand free, the object on
    # the table a pose would put the arm against
    blocking = None if holding else planner.on_table(direct.blocker)
    moved = held if direct.out_of_reach else blocking
    if moved is None:
        return direct
    rearranged = planner.plan_via(task, held, target, moved, holding, free_spots(scene, moved.label))
    return rearranged if isinstance(rearranged, Plan) else direct


def _chosen(candidate: dict | None, answer: dict[str, str] | None) -> str | None:
    if answer:
        return next(iter(answer.values()))
    return candidate["object"] if candidate else None


def _ranking(completion: dict, tried: list) -> list[dict]:
    """The candidates by language-model probability x feasibility (1 planned feasible, 0 not, unknown
    when not planned: those keep their probability and rank after the feasible ones)."""
    feasible = {c["object"]: isinstance(r, Plan) for _, c, r in tried if c is not None}
    rows = [{"object": c["object"], "probability": c["probability"], "feasible": feasible.get(c["object"])}
            for c in completion["candidates"]]
    return sorted(rows, key=lambda r: -(r["probability"] * (r["feasible"] is not False)))


def _refusal(frame: dict, result: Infeasible, tried: list, parser) -> dict:
    """Why nothing moved, and the question to ask when another candidate is feasible."""
    out = {"reason": result.reason}
    alternative = next(((f, c) for f, c, r in tried[1:] if isinstance(r, Plan)), None)
    if alternative is not None:
        f, c = alternative
        sentence = parser.lex.predicates[f["predicate"]].sentence.format(**f["roles"])
        out["question"] = f"I can't reach the {tried[0][1]['object']}. Should I {sentence} instead?"
        out["suggestion"] = c["objects"]
    return out


BATCH_FIELDS = {"id": (str, int), "instruction": str}


def execute_batch(path: Path, run: Callable[[str, Scene], dict]) -> Iterator[dict]:
    """The batch form of the CLI contract: one output line per input line, in order. Each line gives an
    instruction and a `scene` object or a `scene_file` (relative to the input's folder); `run` executes
    one. A bad line (not JSON, a bad scene, an instruction that cannot be completed or acted on) gets
    `{"id", "error"}` and the rest go on; only an unreadable input file raises."""
    for line_no, record, error in read_jsonl_lines(path, BATCH_FIELDS):
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
