"""Waiting for a flow's task futures so that Ctrl-C or SIGTERM ends a run in seconds.

On an interrupt Prefect's process-pool runner shuts its pool down with `wait=True`: tasks not yet
started are cancelled, but a running parse (minutes of spaCy on a loaded machine) is waited for, and the
run does not end until it has finished. `results` stops the pool's worker processes first; what they
were writing is lost, and never seen, since every stage writes under a temporary name and renames.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Iterable
from typing import Any


def results(futures: Iterable[Any]) -> list[Any]:
    """Each future's result, in order; on an interrupt the worker processes are terminated, then it is
    re-raised."""
    try:
        return [future.result() for future in futures]
    except KeyboardInterrupt:
        stop_workers()
        raise


def stop_workers() -> None:
    """Terminate this process's worker processes (a process pool's), whatever they are doing."""
    for worker in multiprocessing.active_children():
        worker.terminate()
