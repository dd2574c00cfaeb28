"""Waiting for task futures, and a run's Ctrl-C or SIGTERM: an interrupt stops the worker processes instead
of waiting for them."""

from __future__ import annotations

import multiprocessing
import os
import signal
import time

import pytest

from flows.futures import results
from flows.server import run_with_server


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


def _wrapped_interrupt(how: signal.Signals, worker) -> None:
    """A run's body: a signal lands inside a library call that turns the KeyboardInterrupt into an error of
    its own (as pydantic does while Prefect serialises a task's context on submit)."""
    try:
        os.kill(os.getpid(), how)
        time.sleep(5)  # the handler runs before this ends
    except KeyboardInterrupt as exc:
        raise RuntimeError("Error calling function `ser_model`: KeyboardInterrupt") from exc
    raise AssertionError("the signal was not delivered")


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_that_a_library_wraps_still_ends_the_run_as_an_interrupt(monkeypatch, how):
    """Ctrl-C or SIGTERM anywhere in the run: the workers are stopped at once and the run ends with
    KeyboardInterrupt (the pipeline's one line and exit status 130), not the wrapping error's traceback;
    the process's own handlers are restored after."""
    monkeypatch.setenv("PREFECT_API_URL", "http://127.0.0.1:1/api")  # no server of its own
    # a run at a terminal: Ctrl-C is live even where these tests run as a background job (which ignores it)
    live = signal.signal(how, signal.default_int_handler if how == signal.SIGINT else signal.SIG_DFL)
    worker = multiprocessing.get_context("spawn").Process(target=time.sleep, args=(60,))
    worker.start()
    before = signal.getsignal(how)
    try:
        with pytest.raises(KeyboardInterrupt):
            run_with_server(_wrapped_interrupt, how, worker)
        worker.join(timeout=10)
        assert not worker.is_alive() and worker.exitcode is not None and worker.exitcode < 0
        assert signal.getsignal(how) is before
    finally:
        signal.signal(how, live)
        if worker.is_alive():
            worker.kill()


def test_an_ignored_ctrl_c_stays_ignored_through_the_run(monkeypatch):
    """A run started as a background job (SIGINT ignored, as the shell leaves it) does not take Ctrl-C
    up: the signal is still ignored during the run, which ends as its body does, and after."""
    monkeypatch.setenv("PREFECT_API_URL", "http://127.0.0.1:1/api")
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        assert run_with_server(_ignored_interrupt) == "ran on"
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def _ignored_interrupt() -> str:
    os.kill(os.getpid(), signal.SIGINT)
    time.sleep(0.5)  # a handler would have run by now
    return "ran on" if signal.getsignal(signal.SIGINT) is signal.SIG_IGN else "taken up"


def test_an_error_without_a_signal_is_left_as_it_is(monkeypatch):
    monkeypatch.setenv("PREFECT_API_URL", "http://127.0.0.1:1/api")

    def fails():
        raise RuntimeError("a real failure")

    with pytest.raises(RuntimeError, match="a real failure"):
        run_with_server(fails)
