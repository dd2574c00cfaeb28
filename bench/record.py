"""A benchmark's figures as JSON: what the documentation's results page is generated from.

Each benchmark writes `bench/results/<benchmark>.json` (or `--json PATH`): its figures by name, the exact
command that produced them (with the `LMCR_*` variables it ran under), the date, the commit, the
machine and its load average. Files in `bench/results/` are committed; the page shows nothing else, so
a figure in the documentation is always one a benchmark printed.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path

from lmcr.errors import LMCRError

REPO_ROOT = Path(__file__).resolve().parent.parent
RESULTS_DIR = REPO_ROOT / "bench" / "results"


@contextmanager
def busy_cores(n: int, settle: float = 0.0) -> Iterator[None]:
    """`n` processes spinning (one core each) while the block runs, killed after it whatever happens: what
    a benchmark measures on a busy machine. `settle`: seconds they spin before the block, for what reads
    the load average (a one-minute mean) to see them."""
    spinners = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(n)]
    try:
        time.sleep(settle if n else 0.0)
        yield
    finally:
        for spinner in spinners:
            spinner.kill()
            spinner.wait()


def add_json_option(parser: argparse.ArgumentParser, name: str) -> None:
    """`--json PATH`: where the figures go (default bench/results/<name>.json; '' writes none)."""
    parser.add_argument(
        "--json",
        type=str,
        default=str(RESULTS_DIR / f"{name}.json"),
        help=f"write the figures, command and date here (default bench/results/{name}.json; '' for none)",
    )


def add_shared_option(parser: argparse.ArgumentParser) -> None:
    """`--shared DIR`: the read-only shared data (default $LMCR_SHARED_DIR, else ../shared beside the checkout)."""
    parser.add_argument(
        "--shared",
        type=Path,
        default=Path(os.environ.get("LMCR_SHARED_DIR") or REPO_ROOT.parent / "shared"),
        help="the shared data folder (default $LMCR_SHARED_DIR, else ../shared)",
    )


def run_or_exit(run: Callable[[argparse.Namespace], None], args: argparse.Namespace) -> None:
    """`run(args)`; a project error (bad input, a missing store) ends the benchmark with its one line."""
    try:
        run(args)
    except LMCRError as exc:
        sys.exit(f"error: {exc}")


def command_line() -> str:
    """The command as typed from the repository root, the LMCR_* variables first."""
    script = Path(sys.argv[0]).resolve()
    shown = script.relative_to(REPO_ROOT) if script.is_relative_to(REPO_ROOT) else script
    env = [f"{k}={shlex.quote(v)}" for k, v in sorted(os.environ.items()) if k.startswith("LMCR_")]
    return " ".join([*env, "python", shlex.quote(str(shown)), *map(shlex.quote, sys.argv[1:])])


def git_commit() -> str:
    """The checked-out commit, `-dirty` when tracked files differ from it; '' outside a git checkout."""

    def git(*args: str) -> str:
        done = subprocess.run(["git", *args], cwd=REPO_ROOT, capture_output=True, text=True, check=False)
        return done.stdout.strip() if done.returncode == 0 else ""

    commit = git("rev-parse", "--short", "HEAD")
    return commit + ("-dirty" if commit and git("status", "--porcelain", "--untracked-files=no") else "")


def machine() -> str:
    """OS, architecture, CPU model and count, Python version."""
    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(
            line.split(":", 1)[1].strip()
            for line in Path("/proc/cpuinfo").read_text().splitlines()
            if line.startswith("model name")
        )
    except (OSError, StopIteration):
        pass
    return f"{platform.system()} {platform.machine()}, {cpu}, {os.cpu_count()} CPUs, Python {platform.python_version()}"


def write_results(path: str, name: str, title: str, figures: dict) -> None:
    """Write the record (to a temporary name, then renamed) unless `path` is ''; say where it went."""
    if not path:
        return
    record = {
        "benchmark": name,
        "title": title,
        "command": command_line(),
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "commit": git_commit(),
        "machine": machine(),
        # how busy the machine was (1, 5, 15 minutes): timings on a loaded host are slower
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "figures": figures,
    }
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp")
    tmp.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    tmp.replace(target)
    print(f"figures written to {path}")
