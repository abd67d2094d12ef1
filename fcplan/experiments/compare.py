"""Compare schedulers: run every (scenario, scheduler, seed) episode and tabulate the scores.

:func:`compare` plays the full grid ``scenarios x schedulers x seeds`` with
:func:`fcplan.run_episode`, in parallel over the machine's cores on the same backends as sweeps
(:func:`fcplan.experiments.backends.select_backend`: this process for ``jobs=1``, else a local
process pool that is restarted if a worker dies), and returns a
:class:`~fcplan.experiments.comparison.ComparisonResult` (per-episode rows in grid order, a
per-scheduler table with confidence intervals, text, CSV and JSON output). Workers send back each
episode's summary numbers and per-replan solve times, never the trace.

Reproducibility. Every episode is seeded by its seed alone, so the scores do not depend on
``jobs``, on the worker an episode ran in, or on the order episodes finished: a serial and a
parallel comparison give identical score columns. The timing columns (solve times, wall time) are
measurements and vary from run to run.

Failures. A scheduler that raises or returns an invalid plan does not fail its episode (the
episode loop falls back to greedy for that replan and counts a fallback). An episode that fails
anyway (an exception escaping :func:`fcplan.run_episode`) is recorded with its error message and
counted in the ``errors`` column, and so is an episode lost because its worker process kept dying;
the other episodes run on. Scheduler names are checked, and every scheduler is constructed once
with its default settings, before any episode runs, so a typo or a scheduler that cannot be built
fails at once with a one-line :class:`fcplan.FcplanError`. Ctrl-C (:class:`KeyboardInterrupt`)
cancels the pending episodes, stops the workers and re-raises.

Examples
--------
>>> from fcplan.experiments import compare
>>> from fcplan.scenario import load_scenario
>>> short = load_scenario(3).replace(duration_s=10)
>>> result = compare([short], ["greedy", "idle"], [0, 1], jobs=1)
>>> [(r["scheduler"], r["episodes"], r["errors"]) for r in result.table()]
[('greedy', 2, 0), ('idle', 2, 0)]
>>> result.episodes[0]["scenario"], result.episodes[0]["seed"]
('#3', 0)
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan.errors import FcplanError, UnknownNameError
from fcplan.experiments.backends import select_backend
from fcplan.experiments.comparison import ComparisonResult
from fcplan.experiments.progress import ProgressPrinter
from fcplan.experiments.ranges import RangeError, parse_range
from fcplan.experiments.tables import SCORE_COLUMNS
from fcplan.experiments.workers import default_jobs, runtime_factories

__all__ = [
    "compare",
    "ComparisonResult",
    "parse_range",
    "RangeError",
    "ProgressPrinter",
    "METRICS",
]

METRICS: dict[str, tuple[str, str]] = {c.key: (c.name, c.label) for c in SCORE_COLUMNS}
"""Table metrics: short name -> (episode key, column label in :meth:`ComparisonResult.format`),
from :data:`fcplan.experiments.tables.SCORE_COLUMNS`."""


# --------------------------------------------------------------------------------------------
# validation


def _check_schedulers(names: Sequence[str]) -> list[str]:
    """Validate scheduler names and build each once; a clear one-line error otherwise."""
    from fcplan.scheduling import available_schedulers, make_scheduler

    if isinstance(names, str):
        names = [names]
    names = list(dict.fromkeys(names))
    if not names:
        raise FcplanError("no schedulers to compare")
    known = available_schedulers()
    for name in names:
        if not isinstance(name, str):
            raise FcplanError(f"schedulers are given by registered name, got {name!r}")
        if name.split(":")[0].strip() not in known:
            raise UnknownNameError(
                f"unknown scheduler {name!r}; known schedulers: {', '.join(known)}"
            )
        try:
            make_scheduler(name)
        except FcplanError:
            raise
        except Exception as exc:  # noqa: BLE001 - report any construction failure in one line
            raise FcplanError(
                f"scheduler {name!r} cannot be created: {type(exc).__name__}: {exc}"
            ) from exc
    return names


def _load_scenarios(scenarios: Any) -> list[Any]:
    from fcplan.scenario import Scenario, load_scenario

    if isinstance(scenarios, (str, int, Scenario)):
        scenarios = [scenarios]
    out = [s if isinstance(s, Scenario) else load_scenario(s) for s in scenarios]
    if not out:
        raise FcplanError("no scenarios to compare")
    return out


def _check_seeds(seeds: Any) -> list[int]:
    if isinstance(seeds, (int, np.integer)):
        seeds = [seeds]
    out = []
    for s in seeds:
        if isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 0:
            raise FcplanError(f"seeds must be integers >= 0, got {s!r}")
        out.append(int(s))
    if not out:
        raise FcplanError("no seeds to compare")
    return list(dict.fromkeys(out))


def _positive(name: str, value: Any) -> float:
    """``value`` as a finite number > 0, or a one-line error naming ``name``."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise FcplanError(f"{name} must be a number > 0, got {value!r}")
    return v


# --------------------------------------------------------------------------------------------
# episodes


@dataclass(frozen=True, slots=True)
class _Task:
    index: int
    scenario: Any  # Scenario
    scheduler: str
    seed: int
    time_limit: float | None
    replan_period: float

    @property
    def key(self) -> str:
        """Unique name of the task for the backends (its grid index)."""
        return str(self.index)


