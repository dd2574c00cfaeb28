"""Speech flow: the recogniser's domain language model built from the ingested corpora and the lexicon,
published as a version (kept when its inputs are unchanged)."""

from __future__ import annotations

from prefect import flow, get_run_logger

from lmcr.lexicon import load_lexicon
from lmcr.speech.domain_lm import SpeechLMConfig, build_speech_lm
from lmcr.speech.recognize import cmudict_path
from lmcr.workspace import Workspace


@flow(name="speech-lm")
def speech_flow(config: SpeechLMConfig = SpeechLMConfig(), db: str | None = None, data_dir: str | None = None) -> str:
    """Build (or keep) the speech model; returns its version folder."""
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    with ws.read() as con:
        path = build_speech_lm(con, load_lexicon(), cmudict_path(), ws.speech, config,
                               log=get_run_logger().info)
    return str(path)
