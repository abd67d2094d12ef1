"""A time bound on a block of the main thread, by ``SIGALRM``: the one way the test helpers
stop a call that runs too long.

:func:`deadline` raises ``error()`` inside the block once ``seconds`` have passed and restores
the previous handler and timer state when the block ends. Off the main thread, or where there is
no ``setitimer`` (Windows), the block runs unbounded: signals reach only the main thread.

Examples
--------
>>> import time
>>> try:
...     with deadline(0.05, lambda: TimeoutError("too slow")):
...         time.sleep(1)
... except TimeoutError as exc:
...     print(exc)
too slow
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from typing import Any

__all__ = ["deadline", "bounded"]


def bounded() -> bool:
    """Whether :func:`deadline` can bound a block here (the main thread, with ``setitimer``)."""
    return threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer")


@contextlib.contextmanager
def deadline(seconds: float, error: Callable[[], BaseException]) -> Iterator[None]:
    """Raise ``error()`` in the block after ``seconds`` of wall-clock time (module docstring)."""
    if not bounded():
        yield
        return

    def stop(signum: int, frame: Any) -> None:
        raise error()

    previous = signal.signal(signal.SIGALRM, stop)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
