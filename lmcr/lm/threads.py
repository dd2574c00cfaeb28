"""How many threads torch's kernels use while one request is scored.

A completion scores a few dozen to a few thousand short texts: kernels too small to gain much from a
second thread, and a thread that waits at every kernel's end for the other to finish. With the full
store's sentence LM among 40 objects on 2 cores (`bench/bench_complete.py [--busy 2]`, p50), two threads
took 7.2 ms idle and 35.3 ms with both cores busy (two spinning processes; p90 148 ms), one thread 7.4
and 9.2 ms (p90 22 ms): on a busy machine each kernel's end waits for a thread the scheduler has put
aside. With a context to read ("for my tea") one thread costs 1.8 ms idle (10.1 -> 11.9 ms) and saves
39 ms busy (53.7 -> 14.7 ms). So a request runs on REQUEST_THREADS; batch scoring (an evaluation's
ratings, training) keeps torch's default, where two threads gain 15-20% on an idle machine.

torch is only touched when something already imported it: a count-only completion loads no torch.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

REQUEST_THREADS = 1


@contextmanager
def request_threads(threads: int = REQUEST_THREADS) -> Iterator[None]:
    """Run the block with torch on at most `threads` threads, as before afterwards. A no-op where torch
    is not loaded. Process-wide, like torch's setting: requests are served one at a time (`lmcr serve`)."""
    torch = sys.modules.get("torch")
    before = torch.get_num_threads() if torch is not None else 0
    if torch is None or before <= threads:
        yield
        return
    torch.set_num_threads(threads)
    try:
        yield
    finally:
        torch.set_num_threads(before)
