"""Annotate flow: generate rating tasks -> (crowd work happens outside) -> ingest results -> aggregate,
with artifacts of Krippendorff's alpha and the worker table.

Run it once with `tasks_out` to write a batch; after the HITs come back, run it with `results`.
"""

from __future__ import annotations

from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact

from lmcr.annotate.quality import QualityRules, alpha_by_verb, decisions, worker_table, write_decisions
from lmcr.annotate.results import ingest_ratings
from lmcr.annotate.tasks import TaskConfig, generate_tasks
from lmcr.store import check_contracts
from lmcr.workspace import Workspace


@task(name="generate-tasks")
def tasks_task(out: str, config: TaskConfig, ws: Workspace) -> dict:
    with ws.connect() as con:
        meta = generate_tasks(con, Path(out), config)
    get_run_logger().info("%d frames in %d HITs -> %s", meta["frames"], meta["hits"], out)
    return meta


@task(name="ingest-ratings", retries=2, retry_delay_seconds=5)  # files may still be copying in
def ingest_task(path: str, ws: Workspace) -> dict:
    with ws.connect() as con:
        counts = ingest_ratings(con, Path(path))
        check_contracts(con, ws.sql_dir, "ratings")
    get_run_logger().info("%s: %s", path, counts)
    return counts


@task(name="aggregate-ratings")
def aggregate_task(decisions_out: str | None, ws: Workspace) -> dict:
    with ws.connect() as con:
        alpha = alpha_by_verb(con)
        workers = worker_table(con)
        if decisions_out:
            write_decisions(Path(decisions_out), decisions(con, QualityRules(), workers=workers))
    create_table_artifact(
        key="krippendorff-alpha",
        table=[{"verbs": k, "alpha": round(v, 3)} for k, v in alpha.items()],
        description="Krippendorff's alpha (interval) over valid ratings",
    )
    create_table_artifact(
        key="worker-quality",
        table=workers.astype(object).where(workers.notna(), None).to_dict("records"),
        description="Per worker: leave-one-out agreement, gold accuracy, MACE spam probability",
    )
    return {"alpha": alpha, "workers": len(workers)}


@flow(name="annotate")
def annotate_flow(
    tasks_out: str | None = None,
    task_config: TaskConfig = TaskConfig(),
    results: list[str] = [],  # noqa: B006 - Prefect parameters must be JSON
    decisions_out: str | None = None,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Generate a batch (with `tasks_out`), ingest result files, aggregate whatever ratings exist."""
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    out: dict = {}
    if tasks_out:
        out["tasks"] = tasks_task(tasks_out, task_config, ws)
    out["ingested"] = [ingest_task(path, ws) for path in results]
    with ws.connect() as con:
        rated = con.execute("select count(*) from ratings").fetchone()[0]
    if rated:
        out["aggregate"] = aggregate_task(decisions_out, ws)
    return out
