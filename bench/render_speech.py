"""Render instructions as speech for the recogniser bench: espeak-ng voices x speaking rates, each clean,
with white noise at a chosen SNR, and at telephone bandwidth (sox: 8 kHz, 300-3400 Hz).

    python bench/render_speech.py --instructions ../shared/eval/instructions_dev.jsonl --out /tmp/speech

Writes OUT/<condition>/<id>.wav and OUT/index.jsonl, one line per WAV: {id, audio, text, voice, rate,
condition, expected, missing} (also a valid `lmcr listen --input` file). Needs espeak-ng and sox.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lmcr.jsonl import InputError, read_jsonl  # noqa: E402
from lmcr.speech.audio import read_wav, write_wav  # noqa: E402


def synthesize(text: str, voice: str, rate: int, out: Path) -> None:
    """espeak-ng speech, resampled to 16 kHz mono."""
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "raw.wav"
        subprocess.run(["espeak-ng", "-v", voice, "-s", str(rate), "-w", str(raw), text], check=True)
        write_wav(out, read_wav(raw))


def add_noise(clean: Path, out: Path, snr_db: float, seed: int) -> None:
    """White noise at `snr_db` below the speech's RMS (seeded, so the bench is reproducible)."""
    samples = read_wav(clean).astype(np.float64)
    speech = samples[np.abs(samples) > 0.02 * 32768]  # the RMS of the speech, not of the pauses
    rms = np.sqrt(np.mean(speech**2)) if len(speech) else 1.0
    noise = np.random.default_rng(seed).normal(0, rms / 10 ** (snr_db / 20), len(samples))
    write_wav(out, np.clip(np.round(samples + noise), -32768, 32767).astype(np.int16))


def telephone(clean: Path, out: Path) -> None:
    """Telephone channel: 300-3400 Hz band, 8 kHz sampling (the reader resamples it back to 16 kHz)."""
    subprocess.run(["sox", str(clean), "-r", "8000", str(out), "sinc", "300-3400"], check=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--instructions", type=Path, required=True, help="JSONL with id and instruction")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--voices", default="en-us,en-gb+f3", help="espeak-ng voices (comma-separated)")
    parser.add_argument("--rates", default="140,175", help="words per minute (comma-separated)")
    parser.add_argument("--snr", type=float, default=20.0, help="SNR of the noisy copies, dB")
    args = parser.parse_args()
    for tool in ("espeak-ng", "sox"):
        if shutil.which(tool) is None:
            sys.exit(f"render_speech: {tool} is not installed (apt-get install espeak-ng sox)")
    try:
        records = [rec for _, rec in read_jsonl(args.instructions, {"id": (str, int), "instruction": str})]
    except InputError as exc:
        sys.exit(f"render_speech: {exc}")
    index = []
    for voice in args.voices.split(","):
        for rate in (int(r) for r in args.rates.split(",")):
            tag = f"{voice.replace('+', '_')}-{rate}"
            for condition in ("clean", f"noise{args.snr:g}", "telephone"):
                (args.out / f"{tag}-{condition}").mkdir(parents=True, exist_ok=True)
            for n, rec in enumerate(records):
                clean = args.out / f"{tag}-clean" / f"{rec['id']}.wav"
                synthesize(rec["instruction"], voice, rate, clean)
                noisy = args.out / f"{tag}-noise{args.snr:g}" / f"{rec['id']}.wav"
                add_noise(clean, noisy, args.snr, seed=n)
                phone = args.out / f"{tag}-telephone" / f"{rec['id']}.wav"
                telephone(clean, phone)
                for condition, path in (("clean", clean), (f"noise{args.snr:g}", noisy), ("telephone", phone)):
                    index.append(
                        {
                            "id": f"{rec['id']}-{tag}-{condition}",
                            "audio": str(path.relative_to(args.out)),
                            "text": rec["instruction"],
                            "voice": voice,
                            "rate": rate,
                            "condition": condition,
                            "objects": rec.get("objects"),
                            "expected": rec.get("expected"),
                            "missing": rec.get("missing"),
                        }
                    )
            print(f"{tag}: {len(records)} instructions x 3 conditions", flush=True)
    (args.out / "index.jsonl").write_text("".join(json.dumps(r) + "\n" for r in index), encoding="utf-8")
    print(f"{len(index)} WAVs -> {args.out / 'index.jsonl'}")


if __name__ == "__main__":
    main()
