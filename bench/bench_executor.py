"""Benchmark: the Baxter executor on random table layouts, per predicate and per motion of the learned verbs.

Usage: python bench/bench_executor.py [--placements 20] [--distractors 4] [--seed 0] [--predicates pour,fill,place]
       [--urdf PATH] [--holding] [--videos DIR] [--json PATH]
For each of the 11 predicates, and for a learned verb of each motion that puts a Theme at a Destination
(place: put away on a shelf, in a drawer that is opened and shut, in a chest fridge whose lid is lifted
open and lowered shut, in a dish drawer pulled open and pushed shut, or in a cupboard whose door is swung
open, the object carried in through its front, and swung shut; dispose: throw out into a bin; hand
over: hand to a person), and of each class that works with a tool (stir the soup with a spoon, wipe the
cutting board with a sponge, cut the bread with a knife, cover the pot with a lid; serve: scoop the soup
into a bowl with the ladle on the table; cook: reheat the soup in the microwave, bake the bread in the
oven), an incomplete
instruction on `--placements` random layouts: the two objects the frame needs plus `--distractors` random
other objects (obstacles, and other candidates for the completion; for the learned verbs drawn from the
household's receptacles too), placed at random with a seed. The learned verbs need a frame build that
learned them ($LMCR_DATA_DIR); one the store did not learn, or learned as a class with no motion, is
printed as not measured with the reason and left out of the totals. With `--holding` the stated object
starts in the robot's hand instead of on the table (for fill and season it is the target: the robot puts it down first).
The task's own object is given as the answer, so the run measures execution; how often the language
model (the published checkpoint of $LMCR_DATA_DIR) would have chosen another object is counted beside it.
Prints per predicate: executed successfully / executed, refused before moving (infeasible), then a
histogram of failure and refusal reasons, and the time to plan and execute one instruction. With `--videos`,
each executed plan that failed is saved there as an animated GIF (SEED-PREDICATE-K.gif); every run is then
filmed as it goes, and the time spent taking its pictures is left out of the times.
"""

from __future__ import annotations

import argparse
import collections
import os
import random
import statistics
import time
from dataclasses import dataclass, field
from pathlib import Path

from record import add_json_option, write_results

from lmcr.jsonl import InputError
from lmcr.lexicon import load_lexicon
from lmcr.robot.execute import execute
from lmcr.robot.render import VIDEO_EVERY, Recorder
from lmcr.robot.scene import make_scene, robot_objects
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.srl.instruction import NoPredicateError
from lmcr.workspace import Workspace

# predicate -> (incomplete instruction, the object it needs that is stated, the one to be filled in, its role)
TASKS = {
    "pour": ("pour me some water", "water", "cup", "Destination"),
    "fill": ("fill the glass", "glass", "milk", "Theme"),
    "sprinkle": ("sprinkle some cheese", "cheese", "pizza", "Destination"),
    "season": ("season the steak", "steak", "salt", "Instrument"),
    "heat": ("heat the soup", "soup", "microwave", "Instrument"),
    "fry": ("fry the egg", "egg", "pan", "Instrument"),
    "blend": ("blend the banana", "banana", "blender", "Destination"),
    "dump": ("dump the pasta", "pasta", "pot", "Destination"),
    "dip": ("dip the strawberry", "strawberry", "chocolate", "Destination"),
    "brush": ("brush the oil", "oil", "bread", "Destination"),
    "rub": ("rub the salt", "salt", "steak", "Destination"),
    # the motions of the learned verbs, by the Destination's kind (lmcr/robot/household.json)
    "place": ("put the apple away", "apple", "shelf", "Destination"),
    "place in a drawer": ("put the apple away", "apple", "drawer", "Destination"),
    "place in the fridge": ("put the milk away", "milk", "fridge", "Destination"),
    "place in the dishwasher": ("put the plate away", "plate", "dishwasher", "Destination"),
    "place in the cupboard": ("put the cup away", "cup", "cabinet", "Destination"),
    "place on the stove": ("put the pot", "pot", "stove", "Destination"),
    "dispose": ("throw out the banana", "banana", "trash can", "Destination"),
    "hand over": ("hand me the knife", "knife", "person", "Destination"),
    # ... and of the learned verbs whose class works with a tool (the Instrument) on the Theme
    "stir": ("stir the soup", "soup", "spoon", "Instrument"),
    "whisk": ("whisk the batter", "batter", "whisk", "Instrument"),
    "wipe": ("wipe the cutting board", "cutting board", "sponge", "Instrument"),
    "cut": ("cut the bread", "bread", "knife", "Instrument"),
    "cover": ("cover the pot", "pot", "lid", "Instrument"),
    # ... and of the serve class: a ladle the robot finds on the table carries the Theme's content
    "serve": ("scoop the soup", "soup", "bowl", "Destination"),
    # ... and of the cook class: the Theme put where it cooks (its Instrument), a microwave or an oven
    "cook": ("reheat the soup", "soup", "microwave", "Instrument"),
    "cook in the oven": ("bake the bread", "bread", "oven", "Instrument"),
}
ALSO = {"serve": ("ladle",)}  # on the table too: what the motion needs that the instruction leaves unsaid
TOOLS = {"stir", "whisk", "wipe", "cut", "cover"}  # the tool is held: the object filled in, not the one stated
# distractors: the household's receptacles and tools too
LEARNED = {
    "place",
    "place in a drawer",
    "place in the fridge",
    "place in the dishwasher",
    "place in the cupboard",
    "place on the stove",
    "dispose",
    "hand over",
    "serve",
    "cook",
    "cook in the oven",
    *TOOLS,
}
SLOW = 30  # seconds: no instruction should take longer to plan (or refuse) and execute
HELD_IS_STATED = {"pour", "sprinkle", "heat", "fry", "blend", "dump", "dip", "brush", "rub", *LEARNED} - TOOLS


