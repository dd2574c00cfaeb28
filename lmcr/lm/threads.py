"""How many threads torch's kernels use while one request is scored: as many as there are idle cores.

A completion scores a few dozen to a few thousand short texts, and a kernel on two threads ends when the
slower one does. On an idle machine a second thread gains a little; on a busy one the scheduler puts one
of them aside and every kernel waits for it. With the full store's sentence LM among 40 objects on 2 cores
(`bench/bench_complete.py [--busy 2]`, p50; "for my tea" is the context case):

- idle: two threads 7.2 ms (context 10.1), one thread 7.4 ms (11.9); with the household LM mixed in
  (household weight 10) 8.9 / 12.1 against 9.9 / 14.3 ms;
- both cores busy (two spinning processes): two threads 35.3 ms (context 53.7; p90 148 / 283), one
  thread 9.2 ms (14.7; p90 22 / 31).

So a request runs on the cores the load average leaves idle, at least one and at most torch's setting:
`cores - (load - 1)`, its own process being the 1 a running request adds. The load average is the
kernel's one-minute mean of runnable processes: it follows a machine that stays busy (a build, a
training run, parallel tests) within seconds, not a burst. Batch scoring (an evaluation's ratings,
training) keeps torch's setting. Where the load average cannot be read, a request takes one thread,
the choice that is never far off.

torch is only touched when something already imported it: a count-only completion loads no torch.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager


def idle_cores() -> int:
    """The cores left to this process: its cores less the one-minute load of the others (the load average
    less the 1 its own running request adds), at least 1; 1 where the load average cannot be read."""
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # not on every platform
        return 1
    return max(1, math.floor(cores() - max(load - 1.0, 0.0)))


def cores() -> int:
    """The cores this process may run on (its affinity where the platform says, as torch counts them)."""
    affinity = getattr(os, "sched_getaffinity", None)
    return len(affinity(0)) if affinity is not None else os.cpu_count() or 1


@contextmanager
def request_threads() -> Iterator[None]:
    """Run the block with torch on at most `idle_cores()` threads, as before afterwards. A no-op where torch
    is not loaded. Process-wide, like torch's setting: requests are served one at a time (`lmcr serve`)."""
    torch = sys.modules.get("torch")
    threads = before = torch.get_num_threads() if torch is not None else 0
    if before > 1:  # one thread (or no torch) is as few as it gets: no load average to read
        threads = min(before, idle_cores())
    if threads == before:
        yield
        return
    torch.set_num_threads(threads)
    try:
        yield
    finally:
        torch.set_num_threads(before)
