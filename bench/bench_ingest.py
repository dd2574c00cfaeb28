"""Benchmark: full ingest of the shared corpora into a fresh store, then an unchanged re-run.

Usage: python bench/bench_ingest.py [--shared DIR] [--workers N] [--json PATH]
Prints wall time, sentences/s and words/s for the cold run, and the wall time of the no-op re-run.
"""

from __future__ import annotations

import argparse
import tempfile
import time

from record import add_json_option, add_shared_option, write_results

from lmcr.ingest import expand_inputs
from lmcr.ingest.run import corpus_summary, ingest_sources
from lmcr.store import connect
from lmcr.workspace import Workspace


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_shared_option(parser)
    parser.add_argument("--workers", type=int, default=2)
    add_json_option(parser, "bench_ingest")
    args = parser.parse_args()
    figures = {}
    data = args.shared / "data"
    with tempfile.TemporaryDirectory() as tmp:
        paths = Workspace.from_env(data_dir=tmp)
        con = connect(paths.db, paths.sql_dir)
        sources = expand_inputs([data / "youcook2" / "youcookii_annotations_trainval.json"], "youcook2")
        sources += expand_inputs(
            [data / "recipes" / "web_recipes.jsonl.gz", data / "recipes" / "feeding_america"], "recipes"
        )
        started = time.perf_counter()
        loaded, _ = ingest_sources(con, sources, paths.staging, args.workers)
        cold = time.perf_counter() - started
        started = time.perf_counter()
        ingest_sources(con, sources, paths.staging, args.workers)
        warm = time.perf_counter() - started
        for row in corpus_summary(con, paths.sql_dir):
            print(" ".join(f"{k}={v}" for k, v in row.items()))
            figures |= {f"corpus {row['corpus']}: {k}": v for k, v in row.items() if k != "corpus"}
    sentences, words = sum(s.sentences for s in loaded), sum(s.words for s in loaded)
    print(
        f"cold ingest: {cold:.1f}s wall, {sentences / cold:,.0f} sentences/s, {words / cold:,.0f} words/s "
        f"({len(loaded)} sources, {args.workers} workers)"
    )
    print(f"unchanged re-run: {warm:.2f}s wall ({cold / warm:.0f}x faster than cold)")
    figures = {
        "sources": len(loaded),
        "workers": args.workers,
        "cold ingest s": round(cold, 1),
        "sentences/s": round(sentences / cold),
        "words/s": round(words / cold),
        "unchanged re-run s": round(warm, 2),
        **figures,
    }
    write_results(args.json, "bench_ingest", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
