"""Frames flow: sentence shards parsed into frames on a task runner, one task loads DuckDB.

The default runner is a local process pool; `run_frames(..., dask="local")` runs the same flow on a
local Dask cluster and `dask="tcp://scheduler:8786"` on an existing Dask scheduler (scale-out).
"""

from __future__ import annotations

import time
from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact
from prefect.task_runners import ProcessPoolTaskRunner, TaskRunner

from lmcr.config import paths_from_env
from lmcr.srl.corpus import (
    FrameCorpusConfig,
    Shard,
    ShardResult,
    finish_build,
    parse_shard,
    prepare_build,
    shard_output_dir,
    summarize_build,
)
from lmcr.srl.parser import COMPOUNDS_FILE
from lmcr.store import check_contracts, connect, named_query, query_dicts


@task(name="parse-shard", task_run_name="parse shard {shard.number}")
def parse_shard_task(shard: Shard, out_dir: str, model: str | None, compounds: str) -> ShardResult:
    """Parse one sentence shard to frame Parquet (runs on the task runner's workers)."""
    return parse_shard(shard, out_dir, model, compounds)


@task(name="load-frames")
def load_frames_task(db: Path, sql_dir: Path, srl_dir: Path, results: list[ShardResult], build: dict) -> list[dict]:
    """The single DuckDB writer: load frames, learn role priors, check contracts, count per predicate."""
    with connect(db, sql_dir) as con:
        finish_build(con, srl_dir, results, build)
        check_contracts(con, sql_dir, prefix="frames_")
        return query_dicts(con, named_query(sql_dir, "frame_counts"))


@flow(name="frames", task_runner=ProcessPoolTaskRunner(max_workers=2))
def frames_flow(
    kinds: list[str] = ["instruction", "comment"],  # noqa: B006 - Prefect parameters must be JSON
    shard_size: int = 20_000,
    model: str | None = None,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Build the frame corpora from the ingested sentences; skipped when nothing they depend on changed."""
    logger = get_run_logger()
    paths = paths_from_env(data_dir=data_dir, db=db)
    config = FrameCorpusConfig(tuple(kinds), shard_size, model)
    with connect(paths.db, paths.sql_dir) as con:
        prepared = prepare_build(con, paths.staging, paths.srl_dir, config)
    if prepared is None:
        logger.info("frame corpus unchanged: skipped")
        return {"skipped": True}
    fingerprint, shards = prepared
    logger.info("parsing %d shards of %d sentences", len(shards), sum(s.sentences for s in shards))
    out_dir, compounds = shard_output_dir(paths.staging), str(paths.srl_dir / COMPOUNDS_FILE)
    started = time.perf_counter()
    futures = [parse_shard_task.submit(s, out_dir, model, compounds) for s in shards]
    results = [f.result() for f in futures]
    build = summarize_build(fingerprint, config, results, time.perf_counter() - started)
    logger.info("%s words at %s words/s", f"{build['words']:,}", f"{build['words_per_s']:,.0f}")
    counts = load_frames_task(paths.db, paths.sql_dir, paths.srl_dir, results, build)
    create_table_artifact(key="frame-counts", table=counts, description="Robot-predicate frames per corpus")
    return {"skipped": False, **build, "kinds": list(build["kinds"]), "counts": counts}


def task_runner(workers: int = 2, dask: str | None = None) -> TaskRunner:
    """Process pool by default; `dask="local"` for a local Dask cluster, else a scheduler address."""
    if dask is None:
        return ProcessPoolTaskRunner(max_workers=workers)
    from prefect_dask import DaskTaskRunner

    if dask == "local":
        return DaskTaskRunner(cluster_kwargs={"n_workers": workers, "threads_per_worker": 1, "processes": True})
    return DaskTaskRunner(address=dask)


def run_frames(workers: int = 2, dask: str | None = None, **params) -> dict:
    """Run the frames flow on the chosen task runner."""
    return frames_flow.with_options(task_runner=task_runner(workers, dask))(**params)
