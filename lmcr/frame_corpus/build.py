"""The frames stage: learn compounds, export shards, learn first words, parse the shards on some worker
pool, load the store.

`build_frame_corpus` runs the steps once; what differs between the CLI (a process pool with a
progress bar) and the Prefect flow (a task per shard on its task runner) is only `parse_all`, the
function that parses a list of shards. A build is skipped when its fingerprint (ingested files,
settings, SRL code, compounds) matches the last one.
"""

from __future__ import annotations

import shutil
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import duckdb

from lmcr.files import atomic_path
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.frame_corpus.load import last_build, load_frames
from lmcr.frame_corpus.predicates import refresh_predicates
from lmcr.frame_corpus.shards import (
    Shard,
    ShardJob,
    ShardResult,
    build_fingerprint,
    export_shards,
    learn_first_words,
    parse_shard,
)
from lmcr.lexicon import load_lexicon
from lmcr.srl.compounds import learn_compounds
from lmcr.srl.parser import COMPOUNDS_FILE, FIRST_WORDS_FILE, PRIORS_FILE

# Parses every shard of a build (in any order), each with `parse_shard(shard, job)`.
ParseAll = Callable[[list[Shard], ShardJob], Iterable[ShardResult]]


def prepare_build(
    con: duckdb.DuckDBPyConnection, staging: Path, srl_dir: Path, config: FrameCorpusConfig
) -> tuple[str, list[Shard]] | None:
    """Learn compounds, fingerprint the build, and export shards; None when the corpus is unchanged."""
    compounds_path = srl_dir / COMPOUNDS_FILE
    learn_compounds(con).save(compounds_path)
    fingerprint = build_fingerprint(con, config, compounds_path)
    if last_build(con) == fingerprint:
        return None
    return fingerprint, export_shards(con, config, staging / "frames" / "input")


def summarize_build(fingerprint: str, config: FrameCorpusConfig, results: list[ShardResult], wall: float) -> dict:
    """The build record: sizes, re-parse counts, and words/s over the shards parsed (not cached)."""
    parsed_words = sum(r.shard.words for r in results if not r.cached)
    return {
        "fingerprint": fingerprint,
        "kinds": config.kinds,
        "sentences": sum(r.shard.sentences for r in results),
        "words": sum(r.shard.words for r in results),
        "reparsed": sum(r.reparsed for r in results),
        "kept": sum(r.kept for r in results),
        "wall_s": round(wall, 2),
        "words_per_s": round(parsed_words / wall, 1) if parsed_words else 0.0,
    }


def finish_build(
    con: duckdb.DuckDBPyConnection, srl_dir: Path, results: list[ShardResult], build: dict, job: ShardJob
) -> None:
    """Load the shards (one transaction) and publish the learned role priors and the first-word table
    the shards started from beside the compounds (`load_parser` reads all three)."""
    results = sorted(results, key=lambda r: r.shard.number)
    load_frames(con, results, build).save(srl_dir / PRIORS_FILE)
    with atomic_path(srl_dir / FIRST_WORDS_FILE) as tmp:
        shutil.copyfile(job.first_words, tmp)


def shard_job(staging: Path, srl_dir: Path, config: FrameCorpusConfig) -> ShardJob:
    """The workers' shared setup; creates the output folder."""
    out_dir = staging / "frames" / "output"
    out_dir.mkdir(parents=True, exist_ok=True)
    return ShardJob(str(out_dir), config.model, str(srl_dir / COMPOUNDS_FILE))


def process_pool(workers: int = 2, on_shard: Callable[[ShardResult], None] | None = None) -> ParseAll:
    """Parse shards on `workers` local processes, calling `on_shard` as each one finishes."""

    def parse_all(shards: list[Shard], job: ShardJob) -> Iterable[ShardResult]:
        with ProcessPoolExecutor(max_workers=max(1, workers)) as pool:
            for future in as_completed([pool.submit(parse_shard, s, job) for s in shards]):
                if on_shard:
                    on_shard(future.result())
                yield future.result()

    return parse_all


def build_frame_corpus(
    con: duckdb.DuckDBPyConnection,
    staging: Path,
    srl_dir: Path,
    config: FrameCorpusConfig = FrameCorpusConfig(),
    parse_all: ParseAll | None = None,
    log: Callable[[str], None] = lambda message: None,
) -> dict | None:
    """Build (or skip, when unchanged) the frame corpus; return the build record, None if skipped.
    Shards are parsed by `parse_all` (default: two local processes)."""
    prepared = prepare_build(con, staging, srl_dir, config)
    if prepared is None:
        log("frame corpus unchanged: skipped")
        _learn(con, srl_dir, last_build(con), log)
        return None
    fingerprint, shards = prepared
    started = time.perf_counter()  # the wall time and words/s include the first words' minute
    log(f"learning first words from up to {config.first_word_sample:,} texts")
    job = learn_first_words(shards, shard_job(staging, srl_dir, config), config.first_word_sample)
    log(f"parsing {len(shards)} shards of {sum(s.sentences for s in shards):,} sentences")
    results = list((parse_all or process_pool())(shards, job))
    build = summarize_build(fingerprint, config, results, time.perf_counter() - started)
    log(f"{build['words']:,} words at {build['words_per_s']:,.0f} words/s")
    finish_build(con, srl_dir, results, build, job)
    _learn(con, srl_dir, fingerprint, log)
    return build


def _learn(con: duckdb.DuckDBPyConnection, srl_dir: Path, build: str | None, log: Callable[[str], None]) -> None:
    """Learn the predicates of the build when it has no table yet (`frame_corpus.predicates`)."""
    table = refresh_predicates(con, load_lexicon(learned=False), srl_dir, build)
    if table is not None:
        log(f"learned {len(table.predicates):,} predicates; {len(table.refused):,} verbs refused (too little evidence)")
