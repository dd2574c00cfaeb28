"""Deployments against a real local Prefect server (SQLite) on a free loopback port: deploy from
prefect.yaml, run a deployment by name, execute it with a process worker, see its artifacts."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from lmcr.config import REPO_ROOT

PREFECT = str(Path(sys.executable).with_name("prefect"))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    home = tmp_path_factory.mktemp("prefect_home")
    port = free_port()
    env = {**os.environ, "PREFECT_HOME": str(home), "PREFECT_SERVER_ANALYTICS_ENABLED": "false", "COLUMNS": "250",
           "PREFECT_API_URL": f"http://127.0.0.1:{port}/api", "PREFECT_SERVER_SERVICES_SCHEDULER_LOOP_SECONDS": "2"}
    log = open(home / "server.log", "w")
    proc = subprocess.Popen([PREFECT, "server", "start", "--host", "127.0.0.1", "--port", str(port)], env=env,
                            stdout=log, stderr=subprocess.STDOUT)
    env["LMCR_TEST_SERVER_LOG"] = str(home / "server.log")
    try:
        for _ in range(120):
            try:
                urllib.request.urlopen(f"{env['PREFECT_API_URL']}/health", timeout=1)
                break
            except OSError:
                time.sleep(0.5)
        else:
            pytest.fail("the Prefect server did not come up in 60 s")
        yield env
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        log.close()


def prefect(env, *args, timeout=300) -> str:
    done = subprocess.run([PREFECT, *args], env=env, cwd=REPO_ROOT, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_deploy_run_by_name_and_artifacts(server, tmp_path):
    prefect(server, "work-pool", "create", "lmcr-process", "--type", "process")
    out = prefect(server, "--no-prompt", "deploy", "--name", "annotate", "--name", "retrain")
    assert "annotate/annotate" in out and "retrain/retrain" in out
    schedules = prefect(server, "deployment", "inspect", "retrain/retrain")
    assert "0 3 * * 1" in schedules  # the weekly retrain schedule is registered
    # ... and the server's scheduler creates its runs (it failed every loop with SQLAlchemy 2.1)
    for _ in range(60):
        if "retrain" in prefect(server, "flow-run", "ls", "--state", "SCHEDULED"):
            break
        time.sleep(1)
    else:
        pytest.fail("the scheduler created no retrain runs in 60 s")
    log = Path(server["LMCR_TEST_SERVER_LOG"]).read_text(encoding="utf-8", errors="replace")
    assert "InvalidRequestError" not in log and "Traceback" not in log
    prefect(server, "deployment", "run", "annotate/annotate", "--param", f"data_dir={tmp_path}")
    prefect(server, "worker", "start", "--pool", "lmcr-process", "--run-once")
    runs = prefect(server, "flow-run", "ls", "--state", "COMPLETED")
    assert "annotate" in runs
    artifacts = prefect(server, "artifact", "ls")
    assert "krippendorff-alpha" in artifacts and "worker-quality" in artifacts
    assert (tmp_path / "lmcr.duckdb").exists()
