"""Where sweep episodes run: in this process, a local process pool, or a Dask cluster.

Every backend is a generator ``iter_*(specs, ...)`` that yields ``(spec, row, lost)`` as episodes
finish, in completion order: ``row`` is the dict returned by
:func:`~fcplan.experiments.play.play_episode` (which records a failing episode as a row with its
error), or ``None`` with ``lost`` saying why the episode produced nothing (its worker process
died, the cluster lost it). Lost episodes are not stored, so a re-run plays them again.

* :func:`iter_serial`: one after another in this process (``jobs=1``).
* :func:`iter_pool`: a :class:`concurrent.futures.ProcessPoolExecutor` with one worker per core by
  default. Workers ignore Ctrl-C; the parent terminates them on Ctrl-C or SIGTERM (episodes in
  flight are lost), and they die with the parent if it is killed
  (:func:`~fcplan.experiments.workers.init_worker`). A worker that dies (killed, crashed) breaks the pool: the pool is restarted and the
  unfinished episodes resubmitted, up to ``max_restarts`` times; after that the rest are lost.
* :func:`iter_dask`: ``address="local"`` starts a :class:`distributed.LocalCluster` (``jobs``
  single-threaded worker processes); any other address connects to an existing scheduler
  (``tcp://host:8786``). Rows come back to this process, which alone writes results, so workers
  need no shared file system. An episode whose workers keep dying (``KilledWorker``) is lost.

Local workers are bounded: at most :data:`WORKERS_PER_CPU` per CPU this process may use (more
only add memory, about 150-600 MB each, to CPU-bound episodes: ``--jobs 99999999999999999999``
on a 720-episode grid started 720 processes), refused in one line by :func:`select_backend`.

Episodes are pure functions of their spec, so every backend gives the same metrics.
:func:`select_backend` picks one the way :func:`~fcplan.experiments.sweep` and
:func:`~fcplan.experiments.compare` both do. By default a backend plays each spec with
:func:`~fcplan.experiments.play.play_episode`; ``play`` substitutes another module-level function
(picklable, so pool workers can run it) that takes a spec and returns its result, as
:func:`~fcplan.experiments.compare` does. Specs need a unique ``key`` attribute.

Examples
--------
>>> from fcplan.experiments.config import load_sweep_config
>>> specs = load_sweep_config({"scenarios": ["practice"], "schedulers": ["idle"],
...                            "seeds": [0, 1], "overrides": {"duration_s": 2}}).episodes()
>>> [(s.seed, row["status"], lost) for s, row, lost in iter_serial(specs)]
[(0, 'ok', None), (1, 'ok', None)]
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Generator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from fcplan.errors import FcplanError
from fcplan.experiments.optional import require
from fcplan.experiments.play import play_episode
from fcplan.experiments.workers import default_jobs, init_worker, stop_workers

__all__ = ["WORKERS_PER_CPU", "iter_dask", "iter_pool", "iter_serial", "max_jobs", "select_backend"]

#: Local worker processes allowed per CPU this process may use (:func:`max_jobs`).
WORKERS_PER_CPU = 4

Outcome = tuple[Any, Any, str | None]
"""``(spec, result, lost)``: the result of ``play(spec)``, or None and why it was lost."""

Runtime = dict[str, Callable[..., Any]]


def iter_serial(
    specs: Sequence[Any],
    runtime: Runtime | None = None,
    *,
    play: Callable[..., Any] = play_episode,
) -> Generator[Outcome, None, None]:
    """Play ``specs`` one after another in this process."""
    for spec in specs:
        yield spec, play(spec), None


def iter_pool(
    specs: Sequence[Any],
    jobs: int,
    runtime: Runtime | None = None,
    *,
    max_restarts: int = 3,
    play: Callable[..., Any] = play_episode,
) -> Generator[Outcome, None, None]:
    """Play ``specs`` on a local process pool of ``jobs`` workers (see the module docstring)."""
    pending = list(specs)
    restarts = 0
    while pending:
        executor = ProcessPoolExecutor(
            max_workers=max(1, min(jobs, len(pending))),
            initializer=init_worker,
            initargs=(runtime or {}, os.getpid()),
        )
        futures: dict[Future, Any] = {}
        finished_keys: set[str] = set()
        broken = False
        try:
            futures = {executor.submit(play, s): s for s in pending}
            waiting = set(futures)
            while waiting and not broken:
                done, waiting = wait(waiting, return_when=FIRST_COMPLETED)
                for fut in done:
                    spec = futures[fut]
                    try:
                        row = fut.result()
                    except BrokenProcessPool:
                        broken = True
                        continue
                    except Exception as exc:  # noqa: BLE001 - e.g. an unpicklable spec
                        finished_keys.add(spec.key)
                        yield spec, None, f"{type(exc).__name__}: {exc}"
                        continue
                    finished_keys.add(spec.key)
                    yield spec, row, None
        except BaseException:
            stop_workers(executor, futures)
            raise
        if not broken:
            executor.shutdown(wait=True)
            return
        stop_workers(executor, futures)
        pending = [s for s in pending if s.key not in finished_keys]
        restarts += 1
        if restarts > max_restarts:
            for spec in pending:
                yield spec, None, f"worker processes died {restarts} times; giving up"
            return


def iter_dask(
    specs: Sequence[Any],
    address: str,
    jobs: int,
    runtime: Runtime | None = None,
    *,
    play: Callable[..., Any] = play_episode,
) -> Generator[Outcome, None, None]:
    """Play ``specs`` on a Dask cluster (``address="local"``: a new LocalCluster of ``jobs``
    workers)."""
    distributed = require("distributed", "dask")
    cluster = None
    try:
        if address == "local":
            cluster = distributed.LocalCluster(
                n_workers=jobs,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
            client = distributed.Client(cluster)
        else:
            client = distributed.Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as exc:
        if cluster is not None:
            cluster.close()
        raise FcplanError(
            f"--dask {address}: cannot connect to a Dask scheduler ({type(exc).__name__}: {exc})"
        ) from None
    futures: list[Any] = []
    try:
        futures = client.map(play, list(specs), runtime=runtime or None, pure=False)
        by_key = {f.key: s for f, s in zip(futures, specs, strict=True)}
        for fut in distributed.as_completed(futures):
            spec = by_key[fut.key]
            try:
                row = fut.result()
            except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker
                yield spec, None, f"{type(exc).__name__}: {exc}"
            else:
                yield spec, row, None
            fut.release()
    finally:
        try:
            if futures:
                client.cancel(futures)
            client.close()
        finally:
            if cluster is not None:
                cluster.close()


def max_jobs() -> int:
    """The most local worker processes a sweep or comparison may start here:
    :data:`WORKERS_PER_CPU` per CPU this process may use."""
    return WORKERS_PER_CPU * default_jobs()


def select_backend(
    specs: Sequence[Any],
    jobs: int,
    runtime: Runtime | None = None,
    *,
    dask: str | None = None,
    play: Callable[..., Any] = play_episode,
) -> tuple[str, Generator[Outcome, None, None]]:
    """The backend for ``specs`` and its outcomes: Dask if ``dask`` is given, this process for
    ``jobs=1`` or a single spec, else a pool of ``min(jobs, len(specs))`` workers.

    Returns
    -------
    name : str
        ``"serial"``, ``"pool:<workers>"`` or ``"dask:<address>"``.
    outcomes : generator of Outcome
        Close it when done early: that stops the workers.

    Raises
    ------
    FcplanError
        ``jobs`` above :func:`max_jobs` for local workers (a pool or a local Dask cluster).

    Examples
    --------
    >>> name, outcomes = select_backend([], jobs=4)
    >>> name, list(outcomes)
    ('serial', [])
    """
    workers = jobs if dask == "local" else min(jobs, len(specs)) if dask is None else 1
    if workers > max_jobs():
        raise FcplanError(
            f"--jobs asks for {workers} worker processes; at most {max_jobs()} may run here "
            f"({WORKERS_PER_CPU} per CPU this process may use)"
        )
    if dask is not None:
        name = f"dask:{dask}"
        if not specs:  # no cluster for nothing to do
            return name, iter_serial(specs, runtime, play=play)
        return name, iter_dask(specs, dask, jobs, runtime, play=play)
    if jobs == 1 or len(specs) <= 1:
        return "serial", iter_serial(specs, runtime, play=play)
    return f"pool:{min(jobs, len(specs))}", iter_pool(specs, jobs, runtime, play=play)
