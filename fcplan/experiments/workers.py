"""Worker processes shared by :func:`~fcplan.experiments.compare` and
:func:`~fcplan.experiments.sweep`.

Episodes run in worker processes that ignore Ctrl-C (the parent handles it and stops them), that
know the schedulers registered at run time in the parent (:func:`fcplan.register_scheduler`),
which a fresh process would not, and that die with their parent: on Linux the kernel sends them
SIGKILL when it dies (``prctl(PR_SET_PDEATHSIG)``), and everywhere a watchdog thread ends the
worker within :data:`WATCHDOG_PERIOD_S` of its parent's death (the parent pid stops existing or
the worker is re-parented). So ``kill -9`` of a sweep or a comparison leaves no worker holding its pipes.

Examples
--------
>>> default_jobs() >= 1
True
>>> runtime_factories(["greedy"])
{}
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

import numpy as np

from fcplan.errors import FcplanError

__all__ = [
    "MAX_JOBS",
    "WATCHDOG_PERIOD_S",
    "check_dask",
    "check_jobs",
    "default_jobs",
    "die_with_parent",
    "init_worker",
    "register_runtime",
    "runtime_factories",
    "stop_workers",
]

#: Seconds between two looks of a worker's watchdog at its parent.
WATCHDOG_PERIOD_S = 1.0
_PR_SET_PDEATHSIG = 1


def default_jobs() -> int:
    """The number of CPUs this process may use (one worker per core)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


#: Most worker processes a local pool may start (each is a Python process of ~100 MB).
MAX_JOBS = 1024


def check_dask(dask: Any) -> str | None:
    """``dask`` (None: no Dask; ``"local"``: a LocalCluster; else a scheduler address) checked,
    or a one-line error.

    Examples
    --------
    >>> check_dask(None), check_dask("local")
    (None, 'local')
    """
    if dask is not None and (not isinstance(dask, str) or not dask.strip()):
        raise FcplanError(f"dask must be 'local' or a scheduler address, got {dask!r:.60}")
    return dask


def check_jobs(jobs: Any) -> int:
    """``jobs`` (None: :func:`default_jobs`) as an int in ``1..MAX_JOBS``, or a one-line error.

    Examples
    --------
    >>> check_jobs(2), check_jobs(None) >= 1
    (2, True)
    """
    if jobs is None:
        return default_jobs()
    ok = not isinstance(jobs, bool) and isinstance(jobs, (int, np.integer))
    if not ok or not 1 <= jobs <= MAX_JOBS:
        raise FcplanError(f"jobs must be an integer in 1..{MAX_JOBS}, got {jobs!r:.40}")
    return int(jobs)


def runtime_factories(names: Sequence[str]) -> dict[str, Callable[..., Any]]:
    """Run-time registrations (:func:`fcplan.register_scheduler`) among ``names`` (names may be
    specs such as ``"greedy:x=1"``), which workers must register again."""
    from fcplan import scheduling

    runtime = getattr(scheduling, "_RUNTIME", {})
    out = {}
    for n in names:
        base = n.split(":")[0].strip()
        if base in runtime:
            out[base] = runtime[base]
    return out


def register_runtime(runtime: dict[str, Callable[..., Any]]) -> None:
    """Register ``runtime`` factories in this process (a no-op for an empty dict)."""
    if runtime:
        from fcplan.scheduling import register_scheduler

        for name, factory in runtime.items():
            register_scheduler(name, factory)


def init_worker(runtime: dict[str, Callable[..., Any]], parent: int | None = None) -> None:
    """Process-pool initializer: leave Ctrl-C to the parent, take SIGTERM's default action (the
    parent's handler is inherited through fork), die with ``parent`` (:func:`die_with_parent`)
    and re-register run-time schedulers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if parent is not None:
        die_with_parent(parent)
    register_runtime(runtime)


def die_with_parent(parent: int) -> None:
    """End this process when ``parent`` dies.

    On Linux, ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` asks the kernel to kill this process when the
    thread that forked it exits; and a daemon thread checks every :data:`WATCHDOG_PERIOD_S` that
    ``parent`` is alive and this process was not re-parented, and else ends it with
    ``os._exit(1)`` (the portable fallback, which also covers a parent whose forking thread ended
    early). The process that forked this one may be ``parent`` itself or a fork server it started
    (the ``forkserver`` start method). If ``parent`` is already gone, this process ends at once.
    """
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no usable libc: the thread acts
            pass
    ppid = os.getppid()  # ``parent`` itself, or a fork server it started
    if not _parent_alive(parent, ppid):
        os._exit(1)
    threading.Thread(
        target=_watch, args=(parent, ppid), name="fcplan-parent-watchdog", daemon=True
    ).start()


def _parent_alive(parent: int, ppid: int) -> bool:
    """``parent`` exists and this process was not re-parented (``ppid``, its parent, lives)."""
    if os.getppid() != ppid:
        return False
    try:
        os.kill(parent, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - alive, another user's
        return True
    return True


def _watch(parent: int, ppid: int) -> None:  # pragma: no cover - runs in pool workers
    while _parent_alive(parent, ppid):
        time.sleep(WATCHDOG_PERIOD_S)
    os._exit(1)


def stop_workers(executor: ProcessPoolExecutor, futures: Iterable[Future]) -> None:
    """Cancel ``futures`` and terminate the pool's processes now (episodes in flight are lost)."""
    for f in futures:
        f.cancel()
    terminate = getattr(executor, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:  # pragma: no cover - depends on the Python version
        terminate()
        return
    procs = list((getattr(executor, "_processes", None) or {}).values())
    for p in procs:
        if p.is_alive():
            p.terminate()
    executor.shutdown(wait=True, cancel_futures=True)
    for p in procs:
        p.join(timeout=5)
