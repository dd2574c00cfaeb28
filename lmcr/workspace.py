"""One LMCR installation: where it reads and writes, and what every command and flow builds from it.

`Workspace.from_env()` is the one place the environment is read (`LMCR_DATA_DIR`, `LMCR_DB`,
`LMCR_SQL_DIR`, `LMCR_SPACY_MODEL`, `LMCR_VECTORS`, `LMCR_CONCEPTNET`, `LMCR_PAPER`, `LMCR_BAXTER_URDF`,
`LMCR_ASR`, `LMCR_WHISPER_MODEL`); explicit
arguments win over it. The CLI builds one per command and each flow one per run, then asks it for a
folder, a store connection, the scorers' resources, the parser or a scorer.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from lmcr.checkout import SQL_DIR
from lmcr.data_dir import PREDICATES_FILE, SRL_SUBDIR, data_dir_from_env
from lmcr.srl.spacy_model import SPACY_MODEL, spacy_model_from_env

if TYPE_CHECKING:  # the scorers, the parser and DuckDB are imported when first used (CLI start-up)
    import duckdb

    from lmcr.complete import CompletionConfig
    from lmcr.scorers.registry import Scorer
    from lmcr.scorers.resources import MethodResources
    from lmcr.speech.recognize import Recognizer
    from lmcr.speech.whisper import WhisperRecognizer
    from lmcr.srl.parser import FrameParser


def _env_path(name: str) -> Path | None:
    return Path(os.environ[name]) if os.environ.get(name) else None


@dataclass(frozen=True)
class Workspace:
    """The folders, store and shared inputs of one installation (picklable: flows hand it to tasks)."""

    data_dir: Path
    db: Path
    sql_dir: Path
    spacy_model: str = SPACY_MODEL
    vectors: Path | None = None  # word vectors for the w2v baseline (else trained on the corpus)
    conceptnet: Path | None = None  # ConceptNet edges or Numberbatch for the conceptnet baseline
    paper: Path | None = None  # the paper's LaTeX source: its Table I beside ours in the report
    baxter_urdf: Path | None = None  # the official Baxter description (else the built-in one)
    asr: str = "whisper"  # the speech recogniser: whisper (default) or sphinx (pocketsphinx + domain LM)
    whisper_model: Path | None = None  # a CTranslate2 Whisper folder (else the packaged Whisper base)

    @classmethod
    def from_env(cls, data_dir: str | Path | None = None, db: str | Path | None = None) -> Workspace:
        """Explicit arguments win, then the environment, then `data/` beside the current directory."""
        data = data_dir_from_env(data_dir)
        return cls(
            data_dir=data,
            db=Path(db or os.environ.get("LMCR_DB") or data / "lmcr.duckdb"),
            sql_dir=Path(os.environ.get("LMCR_SQL_DIR") or SQL_DIR),
            spacy_model=spacy_model_from_env(),
            vectors=_env_path("LMCR_VECTORS"),
            conceptnet=_env_path("LMCR_CONCEPTNET"),
            paper=_env_path("LMCR_PAPER"),
            baxter_urdf=_env_path("LMCR_BAXTER_URDF"),
            asr=os.environ.get("LMCR_ASR") or "whisper",
            whisper_model=_env_path("LMCR_WHISPER_MODEL"),
        )

    @property
    def srl_dir(self) -> Path:
        """Learned SRL resources (compounds, role priors) built by the frames stage."""
        return self.data_dir / SRL_SUBDIR

    @property
    def checkpoints(self) -> Path:
        """Published language-model checkpoints, one folder per setting (`frame-all`, ...)."""
        return self.data_dir / "checkpoints"

    @property
    def staging(self) -> Path:
        """Parquet written by parallel workers before the single writer loads it into DuckDB."""
        return self.data_dir / "staging"

    @property
    def calibration(self) -> Path:
        """Completion settings calibrated by `lmcr evaluate`, one file per scorer fingerprint."""
        return self.data_dir / "calibration"

    @property
    def report(self) -> Path:
        """The evaluation report (Table I, Fig. 4) written by the pipeline."""
        return self.data_dir / "report"

    @property
    def robot(self) -> Path:
        """Executor logs and renders."""
        return self.data_dir / "robot"

    @property
    def speech(self) -> Path:
        """The recogniser's domain language model, versioned (`lmcr speech-lm`)."""
        return self.data_dir / "speech" / "en-us"

    @property
    def whisper(self) -> Path:
        """Where the packaged Whisper base model is joined (`speech.whisper.packaged_model`)."""
        return self.data_dir / "speech" / "whisper-base"

    @property
    def baselines(self) -> Path:
        """Baseline caches (word2vec trained on the corpus)."""
        return self.data_dir / "baselines"

    def connect(self) -> duckdb.DuckDBPyConnection:
        """The store, migrated, open for writing (a connection closes at the end of a `with` block)."""
        from lmcr.store import connect

        return connect(self.db, self.sql_dir)

    def read(self) -> duckdb.DuckDBPyConnection:
        """A read-only connection to the store."""
        from lmcr.store import read_connection

        return read_connection(self.db)

    def resources(
        self,
        checkpoint: Path | None = None,
        corpus: str = "all",
        vectors: str | Path | None = None,
        conceptnet: str | Path | None = None,
        seed: int = 0,
    ) -> MethodResources:
        """What the scorers are built from; explicit values win over the workspace's."""
        from lmcr.scorers.context_pmi import WEIGHT
        from lmcr.scorers.mixture import load_choice
        from lmcr.scorers.resources import MethodResources

        mixture, context_weight = load_choice(self.data_dir)  # chosen together, saved in one file
        return MethodResources(
            checkpoints=Path(checkpoint) if checkpoint else self.checkpoints,
            corpus=corpus,
            db=self.db,
            sql_dir=self.sql_dir,
            vectors=Path(vectors) if vectors else self.vectors,
            conceptnet=Path(conceptnet) if conceptnet else self.conceptnet,
            spacy_model=self.spacy_model,
            cache_dir=self.baselines,
            seed=seed,
            mixture=mixture,
            context_weight=context_weight or WEIGHT,
            predicates=self.srl_dir / PREDICATES_FILE,
        )

    def parser(self, model: str | None = None, resources: Path | None = None) -> FrameParser:
        """The SRL parser with this workspace's learned compounds and role priors."""
        from lmcr.srl.parser import load_parser

        return load_parser(model or self.spacy_model, resources or self.srl_dir)

    def scorer(self, method: str, res: MethodResources | None = None) -> Scorer:
        """The scorer of `method` ('a+b' sums two) built from `res` (default: this workspace's)."""
        from lmcr.scorers.registry import make_scorer

        return make_scorer(method, res or self.resources())

    def completion_scorer(self, method: str, res: MethodResources | None = None) -> tuple[Scorer, CompletionConfig]:
        """The scorer of `method` with the completion settings calibrated for it (else the defaults)."""
        from lmcr.complete import completion_scorer

        return completion_scorer(method, res or self.resources(), self.calibration)

    def recognizer(self, model: Path | None = None, asr: str | None = None) -> Recognizer | WhisperRecognizer:
        """The speech recogniser `asr` (else the workspace's): Whisper (the packaged base model, or
        `LMCR_WHISPER_MODEL`), or pocketsphinx with the published domain model (`lmcr speech-lm`) or `model`."""
        from lmcr.lexicon import load_lexicon
        from lmcr.speech.recognize import Recognizer, SpeechModelError

        asr = asr or self.asr
        if asr == "sphinx":
            return Recognizer(model or self.speech, load_lexicon())
        if asr != "whisper":
            raise SpeechModelError(f"unknown speech recogniser {asr!r} (LMCR_ASR / --asr): whisper or sphinx")
        from lmcr.speech.whisper import WhisperRecognizer, packaged_model

        return WhisperRecognizer(self.whisper_model or packaged_model(self.whisper), load_lexicon())
