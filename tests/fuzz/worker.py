"""Run reader calls in forked children, each with a time and memory bound, and classify them.

Each call runs in a child forked from this (single-threaded) process: the child measures its own
peak resident memory with ``resource.getrusage`` before and after the call, under an address-space
limit (so a runaway allocation fails fast instead of swapping the machine) and an alarm. The
outcome is one of

* ``loaded``: the reader returned a value;
* ``clean``: it raised its own error (``LegacyError``, ``RecordingError``, ``ResultsError``);
* ``traceback``: it raised anything else;
* ``hang``: it did not finish within the time bound (the child is killed);
* ``oom``: it ran out of the memory bound (``MemoryError``) or grew past it;
* ``crash``: the child died (a signal: SIGSEGV, abort, ...).

Usage (POSIX)::

    python -m tests.fuzz.worker CASES.json [--timeout S] [--memory-mb MB]

``CASES.json`` holds ``[[name, target, path], ...]`` (targets: see
:func:`tests.fuzz.cases.load_target`); one JSON object per case is printed.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import select
import signal
import sys
import time
from typing import Any

from tests.deadline import deadline
from tests.fuzz.cases import clean_error, load_target

#: memory the child may grow by before the call counts as ``oom``
GROWTH_MB = 256


class _HangError(Exception):
    pass


def _child(target: str, path: str, timeout: float, memory_mb: int) -> dict[str, Any]:
    import resource  # (POSIX only: imported here so that the module imports everywhere)

    with open("/proc/self/statm") as f:
        vm = int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    limit = vm + memory_mb * 2**20
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    message = ""
    try:
        with deadline(timeout, _HangError):
            load_target(target, path)
        result = "loaded"
    except _HangError:
        result = "hang"
    except MemoryError:
        result = "oom"
    except clean_error(target) as exc:
        result, message = "clean", str(exc)
    except BaseException as exc:  # noqa: BLE001 - what a fuzzer looks for
        result, message = "traceback", f"{type(exc).__name__}: {exc}"
    growth = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base) / 1024
    if growth > memory_mb and result != "hang":
        result = "oom"
    return {
        "outcome": result,
        "message": message[:300],
        "seconds": round(time.perf_counter() - t0, 3),
        "rss_growth_mb": round(growth, 1),
    }


def run_isolated(
    target: str, path: str, timeout: float = 30.0, memory_mb: int = GROWTH_MB
) -> dict[str, Any]:
    """Call the reader of ``target`` on ``path`` in a forked child; its outcome (module doc)."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # child
        os.close(r)
        try:
            out = _child(target, path, timeout, memory_mb)
        except BaseException as exc:  # noqa: BLE001
            out = {"outcome": "traceback", "message": repr(exc)[:300]}
        os.write(w, json.dumps(out).encode())
        os._exit(0)
    os.close(w)
    deadline = time.monotonic() + timeout + 10
    chunks = []
    while True:
        left = deadline - time.monotonic()
        ready, _, _ = select.select([r], [], [], max(left, 0))
        if not ready:  # stuck outside Python code: kill it
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            os.close(r)
            return {"outcome": "hang", "message": "killed", "seconds": timeout}
        chunk = os.read(r, 65536)
        if not chunk:
            break
        chunks.append(chunk)
    os.close(r)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        sig = signal.Signals(os.WTERMSIG(status)).name
        return {"outcome": "crash", "message": sig}
    return json.loads(b"".join(chunks) or b'{"outcome": "crash", "message": "no report"}')


def _warm_up() -> None:
    """Import what the readers import lazily (pandas, pyarrow), so children measure the call."""
    for name in ("pandas", "pyarrow.parquet", "fcplan.experiments.results", "fcplan.legacy"):
        with contextlib.suppress(ImportError):
            __import__(name)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases")
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--memory-mb", type=int, default=GROWTH_MB)
    args = ap.parse_args(argv)
    with open(args.cases) as f:
        cases = json.load(f)
    _warm_up()
    for name, target, path in cases:
        out = run_isolated(target, path, args.timeout, args.memory_mb)
        print(json.dumps({"name": name, "target": target, **out}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