def failure_reason(out: dict, held: str, target: str) -> str:
    """The first failed check of an executed plan, in words; a knock names the step it happened in
    (the task's objects written as <held> and <target>, so that the histogram groups them)."""
    checks = out["checks"]
    if not checks.get("grasped", True):
        return "grasp missed"
    if checks.get("knocked"):
        step = next(iter(out.get("knocked_during", {}).values()), "?")
        return f"knocked an object ({step.replace(held, '<held>').replace(target, '<target>')})"
    if not checks.get("verb_check", True) and out.get("target_moved_m", 0) > 0.02:
        return f"pushed the target {100 * out['target_moved_m']:.0f} cm"
    far = [w["name"] for w in out["waypoints"] if w["error_m"] > 0.02]
    if far:
        return f"waypoint off by > 2 cm ({far[0].split(' ')[0]})"
    failed = [k for k, v in checks.items() if v is False and k not in ("verb_check", "waypoints_within_tolerance")]
    if "liquid_in_target" in checks:
        failed.append(f"liquid missed the target ({checks['liquid_in_target']:.2f} in)")
    if "powder_on_target" in checks:
        failed.append(f"powder missed the target ({checks['powder_on_target']:.2f} on)")
    return "verb check failed: " + (failed[0] if failed else "?")


def refusal_reason(out: dict) -> str:
    """The refusal's kind: out of reach, an obstacle, no clear path."""
    reason = out.get("reason", "")
    for key, name in (
        ("cannot reach", "out of reach"),
        ("no clear way", "no collision-free path"),
        ("against the table", "pose hits the table"),
        ("against", "pose hits an object"),
        ("hand is full", "hand full"),
    ):
        if key in reason:
            return name
    return reason[:40]


def random_scene(
    seed: str, stated: str, expected: str, objects: tuple, distractors: int, holding: str | None, also: tuple = ()
):
    """The task's objects (and the ones it needs `also`) and random distractors at random spots; a draw
    whose objects do not fit on the table is drawn again."""
    for attempt in range(100):
        rng = random.Random(f"{seed}:{attempt}" if attempt else seed)
        others = rng.sample([o for o in objects if o not in (stated, expected, *also)], distractors)
        on_table = [o for o in [stated, expected, *also, *others] if o != holding]
        try:
            return make_scene([(label, None) for label in on_table], seed=rng.randrange(10**6), holding=holding)
        except InputError:  # no room for them all
            continue
    raise RuntimeError(f"{seed}: no layout fits")


@dataclass
class Tally:
    """What the rows add up to: each instruction's (seconds, name, executed or refused), failure and
    refusal reasons."""

    runs: list = field(default_factory=list)
    reasons: collections.Counter = field(default_factory=collections.Counter)
    refusals: collections.Counter = field(default_factory=collections.Counter)


def measure_row(predicate: str, args, ws, scorer, config, nlp, pool: tuple, tally: Tally) -> collections.Counter:
    """One predicate on `args.placements` random layouts: executed, succeeded, refused, replanned and how
    often the LM would have chosen another object. Raises NoPredicateError when the store cannot carry
    the predicate out at all (never learned, or no motion for its class)."""
    instruction, stated, expected, role = TASKS[predicate]
    row = collections.Counter()
    for k in range(args.placements):
        holding = stated if args.holding else None
        scene = random_scene(
            f"{args.seed}:{predicate}:{k}", stated, expected, pool, args.distractors, holding, ALSO.get(predicate, ())
        )
        started = time.perf_counter()
        recorder = Recorder(scene, every=VIDEO_EVERY) if args.videos else None
        out = execute(
            instruction, scene, nlp, scorer, config, ws.robot, recorder, answer={role: expected}, urdf=ws.baxter_urdf
        )
        # the pictures of a video are no part of planning or acting: their time is left out
        taking_pictures = recorder.seconds if recorder is not None else 0.0
        seconds = time.perf_counter() - started - out["seconds"]["perceive_and_complete"] - taking_pictures
        tally.runs.append((seconds, f"{predicate} {k}", "refused" if not out["feasible"] else "executed"))
        lm_choice = max(out["ranking"], key=lambda r: r["probability"])["object"] if out["ranking"] else None
        row["other_choice"] += lm_choice != expected
        if not out["feasible"]:
            row["refused"] += 1
            tally.refusals[refusal_reason(out)] += 1
            continue
        row["executed"] += 1
        row["ok"] += out["success"]
        row["replanned"] += out["replanned_after_grasp"]
        if not out["success"]:
            held, target = (stated, expected) if predicate in HELD_IS_STATED else (expected, stated)
            tally.reasons[f"{predicate}: {failure_reason(out, held, target)}"] += 1
            if recorder is not None:
                print(f"  video: {recorder.save_video(args.videos / f'{args.seed}-{predicate}-{k}.gif')}")
    return row


