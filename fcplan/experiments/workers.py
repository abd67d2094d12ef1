"""Worker processes shared by :func:`~fcplan.experiments.compare` and
:func:`~fcplan.experiments.sweep`.

Episodes run in worker processes that ignore Ctrl-C (the parent handles it and stops them), and
that know the schedulers registered at run time in the parent
(:func:`fcplan.register_scheduler`), which a fresh process would not.

Examples
--------
>>> default_jobs() >= 1
True
>>> runtime_factories(["greedy"])
{}
"""

from __future__ import annotations

import os
import signal
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

__all__ = ["default_jobs", "init_worker", "register_runtime", "runtime_factories", "stop_workers"]


def default_jobs() -> int:
    """The number of CPUs this process may use (one worker per core)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


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


def init_worker(runtime: dict[str, Callable[..., Any]]) -> None:
    """Process-pool initializer: leave Ctrl-C to the parent; re-register run-time schedulers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    register_runtime(runtime)


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
