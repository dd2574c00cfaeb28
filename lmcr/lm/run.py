"""Train one setting end to end: text from the store, vocabulary, model, training, published checkpoint."""

from __future__ import annotations

import json
import uuid
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import duckdb

import lmcr
from lmcr.checkout import git_commit
from lmcr.errors import LMCRError
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import TrainingText, corpus_hash, training_text
from lmcr.lm.hyperparams import MIN_FREQ, LMConfig, TrainConfig
from lmcr.lm.model import RecurrentLM
from lmcr.lm.train import train_lm
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting
from lmcr.store import insert_rows, transaction


class TrainingTextError(LMCRError, ValueError):
    """A setting with no text to train on in the store (nothing ingested or framed for its corpus)."""


def code_version() -> str:
    """Package version and, in a git checkout, the commit."""
    commit = git_commit()
    return f"{lmcr.__version__}+{commit[:12]}" if commit else lmcr.__version__


def train_setting(
    open_store: Callable[[], duckdb.DuckDBPyConnection],
    checkpoints: Path,
    setting: Setting,
    model_config: LMConfig | None = None,
    train_config: TrainConfig = TrainConfig(),
    min_freq: int = MIN_FREQ,
    max_vocab: int = 30_000,
    on_epoch: Callable[[dict], None] | None = None,
    promote: bool = True,
    skip_unchanged: bool = False,
) -> Path:
    """Train the setting's linearisation on its corpus, publish the checkpoint (as the setting's latest when `promote`),
    record metrics. With `skip_unchanged`, the setting's latest checkpoint is returned as it is when it
    was trained on the same corpus content with the same configuration.

    The store is opened (`open_store`) only to read the text and, afterwards, to record the run: DuckDB
    admits one writing process, and training takes long enough that holding it would lock users out.
    """
    with open_store() as con:
        if skip_unchanged:
            current = up_to_date(
                checkpoints / setting.name,
                corpus_hash(con, setting.linearization),
                model_config or LMConfig(0),
                train_config,
                min_freq,
            )
            if current is not None:
                return current
        text = training_text(con, setting, articles=train_config.articles)
    if not text.train or not text.val:
        raise TrainingTextError(
            f"no {setting.linearization} training text for corpus {setting.corpus!r}: run ingest and frames first"
        )
    vocab = Vocab.build(text.train, min_freq=min_freq, max_size=max_vocab)
    model = RecurrentLM(replace(model_config or LMConfig(0), vocab_size=len(vocab)))
    history = train_lm(
        model, [vocab.encode(s) for s in text.train], [vocab.encode(s) for s in text.val], train_config, on_epoch
    )
    run_id = uuid.uuid4().hex[:12]
    best = min(row["val_ppl"] for row in history)
    metrics = {
        "best_val_ppl": best,
        "history": history,
        "train_sequences": len(text.train),
        "val_sequences": len(text.val),
    }
    provenance = {
        **text.provenance,
        "code_version": code_version(),
        "train_config": train_config.to_json(),
        "min_freq": min_freq,
        "run_id": run_id,
    }
    # Publish unpromoted, record the run, then promote: LATEST never names a version without its
    # lm_runs row, whatever fails or is killed in between.
    path = ckpt.publish(
        checkpoints,
        setting,
        model.cpu(),
        vocab,
        metrics,
        {**provenance, "model_config": replace(model.config, vocab_size=0).to_json()},
        promote=False,
        articles=train_config.articles,
    )
    with open_store() as con:
        record_run(con, run_id, text, len(vocab), history, path)
    if promote:
        ckpt.set_latest(checkpoints, setting, path.name)
    return path


def up_to_date(
    setting_dir: Path, corpus_sha256: str, model_config: LMConfig, train_config: TrainConfig, min_freq: int
) -> Path | None:
    """The setting's latest checkpoint if it came from this corpus content and configuration."""
    if not (setting_dir / "LATEST").exists():
        return None
    path = ckpt.resolve(setting_dir)
    prov = json.loads((path / "provenance.json").read_text(encoding="utf-8"))
    same = (
        prov.get("corpus_sha256") == corpus_sha256
        and prov.get("train_config") == train_config.to_json()
        and prov.get("model_config") == replace(model_config, vocab_size=0).to_json()
        and prov.get("min_freq") == min_freq
    )
    return path if same else None


def record_run(
    con: duckdb.DuckDBPyConnection, run_id: str, text: TrainingText, vocab_size: int, history: list[dict], path: Path
) -> None:
    """One lm_runs row and its lm_epochs rows, in one transaction."""
    with transaction(con):
        insert_rows(
            con,
            "lm_runs",
            [
                {
                    "run_id": run_id,
                    "linearization": text.provenance["linearization"],
                    "corpus": text.provenance["corpus"],
                    "train_sequences": len(text.train),
                    "val_sequences": len(text.val),
                    "vocab_size": vocab_size,
                    "best_val_ppl": min(r["val_ppl"] for r in history),
                    "checkpoint": str(path),
                }
            ],
        )
        insert_rows(con, "lm_epochs", [{"run_id": run_id, **r} for r in history])
