"""How many threads torch's kernels use while one request is scored.

A completion scores a few dozen to a few thousand short texts: kernels too small to gain much from a
second thread, and a thread that waits at every kernel's end for the other to finish. On an idle 2-core
machine the sentence LM's part of a completion among 40 objects took 2.6-2.8 ms on two threads and
3.1-3.2 ms on one, and the whole completion about the same (7.7-7.9 ms against 7.6-8.1 ms p50, the full
store's LM). With both cores busy (two spinning processes) the completion took 40-56 ms on two threads
and 11-12 ms on one: each kernel's end waits for a thread the scheduler has put aside. So a request
runs on REQUEST_THREADS; batch scoring (an evaluation's ratings, training) keeps torch's default, where
two threads gain 15-20% on an idle machine.

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
