"""One instruction in simulation: build the scene, detect the objects, complete the instruction with
the detected labels, plan and execute the predicate's motion, and check the outcome."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pybullet as p

from lmcr.complete import CompletionConfig, complete
from lmcr.errors import LMCRError, one_line
from lmcr.executor.detect import capture, detect
from lmcr.executor.motion import PLANS, TILTING, TOLERANCE, choose_arm
from lmcr.executor.scene import Scene, build_world, load_scene, scene_from_json
from lmcr.jsonl import InputError, check_text, read_jsonl_lines


class ExecutionError(LMCRError, ValueError):
    """The completed frame names something the robot cannot act on here."""


def _connect() -> None:
    if not p.isConnected():
        p.connect(p.DIRECT)


def execute(instruction: str, scene: Scene, parser, scorer: Callable, config: CompletionConfig, cache_dir: Path,
            frames: list | None = None, answer: dict[str, str] | None = None) -> dict:
    """The CLI contract's result: frame, chosen object, waypoint errors, per-verb checks, success.
    With `frames` (a list), camera images are appended at every waypoint for rendering. `answer` (role ->
    object) is what a person answered to the completion's question: it fills those roles instead."""
    started = time.perf_counter()
    _connect()
    robot = build_world(scene, cache_dir)
    seen = detect(scene.bodies)
    completion = complete(parser, scorer, instruction, [d.label for d in seen], config)
    frame = completion["frame"]
    if answer:
        frame = {"predicate": frame["predicate"], "roles": {**frame["roles"], **answer}}
    predicate, roles = frame["predicate"], frame["roles"]
    held_role, target_role, plan = PLANS[predicate]
    try:
        held, target = scene.find(roles[held_role]), scene.find(roles[target_role])
    except KeyError as exc:
        raise ExecutionError(f"cannot {predicate} here: {exc.args[0]}") from exc
    planned = time.perf_counter()
    arm = choose_arm(robot, scene, held, target, tilts=predicate in TILTING)
    if frames is not None:
        arm.on_waypoint = lambda: frames.append(capture()[0])
        frames.append(capture()[0])
    checks = plan(arm, held, target)
    waypoints_ok = all(w["error_m"] <= TOLERANCE for w in arm.log)
    chosen = next(iter(answer.values())) if answer else (
        completion["candidates"][0]["object"] if completion["candidates"] else None)
    return {"frame": frame, "chosen_object": chosen,
            "success": bool(checks["ok"] and waypoints_ok and arm.grasps_ok), "waypoints": arm.log,
            "checks": {**{k: v for k, v in checks.items() if k != "ok"}, "verb_check": bool(checks["ok"]),
                       "grasped": arm.grasps_ok, "waypoints_within_tolerance": waypoints_ok},
            "arm": arm.side, "missing": completion["missing"], "question": completion["question"],
            "detections": [{"label": d.label, "position": [round(v, 3) for v in d.position]} for d in seen],
            "seconds": {"perceive_and_complete": round(planned - started, 3),
                        "plan_and_execute": round(time.perf_counter() - planned, 3)}}


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
        except (ValueError, KeyError, RuntimeError) as exc:  # every LMCR error is a ValueError/RuntimeError
            yield {"id": ident, "line": line_no, "error": one_line(exc)}


def _batch_scene(record: dict, base: Path, where: str) -> Scene:
    if "scene" in record:
        return scene_from_json(record["scene"], f"{where}: scene")
    if isinstance(record.get("scene_file"), str):
        return load_scene(base / record["scene_file"])
    raise InputError(f"{where}: needs a 'scene' object or a 'scene_file' path")


def save_render(frames: list, path: Path) -> Path:
    """The last frame as PNG, or every waypoint's frame as an animated GIF."""
    from PIL import Image

    from lmcr.files import atomic_path

    images = [Image.fromarray(f) for f in frames]
    path = Path(path)
    with atomic_path(path) as tmp:
        if path.suffix.lower() == ".gif":
            images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=300, loop=0)
        else:
            images[-1].save(tmp, format="PNG")
    return path
