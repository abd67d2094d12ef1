"""tests/deadline.py: a block over its bound gets the error, one within it runs to the end,
the previous SIGALRM handler comes back either way, and off the main thread the block runs
unbounded."""

from __future__ import annotations

import signal
import threading
import time

import pytest

from tests.deadline import bounded, deadline

pytestmark = pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs SIGALRM")


class _LateError(Exception):
    pass


def test_a_long_block_gets_the_error_and_the_handler_comes_back():
    """A sleep of 5 s under a 0.05-s bound raises the error within a second; afterwards the
    handler is the one before and no timer is left."""
    before = signal.getsignal(signal.SIGALRM)
    t0 = time.monotonic()
    with pytest.raises(_LateError), deadline(0.05, _LateError):
        time.sleep(5)
    assert time.monotonic() - t0 < 1.0
    assert signal.getsignal(signal.SIGALRM) is before
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_a_short_block_runs_to_its_end():
    """A block well within its bound returns its work and leaves no timer."""
    with deadline(5, _LateError):
        done = sum(range(1000))
    assert done == 499500 and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_off_the_main_thread_the_block_is_unbounded():
    """In a worker thread the block runs (no signal can reach it) and nothing is raised."""
    seen = {}

    def work():
        seen["bounded"] = bounded()
        with deadline(0.01, _LateError):
            time.sleep(0.05)
        seen["done"] = True

    t = threading.Thread(target=work)
    t.start()
    t.join()
    assert seen == {"bounded": False, "done": True}