def main() -> None:
    parser_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser_.add_argument("--placements", type=int, default=20)
    parser_.add_argument("--distractors", type=int, default=4)
    parser_.add_argument("--method", default=COMPLETION_METHOD)
    parser_.add_argument("--seed", type=int, default=0)
    parser_.add_argument("--predicates", default=",".join(TASKS), help="comma-separated subset")
    parser_.add_argument("--urdf", help="a Baxter URDF to use instead of the built-in one (LMCR_BAXTER_URDF)")
    parser_.add_argument(
        "--holding", action="store_true", help="the stated object starts in the hand (fill, season: put down first)"
    )
    parser_.add_argument("--videos", type=Path, help="folder for an animated GIF of each executed plan that failed")
    add_json_option(parser_, "bench_executor")
    args = parser_.parse_args()
    if args.videos and args.videos.exists() and not args.videos.is_dir():
        parser_.error(f"--videos {args.videos}: is a file, not a folder")
    if args.urdf:
        os.environ["LMCR_BAXTER_URDF"] = args.urdf
    ws = Workspace.from_env()
    scorer, config = ws.completion_scorer(args.method)
    nlp = ws.parser()
    objects, household_too = load_lexicon().objects, tuple(sorted(robot_objects()))
    tally, totals, per_predicate = Tally(), collections.Counter(), {}
    for predicate in args.predicates.split(","):
        pool = household_too if predicate in LEARNED else objects
        try:
            row = measure_row(predicate, args, ws, scorer, config, nlp, pool, tally)
        except NoPredicateError as exc:
            # the store never learned the verb, or has no motion for its class: the row is unmeasured on
            # this store and said so, not a traceback that loses the rows already run
            per_predicate[f"{predicate}: not measured"] = str(exc)
            print(f"{predicate:17s} not measured on this store: {exc}", flush=True)
            continue
        totals.update(row)
        per_predicate[f"{predicate}: succeeded"] = f"{row['ok']}/{args.placements}"
        print(
            f"{predicate:17s} succeeded {row['ok']}/{args.placements} (executed {row['executed']}, failed "
            f"{row['executed'] - row['ok']}, refused before moving {row['refused']}); the language model "
            f"would have chosen another object than {TASKS[predicate][2]!r} {row['other_choice']} times",
            flush=True,
        )
    n = totals["executed"] + totals["refused"]
    if not n:
        raise SystemExit("bench_executor: no predicate could be measured on this store (each reason is above)")
    print(
        f"overall: succeeded {totals['ok']}/{n} = {totals['ok'] / n:.3f}; of executed plans "
        f"{totals['ok']}/{totals['executed']} = {totals['ok'] / max(totals['executed'], 1):.3f}; "
        f"refused {totals['refused']}; planned afresh after a grasp that shifted the object {totals['replanned']}"
    )
    print("failures of executed plans:", dict(tally.reasons.most_common()) or "none")
    print("refusals:", dict(tally.refusals.most_common()) or "none")
    times = [seconds for seconds, _, _ in tally.runs]
    print(
        f"plan and execute one instruction: median {statistics.median(times):.2f} s, max {max(times):.2f} s "
        f"(wall clock, 2 cores; simulation at 240 Hz, DIRECT); over {SLOW} s: {sum(t > SLOW for t in times)}; slowest: "
        + ", ".join(f"{name} {seconds:.1f} s ({what})" for seconds, name, what in sorted(tally.runs)[::-1][:3])
    )
    figures = {
        "robot": "official Baxter URDF" if args.urdf else "built-in Baxter",
        "seed": args.seed,
        "placements per predicate": args.placements,
        "distractors": args.distractors,
        "stated object in the hand": args.holding,
        "succeeded": f"{totals['ok']}/{n}",
        "success rate": round(totals["ok"] / n, 3),
        "of executed plans": f"{totals['ok']}/{totals['executed']}",
        "refused before moving": totals["refused"],
        "planned afresh after the grasp": totals["replanned"],
        "plan and execute, median s": round(statistics.median(times), 2),
        "plan and execute, max s": round(max(times), 2),
        f"plan and execute over {SLOW} s": sum(t > SLOW for t in times),
        **per_predicate,
    }
    write_results(args.json, "bench_executor", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
