"""Train one setting end to end: text from the store, vocabulary, model, training, published checkpoint."""

from __future__ import annotations

import json
import random
import uuid
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import duckdb

import lmcr
from lmcr.checkout import git_commit
from lmcr.errors import LMCRError
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import TrainingText, corpus_hash, training_text
from lmcr.lm.hyperparams import MAX_VOCAB, MIN_FREQ, LMConfig, TrainConfig, WarmStartConfig
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
    max_vocab: int = MAX_VOCAB,
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
    provenance = {
        **text.provenance,
        "train_config": train_config.to_json(),
        "min_freq": min_freq,
        "max_vocab": max_vocab,
    }
    return _publish_run(
        open_store, checkpoints, setting, model, vocab, text, history, provenance, train_config.articles, promote
    )


@dataclass(frozen=True)
class WarmStart:
    """A warm start's outcome: the published candidate, or no path and why the setting needs a full run."""

    path: Path | None
    vocab_change: float
    reason: str


def continue_setting(
    open_store: Callable[[], duckdb.DuckDBPyConnection],
    checkpoints: Path,
    setting: Setting,
    new_sources: list[str],
    config: WarmStartConfig = WarmStartConfig(),
    on_epoch: Callable[[dict], None] | None = None,
) -> WarmStart:
    """Continue the setting's LATEST checkpoint on the sequences of `new_sources` (ingested source files)
    mixed with a replay of the old ones, keeping its vocabulary; publish the result unpromoted. Refused
    (no path) when the vocabulary rebuilt from the whole corpus would change too much, or when the new
    files add no training sequence."""
    base = ckpt.load(checkpoints / setting.name)
    train_config = TrainConfig(**base.provenance["train_config"])
    min_freq = base.provenance.get("min_freq", MIN_FREQ)
    max_vocab = base.provenance.get("max_vocab", MAX_VOCAB)
    with open_store() as con:
        text = training_text(con, setting, articles=base.articles)
        new_docs = documents_of(con, new_sources)
    rebuilt = Vocab.build(text.train, min_freq=min_freq, max_size=max_vocab)
    change = vocab_change(base.vocab, rebuilt)
    if change > config.max_vocab_change:
        return WarmStart(None, change, f"the vocabulary would change by {change:.1%} (> {config.max_vocab_change:.0%})")
    new = [seq for seq, doc in zip(text.train, text.train_docs) if doc in new_docs]
    if not new:
        return WarmStart(None, change, "the new files add no training sequence")
    old = [seq for seq, doc in zip(text.train, text.train_docs) if doc not in new_docs]
    replayed = random.Random(config.seed).sample(old, min(len(old), round(config.replay * len(new))))
    steps = replace(
        train_config,
        max_epochs=config.epochs,
        lr=config.lr,
        decay_epochs=config.decay_epochs,
        seed=config.seed,
        max_minutes=None,
        patience=config.epochs,
    )
    model = base.model
    history = train_lm(
        model, [base.vocab.encode(s) for s in new + replayed], [base.vocab.encode(s) for s in text.val], steps, on_epoch
    )
    provenance = {
        **text.provenance,
        "train_config": train_config.to_json(),  # the recipe of the weights it continues
        "min_freq": min_freq,
        "max_vocab": max_vocab,
        "warm_start": {
            "from": base.path.name,
            "new_sequences": len(new),
            "replayed": len(replayed),
            "vocab_change": change,
            **config.to_json(),
        },
    }
    path = _publish_run(
        open_store, checkpoints, setting, model, base.vocab, text, history, provenance, base.articles, promote=False
    )
    reason = f"continued {base.path.name} on {len(new):,} new and {len(replayed):,} old sequences"
    return WarmStart(path, change, reason)


def documents_of(con: duckdb.DuckDBPyConnection, source_files: list[str]) -> set[str]:
    """The document ids loaded from these source files."""
    rows = con.execute("select distinct doc_id from documents where list_contains(?, source_file)", [source_files])
    return {doc for (doc,) in rows.fetchall()}


def vocab_change(old: Vocab, new: Vocab) -> float:
    """Share of `old`'s words that `new` drops or adds (the symmetric difference over `old`'s size)."""
    return len(set(old.words) ^ set(new.words)) / max(1, len(old.words))


def _publish_run(
    open_store: Callable[[], duckdb.DuckDBPyConnection],
    checkpoints: Path,
    setting: Setting,
    model: RecurrentLM,
    vocab: Vocab,
    text: TrainingText,
    history: list[dict],
    provenance: dict,
    articles: bool,
    promote: bool,
) -> Path:
    """Publish a trained model with its metrics and provenance (`articles`: whether its text kept a/an/the),
    record the run, promote when asked."""
    run_id = uuid.uuid4().hex[:12]
    metrics = {
        "best_val_ppl": min(row["val_ppl"] for row in history),
        "history": history,
        "train_sequences": len(text.train),
        "val_sequences": len(text.val),
        "tokens_trained": tokens_trained(history),
    }
    provenance = {
        **provenance,
        "code_version": code_version(),
        "run_id": run_id,
        "model_config": replace(model.config, vocab_size=0).to_json(),
    }
    # Publish unpromoted, record the run, then promote: LATEST never names a version without its
    # lm_runs row, whatever fails or is killed in between.
    path = ckpt.publish(checkpoints, setting, model.cpu(), vocab, metrics, provenance, promote=False, articles=articles)
    with open_store() as con:
        record_run(con, run_id, text, len(vocab), history, path)
    if promote:
        ckpt.set_latest(checkpoints, setting, path.name)
    return path


def tokens_trained(history: list[dict]) -> int:
    """Tokens the training steps went through, over every epoch of a run's history."""
    return int(sum(row["tokens_per_s"] * row["seconds"] for row in history))


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
