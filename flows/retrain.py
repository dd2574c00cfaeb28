"""Retrain flow (the scheduled deployment): ingest and parse what changed, then act on the kind of change
(`lmcr.retrain`): nothing; new ratings only: judge and calibrate the current checkpoint again; new or
changed corpus files: continue the current LM on the new text; removed files: train from scratch. A
trained candidate is promoted only if it is not worse. The decision, its reason and its cost are
recorded in DuckDB and published as an artifact."""

from __future__ import annotations

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact

from flows.annotate import ingest_task
from flows.frames import frames_flow
from flows.ingest import ingest_flow
from lmcr.evaluate.ratings import rated_frames
from lmcr.lexicon import load_lexicon
from lmcr.lm.hyperparams import LMConfig, TrainConfig, WarmStartConfig
from lmcr.retrain import (
    Candidate,
    Change,
    Inputs,
    RetrainConfig,
    classify,
    current_checkpoint,
    decide,
    last_inputs,
    record_unchanged,
    rejudge,
    train_candidate,
)
from lmcr.workspace import Workspace


@task(name="train-candidate")
def candidate_task(
    change: Change, config: RetrainConfig, ws: Workspace, model: LMConfig, train: TrainConfig, warm: WarmStartConfig
) -> Candidate:
    """Train a new version of the setting without making it LATEST: a warm start or a full run."""
    logger = get_run_logger()
    return train_candidate(
        ws.connect,
        ws.checkpoints,
        config.setting,
        change,
        model,
        train,
        warm,
        on_epoch=lambda row: logger.info("epoch %d: val ppl %.1f", row["epoch"], row["val_ppl"]),
    )


@task(name="decide-promotion")
def decide_task(candidate: Candidate, config: RetrainConfig, inputs: Inputs, change: Change, ws: Workspace) -> dict:
    with ws.connect() as con:
        rated = rated_frames(con, set(load_lexicon().predicates))
        return decide(con, ws.checkpoints, candidate, rated, config, inputs, change, ws.db, ws.calibration)


@task(name="recalibrate-current")
def rejudge_task(config: RetrainConfig, inputs: Inputs, change: Change, ws: Workspace) -> dict:
    with ws.connect() as con:
        rated = rated_frames(con, set(load_lexicon().predicates))
        return rejudge(con, ws.checkpoints, rated, config, inputs, change, ws.db, ws.calibration)


@flow(name="retrain")
def retrain_flow(
    youcook2: list[str] | None = None,
    recipes: list[str] | None = None,
    household: list[str] | None = None,
    ratings: list[str] | None = None,
    remove: list[str] | None = None,
    config: RetrainConfig = RetrainConfig(),
    embedding: int = LMConfig.embedding,
    max_epochs: int = TrainConfig.max_epochs,
    max_minutes: float | None = TrainConfig.max_minutes,
    warm: WarmStartConfig = WarmStartConfig(),
    frames: bool = True,
    db: str | None = None,
    data_dir: str | None = None,
) -> dict:
    """Notice new, changed or removed corpora and new ratings (content hashes); act on the kind of
    change; promote a trained candidate if not worse. With `frames`, the frame corpus is rebuilt after a
    corpus change (only new sentences are parsed)."""
    logger = get_run_logger()
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    if youcook2 or recipes or household or remove:
        ingest_flow(youcook2=youcook2, recipes=recipes, household=household, remove=remove, db=db, data_dir=data_dir)
        if frames:
            frames_flow(db=db, data_dir=data_dir)
    for path in ratings or []:
        ingest_task(path, ws)
    current = current_checkpoint(ws.checkpoints, config.setting)
    with ws.connect() as con:
        inputs = Inputs.read(con, config.linearization)
        previous = last_inputs(con, config.setting) or (current and Inputs.of_checkpoint(current))
    change = classify(previous, inputs)
    action = change.action(has_checkpoint=current is not None)
    if action == "none":
        with ws.connect() as con:
            row = record_unchanged(con, config, inputs)
    elif action == "recalibrate":
        row = rejudge_task(config, inputs, change, ws)
    else:
        train = TrainConfig(max_epochs=max_epochs, max_minutes=max_minutes)
        candidate = candidate_task(change, config, ws, LMConfig(0, embedding), train, warm)
        row = decide_task(candidate, config, inputs, change, ws)
    logger.info("%s: %s, %s (%s)", config.setting, change.kind, row["decision"], row["reason"])
    create_table_artifact(
        key="retrain-decision",
        table=[{k: v for k, v in row.items() if k not in ("inputs_sha256", "inputs_json")}],
        description=f"retrain {config.setting}: {change.kind} -> {row['action']}, {row['decision']}",
    )
    return row
