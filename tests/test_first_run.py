"""The first run: the demo's pipeline passes on a machine whose cores are kept busy, through one Prefect
server of its own, and no process of it is left behind, whether it ends, is interrupted or killed."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest

from flows.server import ServerStartError, local_server, startup_timeout
from lmcr.checkout import REPO_ROOT
from lmcr.scorers.registry import COMPLETION_METHOD

MARKER = "LMCR_TEST_RUN_MARKER"
SMALL = {"embedding": 16, "max_epochs": 1, "per_verb": 5}


def processes_with(marker: str) -> list[int]:
    """Live processes whose environment carries `marker` (the run's own and everything it spawned)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit() or int(entry.name) == os.getpid():
            continue
        try:
            environ = (entry / "environ").read_bytes()
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if f"{MARKER}={marker}".encode() in environ.split(b"\0") and state != "Z":
            found.append(int(entry.name))
    return found


def wait_until_gone(marker: str, seconds: float = 20.0) -> list[int]:
    deadline = time.monotonic() + seconds
    while (left := processes_with(marker)) and time.monotonic() < deadline:
        time.sleep(0.2)
    return left


def run_env(tmp_path: Path, marker: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "PREFECT_API_URL"}
    return env | {
        "PREFECT_HOME": str(tmp_path / "prefect-home"),
        "PREFECT_SERVER_ANALYTICS_ENABLED": "false",
        MARKER: marker,
    }


def pipeline(tmp_path: Path, env: dict[str, str]) -> subprocess.Popen:
    """`python -m flows.pipeline` on the sample, small, as a user starts it at a terminal: Ctrl-C
    interrupts it even where the test itself runs with SIGINT ignored (a job started in the background)."""
    params = json.dumps(SMALL | {"data_dir": str(tmp_path / "data")})
    return subprocess.Popen(
        [sys.executable, "-m", "flows.pipeline", params],
        cwd=REPO_ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )


pytestmark = pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs Linux /proc")


def test_the_demo_pipeline_on_busy_cores_then_an_unchanged_rerun(tmp_path, monkeypatch):
    """The demo's pipeline as `make demo` runs it (its own process, the sample, on a busy machine): one
    Prefect server, no task process starting its own, nothing left behind; then what it made, and an
    unchanged re-run in this process that skips the work and shows the first run's artifacts (the same
    Prefect home). A busy loop for every core but one keeps the machine busy beside the suite's other
    worker (a loop for every core as well doubled the test's time in CI and slowed the other worker),
    from before the server starts until the stages whose tasks run in processes of their own (ingest,
    frames) are done: what a busy machine made time out was a server starting, the run's or a task
    process's; the rest of the run is timed by nothing, and under the loops it doubled the test's time."""
    marker = uuid.uuid4().hex
    env = run_env(tmp_path, marker)
    loops = max(1, (os.cpu_count() or 2) - 1)
    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"], env=env) for _ in range(loops)]
    run = pipeline(tmp_path, env)
    watchdog = threading.Timer(1800, run.kill)
    watchdog.start()
    lines = []
    try:
        for line in run.stdout:
            lines.append(line)
            if "for flow 'train'" in line:  # past the frames stage (the flow's order: ingest, frames, ...)
                stop(busy)
        run.wait()
    finally:
        watchdog.cancel()
        stop(busy)
    output = "".join(lines)
    assert run.returncode == 0, output[-3000:]
    assert output.count("Prefect server for this run") == 1
    assert "Starting temporary server" not in output  # no task process started a server of its own
    assert "Error logging to API" not in output  # logs were sent before the server stopped
    assert "executor check 'pour me some water': success" in output
    assert wait_until_gone(marker) == []
    # what the run prints (through Prefect's log: `... - checkpoint SETTING: PATH`)
    checkpoints = dict(re.findall(r"checkpoint ([\w-]+): (\S+)$", output, re.MULTILINE))
    assert set(checkpoints) == {"sentence-all", "frame-all", "sentence-household", "frame-household"}
    table1 = check_what_the_demo_made(tmp_path / "data")

    from flows.pipeline import PipelineParams, pipeline_flow

    chosen = tmp_path / "data" / "mixture.json"
    chosen_at = chosen.stat().st_mtime_ns
    monkeypatch.setenv("PREFECT_HOME", env["PREFECT_HOME"])
    with local_server():
        second = pipeline_flow(PipelineParams(**SMALL, data_dir=str(tmp_path / "data")))
        keys = artifact_keys()
    assert {s: str(p) for s, p in second["checkpoints"].items()} == checkpoints  # training skipped
    speech = tmp_path / "data" / "speech" / "en-us"  # the speech model: built once, kept on the unchanged re-run
    assert (speech / "LATEST").exists() and len([v for v in speech.iterdir() if v.name.startswith("v")]) == 1
    assert second["table1"] == table1
    # the mixture was not chosen again: its choice kept for the same inputs, its file as the first run wrote it
    assert chosen.stat().st_mtime_ns == chosen_at and len(list((tmp_path / "data" / "cache").glob("mixture-*"))) == 1
    assert second["executor_check"]["frame"]["predicate"] == "pour" and "grasped" in second["executor_check"]["checks"]
    # What a Prefect UI user sees of the runs: Table I, the report and the executor check as artifacts.
    assert {"table-i", "evaluation-report", "evaluation-report-html", "executor-check"} <= keys


def stop(processes: list[subprocess.Popen]) -> None:
    for proc in processes:
        proc.kill()
        proc.wait()


def check_what_the_demo_made(data: Path) -> dict:
    """The mixture chosen on both dev sets, Table I over the sample's 11 verbs, and a report that says it
    is the sample's; returns Table I."""
    chosen = json.loads((data / "mixture.json").read_text())  # the household weight, chosen on both dev sets
    assert set(chosen["accuracy"]) == {"1", "3", "10", "30", "100"} and chosen["chosen_for"] == COMPLETION_METHOD
    assert set(chosen["accuracy"]["1"]) == {"table1", "instructions"} and chosen["instructions_sha256"]
    # with the context term's weight, chosen on the instructions at the same time
    assert set(chosen["accuracy"]["1"]["instructions"]) == {"0.5", "1", "2"} and chosen["context_weight"] in (0.5, 1, 2)
    table1 = json.loads((data / "report" / "figures.json").read_text())["table1"]
    assert table1["sentence_lm"]["all"] >= 0 and "conceptnet" in table1
    verbs = "blend brush dip dump fill fry heat pour rub season sprinkle".split()
    assert set(table1["sentence_lm"]) == {"all", *verbs}  # the sample ratings cover the 11 verbs
    report = (data / "report" / "report.md").read_text(encoding="utf-8")
    assert "**Sample data.**" in report and "## Provenance" in report and "sample_ratings_mturk.csv" in report
    assert f"weight of the context term in completion: {chosen['context_weight']:g}" in report
    assert "Checkpoint sentence-all: `v" in report and "paper " not in report.split("## Fig. 4A")[0]
    page = (data / "report" / "report.html").read_text(encoding="utf-8")
    assert '<div class="scroll"><table>' in page and "<blockquote>" in page and page.count("data:image/png") == 4
    return table1


def artifact_keys() -> set[str]:
    """The keys of the artifacts the current Prefect server holds."""
    import asyncio

    from prefect.client.orchestration import get_client

    async def read() -> set[str]:
        async with get_client() as client:
            return {a.key for a in await client.read_artifacts()}

    return asyncio.run(read())


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGTERM, signal.SIGKILL])
def test_an_interrupted_or_killed_run_leaves_no_server(tmp_path, how):
    """Stopped while its worker processes parse the sample (the pool's shutdown used to wait for the
    running parses, over a minute on a loaded machine), the run ends at once and leaves nothing."""
    marker = uuid.uuid4().hex
    run = pipeline(tmp_path, run_env(tmp_path, marker))
    try:
        for line in run.stdout:
            if "sources to ingest" in line:
                break
        else:
            pytest.fail("the run never started to ingest")
        assert len(processes_with(marker)) >= 2  # the run and its server
        run.send_signal(how)
        run.wait(timeout=60)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    assert wait_until_gone(marker) == []


