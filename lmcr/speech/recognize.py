"""Decoding: 16 kHz samples -> a transcript with its posterior, n-best alternatives and doubts.

pocketsphinx's en-US acoustic model with the published domain model (`domain_lm`). The recogniser
is unsure of a word when a close n-best alternative puts a different lexicon word (a predicate or an
object) in its place; `doubts` lists those, and the robot asks ("Did you say pour or fill?").
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lmcr.errors import LMCRError
from lmcr.lexicon import Lexicon
from lmcr.speech.audio import RATE, SILENCE_DBFS, level_dbfs
from lmcr.speech.domain_lm import FILES, lexicon_words
from lmcr.versions import CheckpointError, resolve, verify

NBEST = 8
# An alternative whose scaled path score is within this (natural log) of the best one counts as close.
# Picked by looking at a few rendered dev utterances, whose first n-best paths lay 0.02-0.07 apart; not
# tuned on the bench.
CLOSE_LOG_SCORE = 0.05


class SpeechModelError(LMCRError, RuntimeError):
    """No usable speech model (not built, or not loadable)."""


@dataclass(frozen=True)
class Transcript:
    """What was heard: the best text, its posterior probability, the other n-best texts, the lexicon
    words close alternatives disagree on, and why it is empty when it is."""

    text: str
    alternatives: list[str] = field(default_factory=list)  # the other n-best texts, best first
    confidence: float = 0.0  # the best hypothesis' posterior probability
    reason: str | None = None  # set when nothing was recognised
    doubts: list[list[str]] = field(default_factory=list)  # lexicon words the alternatives disagree on

    def to_json(self) -> dict:
        return {
            "text": self.text,
            "confidence": round(self.confidence, 4),
            "alternatives": self.alternatives,
            "doubts": self.doubts,
            **({"reason": self.reason} if self.reason else {}),
        }


def acoustic_model_dir() -> Path:
    """The en-US acoustic model shipped with the pocketsphinx wheel."""
    from pocketsphinx import get_model_path

    base = Path(get_model_path()) / "en-us"
    return base / "en-us" if (base / "en-us").is_dir() else base


def cmudict_path() -> Path:
    """The pronouncing dictionary shipped with the pocketsphinx wheel."""
    from pocketsphinx import get_model_path

    return Path(get_model_path()) / "en-us" / "cmudict-en-us.dict"


class Recognizer:
    """One loaded decoder; `transcribe` may be called for many utterances."""

    def __init__(self, model: Path, lexicon: Lexicon, lw: float = 6.5):
        try:
            self.path = resolve(Path(model))
            verify(self.path, FILES)
        except CheckpointError as exc:
            raise SpeechModelError(f"{exc} (build it with `lmcr speech-lm`)") from exc
        from pocketsphinx import Decoder

        self.decoder = Decoder(
            hmm=str(acoustic_model_dir()),
            lm=str(self.path / "domain.lm"),
            dict=str(self.path / "domain.dict"),
            samprate=RATE,
            bestpath=True,
            lw=lw,
            dither=True,
            cmn="batch",
            loglevel="FATAL",
            logfn=os.devnull,
        )
        self.key_words = lexicon_words(lexicon)

    def transcribe(self, samples: np.ndarray) -> Transcript:
        """Decode one utterance (int16, 16 kHz)."""
        silent = silence(samples)
        if silent is not None:
            return silent
        d = self.decoder
        d.start_utt()
        d.process_raw(samples.tobytes(), full_utt=True)
        d.end_utt()
        hyp = d.hyp()
        if hyp is None or not hyp.hypstr.strip():
            return no_words(samples)
        best_score = None
        alternatives, close = [], []
        for _, alt in zip(range(NBEST), d.nbest()):
            if alt is None:
                break
            best_score = alt.score if best_score is None else best_score
            text = " ".join(alt.hypstr.split())
            if text and text != hyp.hypstr and text not in alternatives:
                alternatives.append(text)
                if _close(best_score, alt.score):
                    close.append(text)
        return Transcript(hyp.hypstr, alternatives, float(hyp.prob), doubts=doubts(hyp.hypstr, close, self.key_words))


def silence(samples: np.ndarray) -> Transcript | None:
    """The empty transcript, with its reason, of audio too quiet to hold speech; None otherwise."""
    level = level_dbfs(samples)
    return Transcript("", reason=f"no speech: the audio is silent ({level:.0f} dBFS)") if level < SILENCE_DBFS else None


def no_words(samples: np.ndarray) -> Transcript:
    """The empty transcript, with its reason, of audio in which the recogniser heard no words."""
    return Transcript("", reason=f"no words recognised ({level_dbfs(samples):.0f} dBFS)")


def doubts(best: str, close: list[str], key_words: set[str]) -> list[list[str]]:
    """Per position of a key word (predicate or object) in the best text: that word and the other key
    words close alternatives hear there (aligned by the words around it); only places heard two ways."""
    best_words = best.split()
    found = []
    for i, word in enumerate(best_words):
        if word not in key_words:
            continue
        heard = [word]
        for alt in close:
            other = _aligned(best_words, alt.split(), i)
            if other and other not in heard and other in key_words:
                heard.append(other)
        if len(heard) > 1:
            found.append(heard)
    return found


def _close(best: float, score: float) -> bool:
    """Whether an n-best path score is close to the best one (the Python API reports path scores
    exponentiated, so their natural logs are the decoder's scaled log scores)."""
    return best > 0 and score > 0 and np.log(best) - np.log(score) <= CLOSE_LOG_SCORE


def _aligned(best: list[str], other: list[str], i: int) -> str | None:
    """The word of `other` at the place of `best[i]`: same left neighbour and same right neighbour
    (or the same offset when the lengths agree)."""
    if len(other) == len(best):
        return other[i]
    left = best[i - 1] if i > 0 else None
    right = best[i + 1] if i + 1 < len(best) else None
    for j in range(len(other)):
        if (other[j - 1] if j > 0 else None) == left and (other[j + 1] if j + 1 < len(other) else None) == right:
            return other[j]
    return None
