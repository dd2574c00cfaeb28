"""Waiting for task futures: an interrupt stops the worker processes instead of waiting for them."""

from __future__ import annotations

import multiprocessing
import time

import pytest

from flows.futures import results


class Done:
    def __init__(self, value):
        self.value = value

    def result(self):
        return self.value


class Interrupted:
    def result(self):
        raise KeyboardInterrupt


def test_results_are_in_order():
    assert results([Done(2), Done(1)]) == [2, 1]


def test_an_interrupt_terminates_the_workers_and_is_re_raised():
    worker = multiprocessing.get_context("spawn").Process(target=time.sleep, args=(60,))
    worker.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            results([Done(1), Interrupted()])
        worker.join(timeout=10)
        assert not worker.is_alive() and worker.exitcode is not None and worker.exitcode < 0
    finally:
        if worker.is_alive():
            worker.kill()
