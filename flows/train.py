"""Train flow: one task per requested (linearization, corpus) setting, each publishing a checkpoint.

Settings train one after another: each uses every core through torch's threads already.
"""

from __future__ import annotations

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact

from lmcr.lm.hyperparams import LMConfig, TrainConfig
from lmcr.lm.run import train_setting
from lmcr.setting import ALL_SETTINGS, Setting
from lmcr.workspace import Workspace

SETTING_NAMES = [s.name for s in ALL_SETTINGS]  # Prefect parameters are JSON: names, not Settings


@task(name="train-setting", task_run_name="train {setting}")
def train_task(
    setting: Setting,
    ws: Workspace,
    embedding: int,
    layers: int,
    max_epochs: int,
    max_minutes: float | None,
    skip_unchanged: bool = False,
) -> dict:
    """Train and publish one setting; returns its best validation perplexity and checkpoint."""
    logger = get_run_logger()
    path = train_setting(
        ws.connect,
        ws.checkpoints,
        setting,
        LMConfig(0, embedding, layers),
        TrainConfig(max_epochs=max_epochs, max_minutes=max_minutes),
        on_epoch=lambda row: logger.info(
            "%s epoch %d: val ppl %.1f, %.0f tokens/s", setting, row["epoch"], row["val_ppl"], row["tokens_per_s"]
        ),
        skip_unchanged=skip_unchanged,
    )
    with ws.connect() as con:
        best = con.execute("select best_val_ppl from lm_runs where checkpoint = ?", [str(path)]).fetchone()[0]
    return {"setting": setting.name, "best_val_ppl": round(best, 2), "checkpoint": str(path)}


@flow(name="train")
def train_flow(
    settings: list[str] = SETTING_NAMES,  # noqa: B006 - Prefect parameters must be JSON
    embedding: int = LMConfig.embedding,
    layers: int = LMConfig.layers,
    max_epochs: int = TrainConfig.max_epochs,
    max_minutes: float | None = TrainConfig.max_minutes,
    skip_unchanged: bool = False,
    db: str | None = None,
    data_dir: str | None = None,
) -> list[dict]:
    """Train the requested settings (default: both linearisations x youcook2/recipes/all; any spelling
    `Setting.parse` reads); with `skip_unchanged`, a setting whose latest checkpoint matches the corpus and
    configuration is kept."""
    chosen = [Setting.parse(s) for s in settings]  # an unknown one fails here, before anything trains
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    results = [train_task(s, ws, embedding, layers, max_epochs, max_minutes, skip_unchanged) for s in chosen]
    create_table_artifact(key="lm-checkpoints", table=results, description="Published language models")
    return results
