"""One local Prefect API server per pipeline run, shared by every task process of the run.

Without `PREFECT_API_URL`, Prefect starts a temporary server in *each* process that runs a task (the
process-pool workers of the ingest and frames flows included), each with a 20 s start-up limit: on a
loaded 2-core machine they time out, and a worker killed with its pool leaves its server behind.
`local_server()` starts one server before the run, points the run and every process it spawns at it
(the environment variable is inherited), waits as long as a loaded machine needs, and stops it on
success, failure and Ctrl-C. The server asks the kernel to kill it when the run's process dies
(`PR_SET_PDEATHSIG`), so not even `kill -9` of the run leaves it behind. With `PREFECT_API_URL` set
(a deployment's worker, `prefect server start`), the run uses that server and starts none.
"""

from __future__ import annotations

import ctypes
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager

import httpx

from flows.futures import stop_workers

STARTUP_TIMEOUT_S = 600.0  # a server takes ~5 s on a quiet machine and minutes beside heavy work
PR_SET_PDEATHSIG = 1
DRAIN_S = 30.0  # per Prefect worker (logs, events) at the end of a run
DRAIN_INTERRUPTED_S = 3.0


class ServerStartError(RuntimeError):
    """The run's Prefect server did not answer in time or exited while starting."""


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _die_with_parent() -> None:  # pragma: no cover - runs in the child between fork and exec
    """Linux: the kernel sends SIGKILL to the server when the process that started it dies."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    except OSError:  # not glibc Linux: the server is still stopped by `local_server`'s own exit paths
        pass


def _start(port: int) -> subprocess.Popen:
    env = {**os.environ, "PREFECT_UI_ENABLED": "0", "PREFECT__SERVER_EPHEMERAL": "1", "PREFECT__SERVER_FINAL": "1"}
    env.pop("PREFECT_API_URL", None)
    # the run's private server sends no usage telemetry unless asked to: offline (CI, a lab machine) it
    # logged "Failed to send telemetry" as an ERROR every few minutes of a run
    env.setdefault("PREFECT_SERVER_ANALYTICS_ENABLED", "false")
    command = [
        sys.executable,
        "-m",
        "uvicorn",
        "--factory",
        "prefect.server.api.server:create_app",
        "--host",
        "127.0.0.1",
        "--port",
        str(port),
        "--log-level",
        "error",
        "--lifespan",
        "on",
    ]
    preexec = _die_with_parent if sys.platform.startswith("linux") else None
    return subprocess.Popen(command, env=env, stdin=subprocess.DEVNULL, preexec_fn=preexec)


def _wait_healthy(process: subprocess.Popen, url: str, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    with httpx.Client(timeout=10.0) as client:
        while time.monotonic() < deadline:
            if process.poll() is not None:
                raise ServerStartError(f"the Prefect server exited with status {process.returncode} while starting")
            try:
                if client.get(f"{url}/health").status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            time.sleep(0.2)
    raise ServerStartError(
        f"the Prefect server did not answer within {timeout_s:.0f} s "
        "(set LMCR_PREFECT_STARTUP_TIMEOUT_S to wait longer, or PREFECT_API_URL to use a running one)"
    )


def _drain_prefect_workers(timeout_s: float) -> None:
    """Send the logs and events Prefect still buffers while the server is up: drained later (at exit),
    they would wait for a stopped server, retry for a minute and print connection errors."""
    from prefect.events.worker import EventsWorker
    from prefect.logging.handlers import APILogWorker

    for worker in (APILogWorker, EventsWorker):
        try:
            worker.drain_all(timeout=timeout_s)
        except RuntimeError:  # never started in this process
            pass


def stop_process(process: subprocess.Popen) -> None:
    """Terminate `process` and wait for it; killed if it has not ended within 10 s."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def startup_timeout() -> float:
    """Seconds to wait for the server: `$LMCR_PREFECT_STARTUP_TIMEOUT_S`, else `STARTUP_TIMEOUT_S`."""
    raw = os.environ.get("LMCR_PREFECT_STARTUP_TIMEOUT_S")
    try:
        value = float(raw) if raw else STARTUP_TIMEOUT_S
    except ValueError:
        raise ServerStartError(f"LMCR_PREFECT_STARTUP_TIMEOUT_S must be a number of seconds, not {raw!r}") from None
    if not value > 0:
        raise ServerStartError(f"LMCR_PREFECT_STARTUP_TIMEOUT_S must be positive, not {raw!r}")
    return value


@contextmanager
def local_server(timeout_s: float | None = None) -> Iterator[str]:
    """Yield the API URL the run uses: `$PREFECT_API_URL` when set, else one local server started here,
    exported to this process's settings and environment (so spawned task processes use it too) and
    stopped when the block ends, however it ends."""
    from prefect.context import refresh_global_settings_context
    from prefect.settings import PREFECT_API_URL, temporary_settings

    if os.environ.get("PREFECT_API_URL"):
        yield os.environ["PREFECT_API_URL"]
        return
    port = _free_port()
    url = f"http://127.0.0.1:{port}/api"
    process = _start(port)
    drain_s = DRAIN_S
    try:
        _wait_healthy(process, url, timeout_s or startup_timeout())
        print(f"Prefect server for this run: {url} (stopped when the run ends)", flush=True)
        # The environment for spawned processes; the global settings for Prefect's own threads (log and
        # event workers, the process pool's message forwarding), which read it, not this thread's context.
        os.environ["PREFECT_API_URL"] = url
        refresh_global_settings_context()
        with temporary_settings(updates={PREFECT_API_URL: url}):
            yield url
    except KeyboardInterrupt:
        drain_s = DRAIN_INTERRUPTED_S  # who pressed Ctrl-C waits for the prompt, not for the last log lines
        raise
    finally:
        if process.poll() is None:
            _drain_prefect_workers(drain_s)
        if os.environ.pop("PREFECT_API_URL", None):
            refresh_global_settings_context()
        stop_process(process)


def run_with_server(main, *args, **kwargs):
    """`main(*args, **kwargs)` against one local server (see `local_server`). Ctrl-C and SIGTERM (a polite
    kill) stop the run's worker processes at once and end it with KeyboardInterrupt, the server stopped,
    wherever the signal lands: one that lands inside a library that wraps it in an error of its own
    (Prefect serialising a task's context as it submits it) still ends the run as an interrupt, not with
    that error's traceback. Returns what `main` returns."""
    interrupted: list[int] = []

    def interrupt(signum, frame):
        interrupted.append(signum)
        stop_workers()
        raise KeyboardInterrupt

    handled = [s for s in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(s) is not signal.SIG_IGN]
    previous = {s: signal.signal(s, interrupt) for s in handled}  # an ignored Ctrl-C (a background job) stays so
    try:
        with local_server():
            try:
                return main(*args, **kwargs)
            except Exception as exc:
                if interrupted:
                    raise KeyboardInterrupt from exc
                raise
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
