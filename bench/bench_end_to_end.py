"""Benchmark: instructions end to end through batch `lmcr execute`: completed right and executed.

Usage: python bench/bench_end_to_end.py --instructions instructions_dev.jsonl [--seed 0] [--work DIR]
       [--method M] [--urdf PATH] [--distractors N] [--json PATH]
Each instruction (`{id, instruction, objects, expected, missing}`) gets a seeded random scene of its
objects (with `--distractors`, N more objects drawn at random from the lexicon: a crowded table, and
candidates the instruction's author did not weigh); a stated object that is not among them is the one in
the robot's hand (`"holding"`). One
`lmcr execute --input IN.jsonl --output OUT.jsonl` process (the published checkpoint and store of
$LMCR_DATA_DIR) runs them all. Prints: completed right (the frame is the expected one), executed
successfully, both, executed plans that failed, refused before moving, errors; per predicate; then
every instruction that is not both right and successful, with why. `--repeat N` gives each instruction
N scenes (ids `<id>#<k>`): a larger batch of the same requests.

Time: the batch's wall clock, and each instruction's time, read as the interval between its result line
and the one before (the batch writes each line to its sidecar when its instruction is done; polled every
0.2 s, so each is within about 0.2 s), the first one including the process's start and loading.
"""

from __future__ import annotations

import argparse
import collections
import json
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from record import add_json_option, write_results

from lmcr.jsonl import read_jsonl
from lmcr.lexicon import load_lexicon
from lmcr.partial import SIDECAR

SLOW = 30.0  # seconds: the bar no instruction may pass (issue 50)
FIELDS = {"id": str, "instruction": str, "objects": list, "expected": dict}


def batch_line(record: dict, seed: int, distractors: int = 0) -> dict:
    """The batch input line: the instruction and a scene of its objects (and `distractors` random other
    ones) placed at random (seeded per instruction), with a stated object that is not among them in the hand."""
    stated = [v for role, v in record["expected"]["roles"].items() if role != record.get("missing")]
    held = [label for label in stated if label not in record["objects"]]
    others = sorted(set(load_lexicon().objects) - set(record["objects"]) - set(stated))
    labels = record["objects"] + random.Random(f"{seed}:distractors").sample(others, distractors)
    scene = {"objects": [{"label": label} for label in labels], "seed": seed}
    if held:
        scene["holding"] = held[0]
    return {"id": record["id"], "instruction": record["instruction"], "scene": scene}


def timed_batch(command: list[str], output: Path) -> tuple[float, list[float]]:
    """Run the batch; its wall seconds and each result line's interval since the one before."""
    started = time.perf_counter()
    process = subprocess.Popen(command)
    sidecar = output.with_name(output.name + SIDECAR)  # where the lines go as they are done (lmcr.partial)
    stamps: list[float] = []
    try:
        while True:
            done = process.poll() is not None
            written = output if done else sidecar
            lines = written.read_bytes().count(b"\n") if written.exists() else 0
            stamps += [time.perf_counter()] * (lines - len(stamps))
            if done:
                break
            time.sleep(0.2)
    finally:  # interrupted or failed while polling: the batch ends with the benchmark
        if process.poll() is None:
            process.terminate()
            process.wait()
    if process.returncode:
        raise subprocess.CalledProcessError(process.returncode, command)
    ends = [started, *stamps]
    return time.perf_counter() - started, [b - a for a, b in zip(ends, ends[1:])]


def timing(times: list[float], outs: list[dict]) -> tuple[str, dict]:
    """The batch's per instruction times, in words and as figures: between result lines (the first also
    holds the start of `lmcr execute`, its models loaded) and on each line's own clock (its `seconds`:
    from perceiving to the end of the execution or the refusal; an error line has none), with how many
    passed SLOW on each."""
    own = [s["perceive_and_complete"] + s["plan_and_execute"] for out in outs if (s := out.get("seconds"))]
    slow, own_slow = sum(t > SLOW for t in times), sum(t > SLOW for t in own)
    text = (
        f"per instruction, between result lines: median {statistics.median(times):.1f} s, max {max(times):.1f} s "
        f"(the first, with the start of lmcr execute: {times[0]:.1f} s), over {SLOW:.0f} s: {slow}; on its own "
        f"clock: median {statistics.median(own):.1f} s, max {max(own):.1f} s, over {SLOW:.0f} s: {own_slow}"
    )
    figures = {
        "per instruction median s": round(statistics.median(times), 2),
        "per instruction max s": round(max(times), 2),
        f"instructions over {SLOW:.0f} s": slow,
        "first line s (with the start of lmcr execute)": round(times[0], 2),
        "own clock median s": round(statistics.median(own), 2),
        "own clock max s": round(max(own), 2),
        f"own clock over {SLOW:.0f} s": own_slow,
    }
    return text, figures


