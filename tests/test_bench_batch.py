"""The end-to-end benchmark's batch timing (bench/bench_end_to_end.py): each instruction's time read from
the batch's sidecar as its lines appear, a failed batch reported, and the batch ended with a benchmark
that fails."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from lmcr.checkout import REPO_ROOT

WRITER = """
import os, sys, time
out = sys.argv[1]
with open(out + ".partial", "w") as f:
    for k, pause in enumerate((0.6, 1.2, 0.6)):
        time.sleep(pause)
        f.write('{"id": "%d"}\\n' % k)
        f.flush()
os.replace(out + ".partial", out)
"""


@pytest.fixture
def bench(monkeypatch):
    monkeypatch.syspath_prepend(str(REPO_ROOT / "bench"))
    import bench_end_to_end

    return bench_end_to_end


def test_each_instruction_is_timed_as_its_line_appears(bench, tmp_path):
    out = tmp_path / "out.jsonl"
    wall, times = bench.timed_batch([sys.executable, "-c", WRITER, str(out)], out)
    assert len(times) == 3 and out.read_text().count("\n") == 3
    assert times[1] == pytest.approx(1.2, abs=0.35) and times[2] == pytest.approx(0.6, abs=0.35)
    assert times[0] >= 0.6 and wall >= sum(times) - 0.01


def test_a_failed_batch_is_an_error(bench, tmp_path):
    with pytest.raises(subprocess.CalledProcessError):
        bench.timed_batch([sys.executable, "-c", "raise SystemExit(3)"], tmp_path / "out.jsonl")


def test_a_benchmark_that_fails_while_polling_ends_its_batch(bench, tmp_path):
    out, pid_file = tmp_path / "out.jsonl", tmp_path / "pid"
    # the batch notes its pid, then makes its sidecar unreadable (a folder): the next poll fails
    batch = (
        f"import os, time; open({str(pid_file)!r}, 'w').write(str(os.getpid())); "
        f"os.mkdir({str(out) + '.partial'!r}); time.sleep(60)"
    )
    with pytest.raises(IsADirectoryError):
        bench.timed_batch([sys.executable, "-c", batch], out)
    with pytest.raises(ProcessLookupError):  # ended and reaped with the benchmark, not left running
        os.kill(int(pid_file.read_text()), 0)
