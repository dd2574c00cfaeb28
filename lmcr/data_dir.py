"""Where an installation's data folder is: the one rule `Workspace.from_env` and the light modules that
cannot import it (the lexicon, which the workspace imports) share."""

from __future__ import annotations

import os
from pathlib import Path

SRL_SUBDIR = "srl"  # the learned SRL resources the frame build writes
PREDICATES_FILE = "predicates.json"  # among them, the predicates learned from the corpus (`lmcr.lexicon`)


def data_dir_from_env(explicit: str | Path | None = None) -> Path:
    """An explicit folder, else `$LMCR_DATA_DIR`, else `data/` beside the current directory."""
    return Path(explicit or os.environ.get("LMCR_DATA_DIR") or "data")
