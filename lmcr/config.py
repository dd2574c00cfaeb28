"""Where LMCR reads and writes: every path comes from the environment or the caller, never hard-coded data."""

from __future__ import annotations

import os
import subprocess
from dataclasses import dataclass
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Paths:
    """The working locations of one LMCR installation."""

    data_dir: Path
    db: Path
    sql_dir: Path

    @property
    def srl_dir(self) -> Path:
        """Learned SRL resources (compounds, role priors) built by the frames stage."""
        return self.data_dir / "srl"

    @property
    def checkpoints(self) -> Path:
        """Published language-model checkpoints, one folder per setting (`frame-all`, ...)."""
        return self.data_dir / "checkpoints"

    @property
    def staging(self) -> Path:
        """Parquet written by parallel workers before the single writer loads it into DuckDB."""
        return self.data_dir / "staging"


def paths_from_env(data_dir: str | Path | None = None, db: str | Path | None = None) -> Paths:
    """Resolve paths: explicit arguments win, then `LMCR_DATA_DIR` / `LMCR_DB` / `LMCR_SQL_DIR`, then defaults."""
    data = Path(data_dir or os.environ.get("LMCR_DATA_DIR") or "data")
    database = Path(db or os.environ.get("LMCR_DB") or data / "lmcr.duckdb")
    sql_dir = Path(os.environ.get("LMCR_SQL_DIR") or REPO_ROOT / "sql")
    return Paths(data_dir=data, db=database, sql_dir=sql_dir)


def paper_from_env() -> Path | None:
    """The paper's LaTeX source for the report's published Table I: `$LMCR_PAPER`, else none."""
    return Path(os.environ["LMCR_PAPER"]) if os.environ.get("LMCR_PAPER") else None


def git_commit(root: Path = REPO_ROOT) -> str | None:
    """The checked-out commit (with '+changes' when tracked files differ), or None outside a git checkout
    or without git."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return head.stdout.strip() + ("+changes" if dirty else "")
    except (OSError, subprocess.TimeoutExpired):
        return None
