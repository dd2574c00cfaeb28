"""Benchmark: does the store still open after its writer is killed (SIGKILL) at a random moment?

Usage: python bench/bench_store_kills.py [--kills 400] [--window 0.3,1.5] [--busy] [--checkpoint-on-close]
       [--seed 0] [--json PATH]
A child process opens a store with `lmcr.store.connect`, records a row in one transaction and closes it,
over and over, as training does when it records each run. It is killed a random time (uniform over
`--window` seconds) after it has started, and the store is then opened by a plain DuckDB client, as a user
would, and its rows counted. A store that no longer opens is set aside and a new one started. With
`--busy` a process spinning on one core runs beside it (a busy machine stretches every write, and with
it the moment a kill can land in). `--checkpoint-on-close` makes the child checkpoint when it closes, as
DuckDB does by default: the behaviour the store had before its writers left their commits in the WAL.
Prints the kills, the stores that did not open, and why.
"""

from __future__ import annotations

import argparse
import collections
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import duckdb
from record import REPO_ROOT, add_json_option, busy_cores, write_results

from lmcr.errors import one_line

WRITER = """
import sys, uuid
from pathlib import Path
from lmcr.store import connect, insert_rows, transaction
db, sql, checkpoint_on_close = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3] == "1"
print("ready", flush=True)
while True:
    with connect(db, sql) as con:
        if checkpoint_on_close:
            con.execute("pragma enable_checkpoint_on_shutdown")
        with transaction(con):
            row = {"stage": "ingest", "source_file": uuid.uuid4().hex, "reason": "bench_store_kills"}
            insert_rows(con, "quarantine", [row])
"""


def kill_once(db: Path, sql: Path, seconds: float, checkpoint_on_close: bool) -> str | None:
    """Start the writer, kill it `seconds` after it is ready, open the store: None when it opens, else why."""
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
    args = [sys.executable, "-c", WRITER, str(db), str(sql), "1" if checkpoint_on_close else "0"]
    child = subprocess.Popen(args, stdout=subprocess.PIPE, env=env)
    try:
        child.stdout.readline()
        time.sleep(seconds)
    finally:  # killed also when the benchmark is interrupted: the writer loops for ever
        child.send_signal(signal.SIGKILL)
        child.wait()
        child.stdout.close()
    try:
        with duckdb.connect(str(db)) as con:
            con.execute("select count(*) from quarantine").fetchone()
    except duckdb.Error as exc:
        return one_line(exc, 120)
    return None


def window(text: str) -> tuple[float, float]:
    """`--window LOW,HIGH`: two numbers of seconds, 0 <= LOW <= HIGH."""
    try:
        low, high = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected LOW,HIGH in seconds, e.g. 0.3,1.5") from None
    if not 0 <= low <= high:
        raise argparse.ArgumentTypeError(f"{text!r}: expected 0 <= LOW <= HIGH")
    return low, high


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kills", type=int, default=400)
    parser.add_argument("--window", type=window, default="0.3,1.5", help="seconds after start to kill within: LOW,HIGH")
    parser.add_argument("--busy", action="store_true", help="a process spinning on one core beside the writer")
    parser.add_argument("--checkpoint-on-close", action="store_true", help="the writer checkpoints when it closes")
    parser.add_argument("--seed", type=int, default=0)
    add_json_option(parser, "bench_store_kills")
    args = parser.parse_args()
    low, high = args.window
    rng, errors = random.Random(args.seed), collections.Counter()
    started = time.perf_counter()
    with busy_cores(1 if args.busy else 0), tempfile.TemporaryDirectory() as scratch:
        db = Path(scratch) / "0" / "lmcr.duckdb"
        for k in range(args.kills):
            why = kill_once(db, REPO_ROOT / "sql", rng.uniform(low, high), args.checkpoint_on_close)
            if why is not None:
                errors[why.split(":")[0]] += 1
                print(f"kill {k + 1}: the store no longer opens: {why}", flush=True)
                db = Path(scratch) / str(k + 1) / "lmcr.duckdb"  # a new store; the broken one stays aside
            if (k + 1) % 50 == 0:
                print(f"{k + 1}/{args.kills} kills, {sum(errors.values())} stores lost", flush=True)
    lost = sum(errors.values())
    print(
        f"writer {'checkpointing' if args.checkpoint_on_close else 'leaving its commits in the WAL'} on close: "
        f"{lost}/{args.kills} kills left a store that does not open ({time.perf_counter() - started:.0f} s)"
    )
    figures = {
        "writer checkpoints on close": args.checkpoint_on_close,
        "busy core beside it": args.busy,
        "kill window s": [low, high],
        "kills": args.kills,
        "stores that did not open": lost,
        "why": dict(errors.most_common()) or "none",
        "duckdb": duckdb.__version__,
    }
    write_results(args.json, "bench_store_kills", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
