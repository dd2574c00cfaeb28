"""Benchmark: completion on the dev instructions (accuracy, questions) and its latency.

Usage: python bench/bench_complete.py --instructions instructions_dev.jsonl [--method sentence_lm+frame_counts] [--corpus all]
Uses the store and checkpoints of $LMCR_DATA_DIR and the calibration `lmcr evaluate` wrote there.
1. Accuracy: an instruction counts as right when the completed frame is the expected one and no
   question is asked, or when a question is asked and names the expected object.
2. Latency: one completion of "pour me some water" with 40 detected objects (the whole robot
   vocabulary but the theme, cycled), median and p90 of 200 runs after 20 warm-up runs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from lmcr.complete import complete
from lmcr.jsonl import read_jsonl
from lmcr.lexicon import load_lexicon
from lmcr.methods import COMPLETION_METHOD
from lmcr.workspace import Workspace


def accuracy(parser, scorer, config, path: Path) -> str:
    rows = [r for _, r in read_jsonl(path, {"instruction": str, "objects": list, "expected": dict})]
    answered = asked = asked_right = 0
    for r in rows:
        out = complete(parser, scorer, r["instruction"], r["objects"], config)
        missing = r.get("missing")
        if out["question"]:
            asked += 1
            asked_right += bool(missing) and f"the {r['expected']['roles'][missing]}" in out["question"]
        else:
            answered += out["frame"] == r["expected"]
    right = answered + asked_right
    return (f"dev instructions: {right}/{len(rows)} = {right / len(rows):.3f} right "
            f"({answered} answered right, {asked} questions of which {asked_right} name the expected object)")


def latency(parser, scorer, config, n_objects: int = 40, runs: int = 200) -> str:
    objects = [o for o in load_lexicon().objects if o != "water"][:n_objects]
    for _ in range(20):
        complete(parser, scorer, "pour me some water", objects, config)
    times = []
    for _ in range(runs):
        started = time.perf_counter()
        complete(parser, scorer, "pour me some water", objects, config)
        times.append(time.perf_counter() - started)
    times.sort()
    return (f"latency with {len(objects)} objects: median {1000 * statistics.median(times):.2f} ms, "
            f"p90 {1000 * times[int(0.9 * runs)]:.2f} ms ({runs} runs)")


def main() -> None:
    parser_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser_.add_argument("--instructions", type=Path, required=True)
    parser_.add_argument("--method", default=COMPLETION_METHOD)
    parser_.add_argument("--corpus", default="all")
    args = parser_.parse_args()
    ws = Workspace.from_env()
    scorer, config = ws.completion_scorer(args.method, ws.resources(corpus=args.corpus))
    parser = ws.parser()
    print(f"{args.method} ({args.corpus}); {config.source}")
    print(accuracy(parser, scorer, config, args.instructions))
    print(latency(parser, scorer, config))


if __name__ == "__main__":
    main()
