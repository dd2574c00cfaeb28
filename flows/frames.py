"""Frames flow: sentence shards parsed into frames on a task runner, one task loads DuckDB.

The default runner is a local process pool; `run_frames(..., dask="local")` runs the same flow on a
local Dask cluster and `dask="tcp://scheduler:8786"` on an existing Dask scheduler (scale-out).
"""

from __future__ import annotations

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact
from prefect.task_runners import ProcessPoolTaskRunner, TaskRunner

from flows.futures import results
from lmcr.frame_corpus.build import build_frame_corpus
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.frame_corpus.shards import Shard, ShardJob, ShardResult, parse_shard
from lmcr.store import check_contracts, named_query, query_dicts
from lmcr.workspace import Workspace


@task(name="parse-shard", task_run_name="parse shard {shard.number}")
def parse_shard_task(shard: Shard, job: ShardJob) -> ShardResult:
    """Parse one sentence shard to frame Parquet (runs on the task runner's workers)."""
    return parse_shard(shard, job)


def on_task_runner(shards: list[Shard], job: ShardJob) -> list[ShardResult]:
    """The build's `parse_all`: a task per shard on the flow's task runner."""
    futures = [parse_shard_task.submit(shard, job) for shard in shards]
    return results(futures)


@flow(name="frames", task_runner=ProcessPoolTaskRunner(max_workers=2))
def frames_flow(
    kinds: list[str] = list(FrameCorpusConfig.kinds),  # noqa: B006 - Prefect parameters must be JSON
    shard_size: int = FrameCorpusConfig.shard_size,
    model: str | None = None,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Build the frame corpora from the ingested sentences; skipped when nothing they depend on changed.
    The store is written by this flow alone: the shard tasks only read and write Parquet."""
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    config = FrameCorpusConfig(tuple(kinds), shard_size, model or ws.spacy_model)
    with ws.connect() as con:
        build = build_frame_corpus(con, ws.staging, ws.srl_dir, config, on_task_runner, log=get_run_logger().info)
        check_contracts(con, ws.sql_dir, prefix="frames_")
        counts = query_dicts(con, named_query(ws.sql_dir, "frame_counts"))
    if build is None:
        return {"skipped": True}
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
