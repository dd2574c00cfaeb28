"""Speech flow: pocketsphinx's domain language model built from the ingested corpora and the lexicon,
published as a version (kept when its inputs are unchanged), and the packaged Whisper model joined into
the workspace (once), so that the first spoken instruction does not wait for either."""

from __future__ import annotations

from prefect import flow, get_run_logger

from lmcr.lexicon import load_lexicon
from lmcr.speech.domain_lm import SpeechLMConfig, build_speech_lm
from lmcr.speech.recognize import cmudict_path
from lmcr.speech.whisper import packaged_model
from lmcr.workspace import Workspace


@flow(name="speech-lm")
def speech_flow(config: SpeechLMConfig = SpeechLMConfig(), db: str | None = None, data_dir: str | None = None) -> str:
    """Build (or keep) the speech models; returns the domain model's version folder."""
    ws = Workspace.from_env(data_dir=data_dir, db=db)
    with ws.read() as con:
        path = build_speech_lm(con, load_lexicon(), cmudict_path(), ws.speech, config, log=get_run_logger().info)
    if ws.whisper_model is None:
        get_run_logger().info(f"Whisper model: {packaged_model(ws.whisper)}")
    return str(path)
