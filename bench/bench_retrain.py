"""Benchmark: what one retrain costs for each kind of change, on a data folder that already has a current
checkpoint of the setting (a store the pipeline or `lmcr train` built).

Usage: python bench/bench_retrain.py --ratings FILE [--add-recipes FILE] [--remove FILE] [--data-dir DIR]
       [--setting sentence-all] [--json PATH]

Each step runs the retrain flow once, against one local Prefect server, and reads its decision back:
1. `--ratings`: a copy of the rating file with one more byte (new file hash, same ratings): the change is
   `ratings`, and the flow judges and recalibrates the current checkpoint without training;
2. `--add-recipes`: a recipe file (a new collection, e.g. about 5% of the corpus's sentences): the flow
   ingests it, parses only its new sentences, continues the current LM on them with a replay of the old
   and gates the candidate;
3. `--remove`: an ingested source taken out: a full training.
Per step: wall seconds of the whole flow and of the decision (training, gate, calibration), tokens
trained, the action and decision, and for a corpus step the texts the frame build parsed. The flow
changes the data folder as a user's retrain would: run it on a copy made for benchmarking.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from record import add_json_option, write_results

from flows.retrain import retrain_flow
from flows.server import run_with_server
from lmcr.errors import LMCRError
from lmcr.retrain import RetrainConfig
from lmcr.workspace import Workspace


def last_build(data_dir: str) -> dict:
    """The newest frame build's record (texts in the corpus, texts parsed, words parsed)."""
    with Workspace.from_env(data_dir=data_dir).connect() as con:
        row = con.execute(
            "select texts, texts_parsed, words_parsed, wall_s from frame_builds order by built_at desc limit 1"
        ).fetchone()
    return dict(zip(("texts", "texts_parsed", "words_parsed", "frames_wall_s"), row)) if row else {}


def step(name: str, data_dir: str, setting: str, **inputs) -> dict:
    """Run the retrain flow once and return its figures."""
    started = time.perf_counter()
    row = run_with_server(retrain_flow, config=RetrainConfig(setting=setting), data_dir=data_dir, **inputs)
    wall = time.perf_counter() - started
    figures = {
        "change": row["change"],
        "action": row["action"],
        "decision": row["decision"],
        "flow seconds": round(wall, 1),
        "decision seconds": round(row["seconds"], 1),
        "tokens trained": row["tokens_trained"],
        "tokens per second": round(row["tokens_trained"] / row["seconds"]) if row["tokens_trained"] else 0,
    }
    if inputs.get("recipes") or inputs.get("remove"):
        figures.update(last_build(data_dir))
    print(f"{name}: " + ", ".join(f"{k} {v}" for k, v in figures.items()), flush=True)
    return figures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratings", type=Path, required=True, help="a rating file (MTurk CSV) already loaded")
    parser.add_argument("--add-recipes", type=Path, help="a new recipe file to add (corpus recipes)")
    parser.add_argument("--remove", type=str, help="an ingested source to remove")
    parser.add_argument("--data-dir", type=str, default=os.environ.get("LMCR_DATA_DIR"), help="the data folder")
    parser.add_argument("--setting", default="sentence-all", help="the checkpoint setting retrained")
    add_json_option(parser, "bench_retrain")
    args = parser.parse_args()
    if not args.data_dir:
        parser.error("give --data-dir or set LMCR_DATA_DIR")
    for path in (args.ratings, args.add_recipes):
        if path is not None and not path.is_file():
            parser.error(f"{path}: no such file")
    os.environ.setdefault("PREFECT_SERVER_ANALYTICS_ENABLED", "false")  # no telemetry from an offline host
    figures = {}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            ratings = Path(tmp) / f"new_{args.ratings.name}"
            shutil.copyfile(args.ratings, ratings)
            with open(ratings, "a", encoding="utf-8") as handle:
                handle.write("\n")
            figures["new rating file"] = step("new rating file", args.data_dir, args.setting, ratings=[str(ratings)])
            if args.add_recipes:
                figures["new corpus file"] = step(
                    "new corpus file", args.data_dir, args.setting, recipes=[str(args.add_recipes)]
                )
            if args.remove:
                figures["removed corpus file"] = step(
                    "removed corpus file", args.data_dir, args.setting, remove=[args.remove]
                )
    except LMCRError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    write_results(args.json, "bench_retrain", "Retraining cost by kind of change", figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
