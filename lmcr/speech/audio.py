"""WAV input for the recogniser: 16-bit PCM, mono, any sample rate, resampled to the model's 16 kHz.

Bad audio is an `AudioError` naming the file and the reason (not a WAV, stereo, 8-bit, empty, too
long); audio without speech is not an error but yields an empty transcript with a reason.
"""

from __future__ import annotations

import struct
import wave
from math import gcd
from pathlib import Path

import numpy as np

from lmcr.errors import LMCRError, one_line

RATE = 16_000  # the en-US acoustic model's sample rate
MAX_SECONDS = 60.0  # an instruction is a sentence or two; a longer file is a mistake, not a command
MIN_SECONDS = 0.1
SILENCE_DBFS = -50.0  # RMS below this (dB relative to full scale) holds no speech


class AudioError(LMCRError, ValueError):
    """An audio file that cannot be decoded as an instruction."""


def read_wav(path: Path) -> np.ndarray:
    """The file's samples as int16 at 16 kHz."""
    path = Path(path)
    try:
        with wave.open(str(path), "rb") as wav:
            channels, width, rate, frames = wav.getnchannels(), wav.getsampwidth(), wav.getframerate(), wav.getnframes()
            if wav.getcomptype() != "NONE":
                raise AudioError(f"{path}: compressed WAV ({wav.getcompname()}); expected 16-bit PCM")
            raw = wav.readframes(frames)
    except OSError as exc:
        raise AudioError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    except (wave.Error, EOFError, RuntimeError, struct.error, ValueError) as exc:  # what `wave` raises on bad chunks
        raise AudioError(f"{path}: not a PCM WAV file ({one_line(exc, 80) or type(exc).__name__})") from exc
    if channels != 1:
        raise AudioError(f"{path}: {channels} channels; expected mono (e.g. `sox IN.wav -c 1 OUT.wav`)")
    if width != 2:
        raise AudioError(f"{path}: {8 * width}-bit samples; expected 16-bit PCM")
    seconds = frames / rate if rate else 0.0
    if seconds < MIN_SECONDS or len(raw) < 2 * frames:
        raise AudioError(f"{path}: empty or truncated audio ({seconds:.2f} s)")
    if seconds > MAX_SECONDS:
        raise AudioError(f"{path}: {seconds:.0f} s long; an instruction must be under {MAX_SECONDS:.0f} s")
    return resample(np.frombuffer(raw[: 2 * frames], dtype="<i2"), rate)


def resample(samples: np.ndarray, rate: int) -> np.ndarray:
    """int16 samples at `rate` -> int16 at 16 kHz (polyphase filter, so no aliasing from 44.1/48 kHz)."""
    if rate == RATE:
        return samples.astype(np.int16)
    from scipy.signal import resample_poly

    g = gcd(RATE, rate)
    out = resample_poly(samples.astype(np.float32), RATE // g, rate // g)
    return np.clip(np.round(out), -32768, 32767).astype(np.int16)


def level_dbfs(samples: np.ndarray) -> float:
    """RMS level in dB relative to full scale (-inf for digital silence)."""
    rms = float(np.sqrt(np.mean(samples.astype(np.float64) ** 2))) if len(samples) else 0.0
    return 20 * np.log10(rms / 32768) if rms > 0 else float("-inf")


def write_wav(path: Path, samples: np.ndarray, rate: int = RATE) -> None:
    """Write int16 mono samples (used by the test-audio renderer and tests)."""
    with wave.open(str(path), "wb") as wav:
        wav.setnchannels(1)
        wav.setsampwidth(2)
        wav.setframerate(rate)
        wav.writeframes(np.asarray(samples, dtype="<i2").tobytes())