def test_a_server_that_cannot_start_is_one_line(tmp_path):
    env = run_env(tmp_path, uuid.uuid4().hex) | {"LMCR_PREFECT_STARTUP_TIMEOUT_S": "0.01"}
    run = pipeline(tmp_path, env)
    output, _ = run.communicate(timeout=120)
    assert run.returncode == 1
    assert output.strip().splitlines() == [
        "error: the Prefect server did not answer within 0 s (set LMCR_PREFECT_STARTUP_TIMEOUT_S to wait longer, "
        "or PREFECT_API_URL to use a running one)"
    ]
    assert wait_until_gone(env[MARKER]) == []


def test_startup_timeout_reads_the_environment(monkeypatch):
    monkeypatch.setenv("LMCR_PREFECT_STARTUP_TIMEOUT_S", "90")
    assert startup_timeout() == 90
    for bad in ("soon", "0", "-5"):
        monkeypatch.setenv("LMCR_PREFECT_STARTUP_TIMEOUT_S", bad)
        with pytest.raises(ServerStartError, match="LMCR_PREFECT_STARTUP_TIMEOUT_S"):
            startup_timeout()


def test_a_set_api_url_is_used_and_no_server_started(monkeypatch):
    monkeypatch.setenv("PREFECT_API_URL", "http://127.0.0.1:1/api")
    with local_server() as url:
        assert url == "http://127.0.0.1:1/api"


@pytest.mark.parametrize(("asked", "sent"), [(None, "false"), ("true", "true")])
def test_the_runs_own_server_sends_no_telemetry_unless_asked(monkeypatch, asked, sent):
    """Offline, the server's telemetry logged an ERROR every few minutes of a run; a user who set the
    variable keeps their choice."""
    from flows import server

    started = {}

    def popen(command, env, **kwargs):
        started.update(env)
        return "process"

    monkeypatch.setattr(server.subprocess, "Popen", popen)
    if asked is None:
        monkeypatch.delenv("PREFECT_SERVER_ANALYTICS_ENABLED", raising=False)
    else:
        monkeypatch.setenv("PREFECT_SERVER_ANALYTICS_ENABLED", asked)
    assert server._start(4200) == "process"
    assert started["PREFECT_SERVER_ANALYTICS_ENABLED"] == sent and "PREFECT_API_URL" not in started