def _identity(task: _Task) -> dict[str, Any]:
    """The first columns of a task's episode row."""
    return {
        "scenario": task.scenario.name,
        "difficulty": task.scenario.difficulty,
        "scheduler": task.scheduler,
        "seed": task.seed,
    }


def _failed_row(task: _Task, error: str) -> dict[str, Any]:
    """The episode row of a task that produced no result, with its one-line error."""
    return {**_identity(task), "error": error.replace("\n", " ")}


def _run_task(task: _Task) -> tuple[int, dict[str, Any], list[float]]:
    """Play one episode; return its summary row and per-replan solve times (ms)."""
    try:
        res = run_episode(
            task.scenario,
            task.scheduler,
            seed=task.seed,
            replan_period=task.replan_period,
            time_limit=task.time_limit,
        )
        summary = res.summary()
        times = (res.solve_times_s * 1e3).tolist()
    except Exception as exc:  # noqa: BLE001 - one failed episode must not stop the comparison
        return task.index, _failed_row(task, f"{type(exc).__name__}: {exc}"), []
    for k in ("scenario", "seed", "scheduler"):  # the registered name is the row's label
        summary.pop(k, None)
    return task.index, {**_identity(task), **summary, "error": ""}, times


def run_episode(*args: Any, **kwargs: Any) -> Any:
    """:func:`fcplan.run_episode` (a module-level name, so tests can substitute a failing one)."""
    from fcplan.episode import run_episode as _run

    return _run(*args, **kwargs)


# --------------------------------------------------------------------------------------------
# compare


def compare(
    scenarios: Any,
    schedulers: Sequence[str],
    seeds: Any,
    *,
    jobs: int | None = None,
    time_limit: float | None = None,
    replan_period: float = 1.0,
    progress: Callable[[int, int, dict[str, Any]], None] | None = None,
) -> ComparisonResult:
    """Run every (scenario, scheduler, seed) episode and collect the scores.

    Parameters
    ----------
    scenarios : sequence of Scenario, str or int
        Scenario objects (e.g. ``load_scenario(3).replace(duration_s=20)``) or names/paths for
        :func:`fcplan.load_scenario`; all are loaded (and so validated) before anything runs.
    schedulers : sequence of str
        Registered scheduler names (:func:`fcplan.available_schedulers`). Each is built once up
        front with its default settings; every episode builds its own instance.
    seeds : sequence of int
        Seeds >= 0; each (scenario, scheduler) pair is played once per seed.
    jobs : int, optional
        Worker processes (default: the CPUs this process may use). ``jobs=1`` runs the episodes
        in this process, one after another.
    time_limit : float, optional
        Seconds per scheduler call (default: each scheduler's own).
    replan_period : float
        Simulated seconds between periodic replans.
    progress : callable, optional
        Called as ``progress(done, total, row)`` after each episode (``row`` is its episode
        dict), in completion order. :class:`ProgressPrinter` prints throttled progress lines.

    Returns
    -------
    ComparisonResult

    Raises
    ------
    fcplan.UnknownNameError
        An unknown scenario or scheduler name.
    fcplan.FcplanError
        A scheduler that cannot be constructed, a bad seed, ``jobs``, ``time_limit`` or
        ``replan_period``. Nothing has run when these are raised.
    KeyboardInterrupt
        After cancelling the pending episodes and stopping the workers.
    """
    scen = _load_scenarios(scenarios)
    names = _check_schedulers(schedulers)
    seed_list = _check_seeds(seeds)
    tl = None if time_limit is None else _positive("time_limit", time_limit)
    rp = _positive("replan_period", replan_period)
    if jobs is None:
        jobs = default_jobs()
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise FcplanError(f"jobs must be an integer >= 1, got {jobs!r}")
    tasks = [
        _Task(len(seed_list) * (i * len(names) + j) + k, s, name, seed, tl, rp)
        for i, s in enumerate(scen)
        for j, name in enumerate(names)
        for k, seed in enumerate(seed_list)
    ]
    jobs = int(min(jobs, len(tasks)))
    t0 = time.perf_counter()
    rows, times = _play(tasks, jobs, runtime_factories(names), progress)
    return ComparisonResult(
        episodes=rows,
        solve_times_ms=times,
        scenarios=[s.name for s in scen],
        schedulers=names,
        seeds=seed_list,
        settings={"time_limit": tl, "replan_period": rp, "jobs": jobs},
        wall_time_s=time.perf_counter() - t0,
    )


def _play(
    tasks: list[_Task],
    jobs: int,
    runtime: dict[str, Callable[..., Any]],
    progress: Callable[[int, int, dict[str, Any]], None] | None,
) -> tuple[list[dict[str, Any]], list[list[float]]]:
    """Play ``tasks`` on a backend; return their rows and solve times in grid order."""
    total = len(tasks)
    rows: list[dict[str, Any]] = [{} for _ in range(total)]
    times: list[list[float]] = [[] for _ in range(total)]
    _, outcomes = select_backend(tasks, jobs, runtime, play=_run_task)
    try:
        for done, (task, result, lost) in enumerate(outcomes, 1):
            if result is None:  # its worker process kept dying, or the task could not be sent
                rows[task.index] = _failed_row(task, str(lost))
            else:
                idx, rows[idx], times[idx] = result
            if progress is not None:
                progress(done, total, rows[task.index])
    finally:
        outcomes.close()
    return rows, times