def verdict(record: dict, out: dict) -> str:
    """'ok', or why not: an error, the wrong frame, a refusal, or the failed execution."""
    if "error" in out:
        return f"error: {out['error']}"
    if out["frame"] != record["expected"]:
        return f"completed {out['frame']['roles']}"
    if not out["feasible"]:
        return f"refused: {out.get('reason', '?')}"
    if not out["success"]:
        failed = [k for k, v in out["checks"].items() if v is False or (k == "knocked" and v)]
        return f"failed: {', '.join(failed) or '?'}"
    return "ok"


def main() -> None:
    args_ = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args_.add_argument("--instructions", type=Path, required=True)
    args_.add_argument("--seed", type=int, default=0)
    args_.add_argument("--work", type=Path, help="folder for IN.jsonl / OUT.jsonl (default: a temporary one)")
    args_.add_argument("--method", help="completion method (default: lmcr execute's)")
    args_.add_argument("--urdf", help="the official Baxter URDF instead of the built-in one")
    args_.add_argument("--distractors", type=int, default=0, help="random other objects in each scene")
    args_.add_argument("--repeat", type=int, default=1, help="scenes per instruction (a larger batch)")
    add_json_option(args_, "bench_end_to_end")
    args = args_.parse_args()
    read = [r for _, r in read_jsonl(args.instructions, FIELDS)]
    records = read if args.repeat <= 1 else [{**r, "id": f"{r['id']}#{k}"} for k in range(args.repeat) for r in read]
    work = args.work or Path(tempfile.mkdtemp(prefix="lmcr-e2e-"))
    work.mkdir(parents=True, exist_ok=True)
    inp, outp = work / "in.jsonl", work / "out.jsonl"
    inp.write_text(
        "".join(json.dumps(batch_line(r, args.seed * 1000 + k, args.distractors)) + "\n" for k, r in enumerate(records))
    )
    outp.unlink(missing_ok=True)
    command = [sys.executable, "-m", "lmcr.cli", "execute", "--input", str(inp), "--output", str(outp)]
    command += ["--method", args.method] if args.method else []
    command += ["--urdf", args.urdf] if args.urdf else []
    wall, times = timed_batch(command, outp)
    outs = {o["id"]: o for o in map(json.loads, outp.read_text().splitlines())}
    rows, per = collections.Counter(), collections.defaultdict(collections.Counter)
    misses = []
    for r in records:
        out, pred = outs[r["id"]], r["expected"]["predicate"]
        why = verdict(r, out)
        right = "error" not in out and out["frame"] == r["expected"]
        done = "error" not in out and out.get("success", False)
        for key, hit in (
            ("n", True),
            ("right", right),
            ("success", done),
            ("both", why == "ok"),
            ("failed", "error" not in out and out["feasible"] and not done),
            ("refused", "error" not in out and not out["feasible"]),
            ("error", "error" in out),
        ):
            rows[key] += hit
            per[pred][key] += hit
        if why != "ok":
            misses.append(f"  {r['id']} {r['instruction']!r}: {why}")
    n = rows["n"]
    print(
        f"{n} instructions, seed {args.seed}, {args.distractors} distractors: completed right {rows['right']}/{n} = "
        f"{rows['right'] / n:.3f}; executed successfully {rows['success']}/{n} = {rows['success'] / n:.3f}; "
        f"**both {rows['both']}/{n} = {rows['both'] / n:.3f}**; executed plans that failed {rows['failed']}; "
        f"refused before moving {rows['refused']}; errors {rows['error']}"
    )
    for pred, c in sorted(per.items()):
        print(
            f"  {pred:9s} both {c['both']}/{c['n']} (right {c['right']}, succeeded {c['success']}, "
            f"refused {c['refused']})"
        )
    print("not both right and successful:" if misses else "every instruction right and successful")
    print("\n".join(misses))
    timed, timed_figures = timing(times, list(outs.values()))
    print(f"batch of {n}: {wall:.0f} s ({60 * n / wall:.1f} instructions a minute); {timed}")
    figures = {
        "instructions": n,
        "seed": args.seed,
        "distractors per scene": args.distractors,
        "completed right": f"{rows['right']}/{n}",
        "executed successfully": f"{rows['success']}/{n}",
        "both": f"{rows['both']}/{n}",
        "both, share": round(rows["both"] / n, 3),
        "executed plans that failed": rows["failed"],
        "refused before moving": rows["refused"],
        "errors": rows["error"],
        "batch wall seconds": round(wall, 1),
        "instructions a minute": round(60 * n / wall, 2),
        **timed_figures,
    }
    figures |= {f"{pred}: both": f"{c['both']}/{c['n']}" for pred, c in sorted(per.items())}
    write_results(args.json, "bench_end_to_end", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
