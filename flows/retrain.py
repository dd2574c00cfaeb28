"""Retrain flow (the scheduled deployment): ingest what changed, and when the corpus or the ratings
changed, train a candidate checkpoint, compare it with the current one on the rated frames, and
promote it only if it is not worse. The decision is recorded in DuckDB and published as an artifact."""

from __future__ import annotations

from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact

from flows.annotate import ingest_task
from flows.ingest import ingest_flow
from lmcr.config import paths_from_env
from lmcr.evaluate.ratings import rated_frames
from lmcr.lexicon import load_lexicon
from lmcr.lm.model import LMConfig
from lmcr.lm.run import train_setting
from lmcr.lm.train import TrainConfig
from lmcr.retrain import RetrainConfig, decide, inputs_sha256, last_inputs, record
from lmcr.setting import Setting
from lmcr.store import connect


@task(name="train-candidate")
def candidate_task(setting: str, db: str | None, data_dir: str | None, embedding: int, max_epochs: int,
                   max_minutes: float | None) -> str:
    """Train a new version of `setting` without making it LATEST."""
    paths = paths_from_env(data_dir=data_dir, db=db)
    chosen = Setting.parse(setting)
    path = train_setting(lambda: connect(paths.db, paths.sql_dir), paths.checkpoints, chosen.linearization,
                         chosen.corpus, LMConfig(0, embedding), TrainConfig(max_epochs=max_epochs, max_minutes=max_minutes),
                         promote=False)
    return str(path)


@task(name="decide-promotion")
def decide_task(candidate: str, config: RetrainConfig, inputs: str, db: str | None, data_dir: str | None) -> dict:
    paths = paths_from_env(data_dir=data_dir, db=db)
    with connect(paths.db, paths.sql_dir) as con:
        rated = rated_frames(con, set(load_lexicon().predicates))
        return decide(con, paths.checkpoints, Path(candidate), rated, config, inputs, paths.db,
                      paths.data_dir / "calibration")


@flow(name="retrain")
def retrain_flow(
    youcook2: list[str] | None = None,
    recipes: list[str] | None = None,
    ratings: list[str] | None = None,
    config: RetrainConfig = RetrainConfig(),
    embedding: int = 256,
    max_epochs: int = 8,
    max_minutes: float | None = 55.0,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Notice new or changed corpora and ratings (content hashes); retrain and promote if not worse."""
    logger = get_run_logger()
    if youcook2 or recipes:
        ingest_flow(youcook2=youcook2, recipes=recipes, db=db, data_dir=data_dir)
    for path in ratings or []:
        ingest_task(path, db, data_dir)
    paths = paths_from_env(data_dir=data_dir, db=db)
    with connect(paths.db, paths.sql_dir) as con:
        inputs = inputs_sha256(con, config.linearization)
        unchanged = inputs == last_inputs(con, config.setting)
        if unchanged:
            row = {"setting": config.setting, "inputs_sha256": inputs, "decision": "unchanged",
                   "reason": "corpus and ratings unchanged since the last decision"}
            record(con, row)
    if not unchanged:
        candidate = candidate_task(config.setting, db, data_dir, embedding, max_epochs, max_minutes)
        row = decide_task(candidate, config, inputs, db, data_dir)
    logger.info("%s: %s (%s)", config.setting, row["decision"], row["reason"])
    create_table_artifact(key="retrain-decision", table=[{k: v for k, v in row.items() if k != "inputs_sha256"}],
                          description=f"retrain {config.setting}: {row['decision']}")
    return row
