"""Retrain flow (the scheduled deployment): ingest what changed, and when the corpus or the ratings
changed, train a candidate checkpoint, compare it with the current one on the rated frames, and
promote it only if it is not worse. The decision is recorded in DuckDB and published as an artifact."""

from __future__ import annotations

from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact

from flows.annotate import ingest_task
from flows.ingest import ingest_flow
from lmcr.evaluate.ratings import rated_frames
from lmcr.lexicon import load_lexicon
from lmcr.lm.hyperparams import LMConfig, TrainConfig
from lmcr.lm.run import train_setting
from lmcr.retrain import RetrainConfig, decide, inputs_sha256, last_inputs, record
from lmcr.setting import Setting
from lmcr.workspace import Workspace


@task(name="train-candidate")
def candidate_task(setting: Setting, ws: Workspace, embedding: int, max_epochs: int, max_minutes: float | None) -> str:
    """Train a new version of `setting` without making it LATEST."""
    path = train_setting(
        ws.connect,
        ws.checkpoints,
        setting,
        LMConfig(0, embedding),
        TrainConfig(max_epochs=max_epochs, max_minutes=max_minutes),
        promote=False,
    )
    return str(path)


@task(name="decide-promotion")
def decide_task(candidate: str, config: RetrainConfig, inputs: str, ws: Workspace) -> dict:
    with ws.connect() as con:
        rated = rated_frames(con, set(load_lexicon().predicates))
        return decide(con, ws.checkpoints, Path(candidate), rated, config, inputs, ws.db, ws.calibration)


@flow(name="retrain")
def retrain_flow(
    youcook2: list[str] | None = None,
    recipes: list[str] | None = None,
    household: list[str] | None = None,
    ratings: list[str] | None = None,
    config: RetrainConfig = RetrainConfig(),
    embedding: int = LMConfig.embedding,
    max_epochs: int = TrainConfig.max_epochs,
    max_minutes: float | None = TrainConfig.max_minutes,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Notice new or changed corpora and ratings (content hashes); retrain and promote if not worse."""
    logger = get_run_logger()
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    if youcook2 or recipes or household:
        ingest_flow(youcook2=youcook2, recipes=recipes, household=household, db=db, data_dir=data_dir)
    for path in ratings or []:
        ingest_task(path, ws)
    with ws.connect() as con:
        inputs = inputs_sha256(con, config.linearization)
        unchanged = inputs == last_inputs(con, config.setting)
        if unchanged:
            row = {
                "setting": config.setting.name,
                "inputs_sha256": inputs,
                "decision": "unchanged",
                "reason": "corpus and ratings unchanged since the last decision",
            }
            record(con, row)
    if not unchanged:
        candidate = candidate_task(config.setting, ws, embedding, max_epochs, max_minutes)
        row = decide_task(candidate, config, inputs, ws)
    logger.info("%s: %s (%s)", config.setting, row["decision"], row["reason"])
    create_table_artifact(
        key="retrain-decision",
        table=[{k: v for k, v in row.items() if k != "inputs_sha256"}],
        description=f"retrain {config.setting}: {row['decision']}",
    )
    return row
