"""Peak traced memory of a call, measured in a helper process that traces from start to end.

:func:`traced_call` runs ``fn(*args)`` in a helper process of this test process and returns its
value with the peak of ``tracemalloc``'s traced memory during the call (Python and numpy
allocations, numpy's untouched ``zeros`` included), above what was traced when the call began.

Why not ``tracemalloc.start()`` and ``stop()`` around the call, here: on CPython 3.11, ``stop()``
frees state that a thread blocked in the traced raw allocator (waiting for the GIL) goes on to
use (python/cpython#128679, fixed for 3.12 and 3.13 by python/cpython#129022 and #128897, never
for 3.11, which takes security fixes only). A test worker has such threads (xdist's own, and the
pools and pyarrow threads that earlier tests leave), and the hardening suite crashed a worker
that way now and then: "Fatal Python error: Segmentation fault", the current thread with no
Python frame, at the worker's first I/O after a case's ``stop()``. Nor can tracing simply stay on
in the test process: it makes allocation-heavy code about 6 times slower (``run_episode("1",
"greedy")``: 0.17 s untraced, 1.06 s traced, medians of 4, 2026-12-04), which every later test
of that worker would pay. So tracing starts once, in a spawned helper, the peak is reset for
each call, and the helper is killed when this process exits: tracing is never stopped.

The helper runs one call at a time, in its main thread and in this process's working folder at
the time of the call (a test's ``monkeypatch.chdir`` holds there too: relative paths land where
they would here), so ``fn`` may set ``signal.alarm``; the processes it starts are the helper's
children (a CLI case counts its orphans there). ``fn``,
its arguments and its value must pickle (``fn`` a module-level function). An exception that
``fn`` raises is raised again here, with the helper's traceback as a note. If the helper dies
(a crash in the code under test) or a call outlives ``limit`` seconds, the helper is killed,
:class:`HelperError` says which, and the next call starts a new helper.

Examples
--------
>>> value, peak = traced_call(bytearray, 10**7)
>>> len(value), peak >= 10**7 - 2**16  # (the helper's own frees during a call lower the peak)
(10000000, True)
"""

from __future__ import annotations

import atexit
import multiprocessing
import os
import pickle
import signal
import traceback
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any, TypeVar

__all__ = ["LIMIT_S", "HelperError", "traced_call"]

T = TypeVar("T")

#: Seconds a call may take before the helper is killed (a backstop: callers bound their own
#: time with ``signal.alarm`` in ``fn``).
LIMIT_S = 1800.0


class HelperError(RuntimeError):
    """The helper process died during a call, or did not answer within the limit."""


def _portable(exc: BaseException) -> BaseException:
    """``exc`` with the helper's traceback as a note, or a RuntimeError if it does not pickle."""
    where = "".join(traceback.format_exception(exc))
    try:
        pickle.dumps(exc)
    except Exception:  # noqa: BLE001 - any exception that cannot cross the pipe
        exc = RuntimeError(f"{type(exc).__name__}: {exc}")
    exc.add_note(f"raised in the traced helper:\n{where}")
    return exc


def _serve(conn: Connection) -> None:
    """The helper's loop: trace from now on, answer calls until the pipe closes."""
    import tracemalloc

    tracemalloc.start()
    while True:
        try:
            fn, args, cwd = conn.recv()
        except EOFError:  # the test process is gone: leave without stopping the tracing
            os._exit(0)
        before = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        kind, value = "value", None
        try:
            os.chdir(cwd)  # (a folder gone since: the caller gets the FileNotFoundError)
            value = fn(*args)
        except BaseException as exc:  # noqa: BLE001 - raised again in the caller
            kind, value = "raised", _portable(exc)
        peak = tracemalloc.get_traced_memory()[1] - before
        try:
            conn.send((kind, value, peak))
        except Exception as exc:  # noqa: BLE001 - a value that does not pickle
            conn.send(("raised", _portable(exc), peak))


class _Helper:
    """One spawned helper process and the pipe to it."""

    def __init__(self) -> None:
        context = multiprocessing.get_context("spawn")
        self.conn, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child,), name="traced-helper")
        self.process.start()
        child.close()

    def call(self, fn: Callable[..., Any], args: tuple[Any, ...], limit: float) -> Any:
        self.conn.send((fn, args, os.getcwd()))
        if not self.conn.poll(limit):
            raise HelperError(f"the traced helper gave no answer in {limit:g} s to {fn!r}")
        try:
            return self.conn.recv()
        except EOFError:
            self.process.join(5)
            raise HelperError(
                f"the traced helper died running {fn!r} (exit code {self.process.exitcode})"
            ) from None

    def kill(self) -> None:
        if self.process.is_alive():
            os.kill(self.process.pid, signal.SIGKILL)
        self.process.join()
        self.conn.close()


_HELPER: list[_Helper] = []  # this process's helper, started by the first call


def _kill_helper() -> None:
    while _HELPER:
        _HELPER.pop().kill()


atexit.register(_kill_helper)


def traced_call(fn: Callable[..., T], *args: Any, limit: float = LIMIT_S) -> tuple[T, int]:
    """``fn(*args)`` run in the traced helper: its value and the peak traced bytes of the call.

    See the module docstring; raises what ``fn`` raised, or :class:`HelperError`.
    """
    if not _HELPER:
        _HELPER.append(_Helper())
    try:
        kind, value, peak = _HELPER[0].call(fn, args, limit)
    except (HelperError, OSError):
        _kill_helper()
        raise
    if kind == "raised":
        raise value
    return value, peak
