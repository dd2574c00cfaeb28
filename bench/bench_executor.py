"""Benchmark: the Baxter executor on random table layouts, per predicate.

Usage: python bench/bench_executor.py [--placements 20] [--distractors 0] [--method sentence_lm+frame_counts] [--seed 0]
For each of the 11 predicates, an incomplete instruction (the role the robot must fill is left out)
on `--placements` random layouts: the two objects the frame needs (plus `--distractors` random other
objects), placed at random with a seed. The instruction is completed with the published checkpoint of $LMCR_DATA_DIR (with
its calibration), then planned and executed. Prints the success rate per predicate (success = every waypoint within 2 cm and the verb's check passed
for the frame as completed), how often the completion picked another object than the one the task
was built around (a distractor can be just as sensible: a pot for water), and the time to plan and
execute one instruction.
"""

from __future__ import annotations

import argparse
import random
import statistics

from lmcr.executor.execute import ExecutionError, execute
from lmcr.executor.scene import make_scene
from lmcr.jsonl import InputError
from lmcr.lexicon import load_lexicon
from lmcr.methods import COMPLETION_METHOD
from lmcr.workspace import Workspace

# predicate -> (incomplete instruction, the object it needs that is stated, the one to be filled in)
TASKS = {
    "pour": ("pour me some water", "water", "cup"),
    "fill": ("fill the glass", "glass", "milk"),
    "sprinkle": ("sprinkle some cheese", "cheese", "pizza"),
    "season": ("season the steak", "steak", "salt"),
    "heat": ("heat the soup", "soup", "microwave"),
    "fry": ("fry the egg", "egg", "pan"),
    "blend": ("blend the banana", "banana", "blender"),
    "dump": ("dump the pasta", "pasta", "pot"),
    "dip": ("dip the strawberry", "strawberry", "chocolate"),
    "brush": ("brush the oil", "oil", "bread"),
    "rub": ("rub the salt", "salt", "steak"),
}


def main() -> None:
    parser_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser_.add_argument("--placements", type=int, default=20)
    parser_.add_argument("--method", default=COMPLETION_METHOD)
    parser_.add_argument("--seed", type=int, default=0)
    parser_.add_argument("--predicates", default=",".join(TASKS), help="comma-separated subset")
    parser_.add_argument("--distractors", type=int, default=0,
                         help="random extra objects: with none the completion has one choice and the run measures "
                              "execution; with some it also measures the completion")
    args = parser_.parse_args()
    ws = Workspace.from_env()
    scorer, config = ws.completion_scorer(args.method)
    nlp = ws.parser()
    objects = load_lexicon().objects
    times, totals = [], {"ok": 0, "n": 0}
    for predicate in args.predicates.split(","):
        instruction, stated, expected = TASKS[predicate]
        ok = wrong_object = failed = 0
        for k in range(args.placements):
            rng = random.Random(f"{args.seed}:{predicate}:{k}")
            others = rng.sample([o for o in objects if o not in (stated, expected)], args.distractors)
            try:
                scene = make_scene([(label, None) for label in [stated, expected, *others]], seed=rng.randrange(10**6))
                out = execute(instruction, scene, nlp, scorer, config, ws.robot)
            except (ExecutionError, InputError):  # the completion named something absent; no room on the table
                failed += 1
                continue
            times.append(out["seconds"]["plan_and_execute"])
            wrong_object += out["chosen_object"] != expected
            ok += out["success"]
            failed += not out["success"]
        totals["ok"] += ok
        totals["n"] += args.placements
        print(f"{predicate:9s} executed successfully {ok}/{args.placements} (failed {failed}); the completion chose "
              f"another object than {expected!r} {wrong_object} times", flush=True)
    print(f"overall {totals['ok']}/{totals['n']} = {totals['ok'] / totals['n']:.3f}; plan and execute one "
          f"instruction: median {statistics.median(times):.2f} s, max {max(times):.2f} s (simulated, 240 Hz, DIRECT)")


if __name__ == "__main__":
    main()
