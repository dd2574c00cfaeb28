"""Speech bench: word error rate and frame accuracy per voice, rate and noise, and decoding speed.

    python bench/render_speech.py --instructions ../shared/eval/instructions_dev.jsonl --out /tmp/speech
    lmcr --data-dir DATA speech-lm                                 # for --asr sphinx
    # LMCR_DATA_DIR=DATA:
    python bench/bench_speech.py --index /tmp/speech/index.jsonl [--asr whisper|sphinx] [--json PATH]

Frame accuracy: the first robot frame of a reading has the right predicate, every stated role right
and the missing role empty (as `lmcr srl-eval --instructions`). `best`: the recogniser's best text;
`listen`: the reading `lmcr listen` takes without a scene (the first of the n-best texts naming only
objects the robot knows, else the first with a robot predicate); `frame`: the reading
`lmcr execute --audio` takes with the scene's objects known (the first naming only objects on the
table); `text`: the written instruction, the ceiling with this parser.
Decoding runs on one core.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
os.environ.setdefault("OMP_NUM_THREADS", "1")

from record import add_json_option, write_results  # noqa: E402

from lmcr.lexicon import load_lexicon  # noqa: E402
from lmcr.speech.audio import RATE, read_wav  # noqa: E402
from lmcr.speech.domain_lm import tokenize  # noqa: E402
from lmcr.speech.listen import understood_reading  # noqa: E402
from lmcr.speech.recognize import Recognizer  # noqa: E402
from lmcr.srl.evaluate import instruction_correct  # noqa: E402
from lmcr.srl.instruction import NoPredicateError, parse_instruction  # noqa: E402
from lmcr.workspace import Workspace  # noqa: E402


def word_errors(ref: list[str], hyp: list[str]) -> int:
    """Levenshtein distance over words (substitutions + deletions + insertions)."""
    row = list(range(len(hyp) + 1))
    for i, r in enumerate(ref, 1):
        prev, row[0] = row[0], i
        for j, h in enumerate(hyp, 1):
            prev, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, prev + (r != h))
    return row[-1]


def first_frame(parser, text: str) -> dict | None:
    try:
        return parse_instruction(parser, text).to_json() if text else None
    except NoPredicateError:
        return None


def main() -> None:
    args_parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args_parser.add_argument("--index", type=Path, required=True, help="index.jsonl of render_speech.py")
    args_parser.add_argument("--model", type=Path, help="speech model (default: the workspace's)")
    args_parser.add_argument(
        "--lw", type=float, default=None, help="sphinx: language weight (default: the recogniser's)"
    )
    args_parser.add_argument(
        "--asr", choices=("whisper", "sphinx"), default=None, help="recogniser (default: LMCR_ASR or whisper)"
    )
    add_json_option(args_parser, "bench_speech")
    args = args_parser.parse_args()
    ws = Workspace.from_env()
    lexicon = load_lexicon()
    asr = args.asr or ws.asr
    recognizer = (
        Recognizer(args.model or ws.speech, lexicon, **({"lw": args.lw} if args.lw else {}))
        if asr == "sphinx"
        else ws.recognizer(asr=asr)
    )
    parser = ws.parser()
    rows = [json.loads(line) for line in args.index.read_text(encoding="utf-8").splitlines() if line.strip()]
    groups: dict[tuple, dict] = defaultdict(lambda: defaultdict(float))
    speed = []
    for row in rows:
        samples = read_wav(args.index.parent / row["audio"])
        started = time.perf_counter()
        heard = recognizer.transcribe(samples)
        reading = understood_reading(parser, heard, row.get("objects")) if heard.text else ""
        listened = understood_reading(parser, heard) if heard.text else ""  # `lmcr listen`: no scene
        speed.append((time.perf_counter() - started, len(samples) / RATE))
        ref = tokenize(row["text"])
        for key in ((row["voice"], row["rate"], row["condition"]), ("all", "", "")):
            g = groups[key]
            g["n"] += 1
            g["errors"] += word_errors(ref, tokenize(heard.text))
            g["words"] += len(ref)
            g["best"] += instruction_correct(first_frame(parser, heard.text), row["expected"], row["missing"])
            g["listen"] += instruction_correct(first_frame(parser, listened), row["expected"], row["missing"])
            g["frame"] += instruction_correct(first_frame(parser, reading), row["expected"], row["missing"])
            g["text"] += instruction_correct(first_frame(parser, row["text"]), row["expected"], row["missing"])
            g["asked"] += bool(heard.doubts)
    print(
        f"{'voice':<12} {'rate':>4} {'condition':<10} {'n':>4} {'WER':>6} {'best':>6} {'listen':>6} "
        f"{'frame':>6} {'text':>6} {'asks':>5}"
    )
    figures = {"recogniser": asr, "utterances": len(rows)}
    for (voice, rate, condition), g in sorted(groups.items(), key=lambda kv: (kv[0][0] == "all", str(kv[0]))):
        print(
            f"{voice:<12} {rate!s:>4} {condition:<10} {int(g['n']):>4} {g['errors'] / g['words']:>6.3f} "
            f"{g['best'] / g['n']:>6.3f} {g['listen'] / g['n']:>6.3f} {g['frame'] / g['n']:>6.3f} "
            f"{g['text'] / g['n']:>6.3f} {g['asked'] / g['n']:>5.2f}"
        )
        group = " ".join(str(part) for part in (voice, rate, condition) if part)
        figures |= {
            f"{group}: WER": round(g["errors"] / g["words"], 3),
            f"{group}: right frame, scene known": round(g["frame"] / g["n"], 3),
            f"{group}: right frame, no scene": round(g["listen"] / g["n"], 3),
            f"{group}: right frame, written text": round(g["text"] / g["n"], 3),
        }
    three = [t for t, s in speed if 2.5 <= s <= 3.5] or [t for t, _ in speed]
    print(
        f"decoding ({asr}, one core): median {statistics.median(t for t, _ in speed):.2f} s per utterance "
        f"(median {statistics.median(s for _, s in speed):.1f} s of audio); {statistics.median(three):.2f} s for "
        f"the {len(three)} utterances of 2.5-3.5 s (target 0.5); {sum(s for _, s in speed):.0f} s of audio in all"
    )
    figures |= {
        "decoding one core, median s per utterance": round(statistics.median(t for t, _ in speed), 2),
        "decoding one core, median s per 2.5-3.5 s utterance": round(statistics.median(three), 2),
    }
    write_results(args.json, "bench_speech", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
