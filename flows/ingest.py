"""Ingest flow: a task per source parses and stages Parquet in parallel, one task loads DuckDB."""

from __future__ import annotations

from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact
from prefect.task_runners import ProcessPoolTaskRunner

from flows.futures import results
from lmcr.ingest import Source, StagedFile, expand_corpora
from lmcr.ingest.run import corpus_summary, parse_and_stage, plan
from lmcr.ingest.stage import load_staged, remove_sources
from lmcr.workspace import Workspace


@task(name="parse-and-stage", task_run_name="parse {source.path.name}")
def parse_and_stage_task(source: Source, sha256: str, staging_dir: Path) -> StagedFile:
    """Parse one source to Parquet (runs in a worker process)."""
    return parse_and_stage(source, sha256, staging_dir)


@task(name="load-duckdb", retries=2, retry_delay_seconds=2)
def load_task(ws: Workspace, staged: list[StagedFile]) -> list[dict]:
    """The single DuckDB writer: load every staged source, then summarise per corpus."""
    logger = get_run_logger()
    with ws.connect() as con:
        for item in staged:
            load_staged(con, item)
            logger.info(
                "loaded %s: %d in = %d loaded + %d quarantined",
                Path(item.source_file).name,
                item.records_in,
                item.records_loaded,
                item.records_quarantined,
            )
        return corpus_summary(con, ws.sql_dir)


@task(name="remove-sources")
def remove_task(ws: Workspace, paths: list[str]) -> list[dict]:
    """Take ingested sources out of the store, with their sentences (one transaction)."""
    with ws.connect() as con:
        removed = remove_sources(con, paths)
    for row in removed:
        get_run_logger().info("removed %s: %d sentences", row["source_file"], row["sentences"])
    return removed


@flow(name="ingest", task_runner=ProcessPoolTaskRunner(max_workers=2), log_prints=True)
def ingest_flow(
    youcook2: list[str] | None = None,
    recipes: list[str] | None = None,
    household: list[str] | None = None,
    fmt: str | None = None,
    db: str | None = None,
    data_dir: str | None = None,
    remove: list[str] | None = None,
) -> list[dict]:
    """Ingest YouCook2, recipe and household corpora; unchanged sources are skipped; sources in `remove`
    are taken out first; publishes a summary table."""
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    if remove:
        remove_task(ws, remove)
    sources = expand_corpora({"youcook2": youcook2, "recipes": recipes, "household": household}, fmt)
    with ws.connect() as con:
        todo, skipped = plan(con, sources)
    get_run_logger().info("%d sources to ingest, %d unchanged", len(todo), len(skipped))
    futures = [parse_and_stage_task.submit(s, sha, ws.staging) for s, sha in todo]
    summary = load_task(ws, results(futures))
    create_table_artifact(key="ingest-summary", table=summary, description="Corpus counts after ingest")
    return summary
