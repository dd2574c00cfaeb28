"""Benchmark: a new store built from scratch — ingest, frames and the sentence-all LM — stage by stage.

Usage: python bench/bench_from_scratch.py --data-dir NEW_DIR [--youcook2 F] [--recipes P ...] [--household P ...]
       [--shared DIR] [--json PATH]
Runs the three commands a user runs (`lmcr ingest`, `lmcr frames`, `lmcr train --linearization sentence
--corpus all`) one after the other in an empty data folder, each as its own process, and prints each
stage's wall seconds, the parse's words/s, and per epoch the validation perplexity, tokens/s and
seconds, with the share of the whole that each stage took. Without corpus options it takes the shared
corpora under --shared (default $LMCR_SHARED_DIR or ../shared). The folder is kept: it is a complete
store with a current sentence-all checkpoint, ready for `lmcr evaluate` or the retrain benchmark.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from record import add_json_option, add_shared_option, write_results

from lmcr.checkout import REPO_ROOT
from lmcr.workspace import Workspace

TRAIN = ("train", "--linearization", "sentence", "--corpus", "all")


def corpus_options(args: argparse.Namespace) -> list[str]:
    """The `lmcr ingest` options: the ones given, else the shared corpora."""
    data = args.shared / "data"
    youcook2 = args.youcook2 or [data / "youcook2" / "youcookii_annotations_trainval.json"]
    recipes = args.recipes or [data / "recipes" / "web_recipes.jsonl.gz", data / "recipes" / "feeding_america"]
    household = args.household or [data / "household"]
    options = []
    for flag, paths in (("--youcook2", youcook2), ("--recipes", recipes), ("--household", household)):
        for path in paths:
            options += [flag, str(path)]
    return options


def stage(name: str, argv: list[str], data_dir: Path) -> float:
    """Run one `lmcr` command in the data folder; its wall seconds. A failing stage ends the benchmark."""
    print(f"{name}: lmcr {' '.join(argv)}", flush=True)
    started = time.perf_counter()
    env = {**os.environ, "LMCR_DATA_DIR": str(data_dir)}
    done = subprocess.run([sys.executable, "-m", "lmcr.cli", *argv], env=env, cwd=REPO_ROOT, check=False)
    if done.returncode != 0:
        sys.exit(f"error: {name} failed with exit status {done.returncode}")
    seconds = time.perf_counter() - started
    print(f"{name}: {seconds:.0f} s", flush=True)
    return seconds


def store_figures(data_dir: Path) -> dict:
    """What the store recorded: the frame build's size and speed, and the LM run's epochs."""
    with Workspace.from_env(data_dir=str(data_dir)).connect() as con:
        texts, words, parse_s = con.execute(
            "select texts_parsed, words_parsed, wall_s from frame_builds order by built_at desc limit 1"
        ).fetchone()
        run_id, sequences, vocab, ppl = con.execute(
            "select run_id, train_sequences, vocab_size, best_val_ppl from lm_runs "
            "where linearization = 'sentence' and corpus = 'all' order by started_at desc limit 1"
        ).fetchone()
        epochs = con.execute(
            "select epoch, val_ppl, tokens_per_s, seconds, precision from lm_epochs where run_id = ? order by epoch",
            [run_id],
        ).fetchall()
    figures = {
        "texts parsed": texts,
        "words parsed": words,
        "parse words per second": round(words / parse_s),
        "train sequences": sequences,
        "vocabulary": vocab,
        "best val ppl": round(ppl, 2),
        "precision": epochs[0][4] if epochs else None,
    }
    for epoch, val_ppl, tokens_per_s, seconds, _ in epochs:
        figures[f"epoch {epoch}: val ppl, tokens/s, seconds"] = f"{val_ppl:.2f}, {tokens_per_s:,.0f}, {seconds:.0f}"
    return figures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-dir", type=Path, required=True, help="a new, empty data folder (kept)")
    add_shared_option(parser)
    parser.add_argument("--youcook2", type=Path, action="append", help="YouCook2 annotations (repeatable)")
    parser.add_argument("--recipes", type=Path, action="append", help="a recipe file or folder (repeatable)")
    parser.add_argument("--household", type=Path, action="append", help="a household file or folder (repeatable)")
    add_json_option(parser, "bench_from_scratch")
    args = parser.parse_args()
    if args.data_dir.exists() and any(args.data_dir.iterdir()):
        parser.error(f"{args.data_dir}: not empty; the benchmark builds a store from scratch")
    os.environ.setdefault("PREFECT_SERVER_ANALYTICS_ENABLED", "false")
    seconds = {
        "ingest": stage("ingest", ["ingest", *corpus_options(args)], args.data_dir),
        "frames": stage("frames", ["frames"], args.data_dir),
        "train sentence-all": stage("train sentence-all", list(TRAIN), args.data_dir),
    }
    total = sum(seconds.values())
    figures = {
        "total minutes": round(total / 60, 1),
        **{f"{name} seconds": round(s) for name, s in seconds.items()},
        **{f"{name} share": round(s / total, 3) for name, s in seconds.items()},
        **store_figures(args.data_dir),
    }
    for name, value in figures.items():
        print(f"{name}: {value}")
    write_results(args.json, "bench_from_scratch", "A store from scratch: ingest, frames, sentence-all LM", figures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
