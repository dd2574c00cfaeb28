"""Benchmark: completion on the dev instructions (accuracy, questions) and its latency.

Usage: python bench/bench_complete.py --instructions instructions_dev.jsonl [--method sentence_lm+frame_counts]
       [--corpus all] [--mixture household=30|plain] [--context-weight 1] [--no-context] [--scene-size 40]
       [--busy N] [--json PATH]
Uses the store, checkpoints, chosen mixture and context weight of $LMCR_DATA_DIR and the calibration `lmcr evaluate`
wrote there.
1. Accuracy: an instruction counts as right when the completed frame is the expected one, with or
   without a question; a question whose best guess is wrong is wrong even when it names the object.
   --scene-size N fills each scene with robot-vocabulary objects up to N: the same instructions among
   many distractors (what a cap on the frames that read the context could lose).
2. Latency: one completion of "pour me some water" and of "pour me some water for my tea" (context) with
   40 detected objects (the robot vocabulary but the theme), median and p90 of 200 runs after 20 warm-ups;
   the same for a learned verb, "put the milk away" (with and without "for my tea"), where the store
   learned it (its terms read a second set of texts, `lmcr/scorers/stated_pmi.py`);
   with --busy N while N processes spin, one core each, from BUSY_SETTLE seconds before (a busy machine:
   a request takes the cores the load average leaves idle, `lmcr.lm.threads`).
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

from record import add_json_option, busy_cores, write_results

from lmcr.complete import complete
from lmcr.evaluate.instructions import instruction_accuracy, load_instructions
from lmcr.lexicon import load_lexicon
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.workspace import Workspace

BUSY_SETTLE = 30  # seconds: the one-minute load average has risen past half a busy core by then


# (instruction, its Theme, the predicate it needs): the eleven's, then a learned verb's
TIMED = (
    ("pour me some water", "water", "pour"),
    ("pour me some water for my tea", "water", "pour"),
    ("put the milk away", "milk", "put away"),
    ("put the milk away for my tea", "milk", "put away"),
)


def latency(
    parser, scorer, config, instruction: str, n_objects: int = 40, runs: int = 200, theme: str = "water"
) -> dict:
    """Median and p90 milliseconds of one completion of `instruction` among `n_objects` detected objects."""
    objects = [o for o in load_lexicon().objects if o != theme][:n_objects]
    for _ in range(20):
        complete(parser, scorer, instruction, objects, config)
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        complete(parser, scorer, instruction, objects, config)
        times.append(time.perf_counter() - started)
    times.sort()
    return {
        "objects": len(objects),
        "median ms": round(1000 * statistics.median(times), 2),
        "p90 ms": round(1000 * times[int(0.9 * runs)], 2),
    }


def filled_scene(record: dict, size: int) -> dict:
    """The record with its objects followed by robot-vocabulary objects it lacks, up to `size` in all."""
    objects = list(dict.fromkeys([*record["objects"], *load_lexicon().objects]))
    return {**record, "objects": objects[: max(size, len(record["objects"]))]}


def main() -> None:
    parser_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser_.add_argument("--instructions", type=Path, required=True)
    parser_.add_argument("--method", default=COMPLETION_METHOD)
    parser_.add_argument("--corpus", default="all")
    parser_.add_argument(
        "--mixture", default=None, help="corpus weights (household=30, plain); default: the chosen one"
    )
    parser_.add_argument(
        "--context-weight", type=float, default=None, help="weight of the context term; default: the chosen one"
    )
    parser_.add_argument("--no-context", action="store_true", help="score the frame alone")
    parser_.add_argument("--runs", type=int, default=200, help="timed completions per latency figure (0: none)")
    parser_.add_argument("--scene-size", type=int, default=0, help="fill each scene with other objects up to this")
    parser_.add_argument("--busy", type=int, default=0, help="processes spinning beside the latency runs")
    add_json_option(parser_, "bench_complete")
    args = parser_.parse_args()
    ws = Workspace.from_env()
    res = ws.resources(corpus=args.corpus)
    res = replace(res, mixture=Mixture.parse(args.mixture)) if args.mixture is not None else res
    res = replace(res, context_weight=args.context_weight) if args.context_weight is not None else res
    scorer, config = ws.completion_scorer(args.method, res)
    config = replace(config, context=not args.no_context)
    parser = ws.parser()
    setting = (
        f"{args.method} ({args.corpus}, mixture {res.mixture.label}, context "
        f"{f'weight {res.context_weight:g}' if config.context else 'off'})"
    )
    print(f"{setting}; {config.source}")
    figures = {
        "method": setting,
        "instructions file": args.instructions.name,
        "scene size": args.scene_size or "as given",
    }
    records = load_instructions(args.instructions)
    if args.scene_size:
        records = [filled_scene(r, args.scene_size) for r in records]
        print(f"scenes filled to {args.scene_size} objects with the robot vocabulary")
    accuracy = instruction_accuracy(parser, scorer, config, records)
    print(accuracy.summary())
    figures |= {
        "instructions right": f"{accuracy.right}/{accuracy.total}",
        "accuracy": round(accuracy.accuracy, 3),
        "answered right without a question": accuracy.answered_right,
        "questions asked": accuracy.asked,
        "questions whose best guess is right": accuracy.asked_right,
    }
    if args.busy:
        figures["latency beside spinning processes"] = args.busy
    timed = []
    for instruction, theme, predicate in TIMED if args.runs else ():
        if predicate in parser.lex.predicates:
            timed.append((instruction, theme))
        else:
            print(f"latency of {instruction!r}: not measured, this store learned no {predicate!r}")
    with busy_cores(args.busy if timed else 0, settle=BUSY_SETTLE):
        for instruction, theme in timed:
            took = latency(parser, scorer, config, instruction, runs=args.runs, theme=theme)
            print(
                f"latency of {instruction!r} with {took['objects']} objects: median {took['median ms']:.2f} ms, "
                f"p90 {took['p90 ms']:.2f} ms ({args.runs} runs)"
            )
            figures |= {
                f"latency {instruction!r}, {took['objects']} objects: {k}": v for k, v in took.items() if k != "objects"
            }
    write_results(args.json, "bench_complete", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
