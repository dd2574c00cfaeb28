"""Start-up time of the command line: `lmcr --help` and the light commands, median of several runs.

Heavy libraries (torch, gensim, scipy, spaCy) are imported inside the commands that use them, so these
must start in well under 1.5 s. Usage: python bench/bench_cli.py [--runs 7] [--json PATH]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time

from record import add_json_option, write_results

TARGET_S = 1.5


def timed(args: list[str], env_dir: str) -> float:
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "lmcr.cli", *args],
        capture_output=True,
        check=False,
        env={"LMCR_DATA_DIR": env_dir, "PATH": "/usr/bin:/bin"},
    )
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    add_json_option(parser, "bench_cli")
    args = parser.parse_args()
    figures = {"runs per command": args.runs, "target median s": TARGET_S}
    with tempfile.TemporaryDirectory() as data:
        commands = {
            "--help": ["--help"],
            "--version": ["--version"],
            "migrate": ["migrate"],
            "query corpus_summary": ["query", "corpus_summary"],
            "schema": ["schema"],
            "srl-eval --help": ["srl-eval", "--help"],
            "execute --help": ["execute", "--help"],
        }
        print(f"{'command':<26} {'median s':>9} {'max s':>7}  target <= {TARGET_S} s")
        for name, argv in commands.items():
            times = [timed(argv, data) for _ in range(args.runs)]
            median = statistics.median(times)
            print(f"lmcr {name:<21} {median:9.3f} {max(times):7.3f}  {'ok' if median <= TARGET_S else 'SLOW'}")
            figures[f"lmcr {name}: median s"] = round(median, 3)
            figures[f"lmcr {name}: max s"] = round(max(times), 3)
    write_results(args.json, "bench_cli", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
