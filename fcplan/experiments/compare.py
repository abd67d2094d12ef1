"""Compare schedulers: run every (scenario, scheduler, seed) episode and tabulate the scores.

:func:`compare` plays the full grid ``scenarios x schedulers x seeds`` with
:func:`fcplan.run_episode`, in parallel over the machine's cores on the same backends as sweeps
(:func:`fcplan.experiments.backends.select_backend`: this process for ``jobs=1``, else a local
process pool that is restarted if a worker dies), and returns a
:class:`~fcplan.experiments.comparison.ComparisonResult` (per-episode rows in grid order, a
per-scheduler table with confidence intervals, text, CSV and JSON output). Workers send back each
episode's summary numbers and per-replan solve times, never the trace.

Reproducibility. Every episode is seeded by its seed alone, and by default every scheduler that
has a deterministic mode runs in it (:func:`fcplan.scheduling.supports_deterministic`: the
``deterministic=True`` setting is added to its spec unless the spec sets ``deterministic``
itself), so the scores do not depend on ``jobs``, on machine load, on the worker an episode ran
in, or on the order episodes finished: a serial and a parallel comparison give identical score
columns. The wall-time mode (time limits that bind on the wall clock) is an explicit choice:
``deterministic=False`` (``fcplan compare --wall-time``) or ``deterministic=false`` in one
scheduler's spec; every episode row records it in its ``deterministic`` column (the scheduler's
own ``deterministic`` attribute: True for greedy, idle and random, which never read the clock).
The timing columns (solve times, wall time) are measurements and vary from run to run.

Failures. A scheduler that raises or returns an invalid plan does not fail its episode (the
episode loop falls back to greedy for that replan and counts a fallback). An episode that fails
anyway (an exception escaping :func:`fcplan.run_episode`) is recorded with its error message and
counted in the ``errors`` column, and so is an episode lost because its worker process kept dying;
the other episodes run on. An episode whose scheduler fell back on more than half of its replans
is flagged (``fallback_majority``): its score is mostly greedy's. Scheduler specs are checked, and
every scheduler is constructed once with its settings, before any episode runs (through
:func:`fcplan.make_scheduler`, the one validation path), so a typo or a bad setting fails at once
with a one-line :class:`fcplan.FcplanError`. Ctrl-C (:class:`KeyboardInterrupt`)
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

from fcplan.errors import FcplanError
from fcplan.experiments.backends import select_backend
from fcplan.experiments.comparison import ComparisonResult
from fcplan.experiments.progress import ProgressPrinter
from fcplan.experiments.ranges import RangeError, parse_range
from fcplan.experiments.tables import SCORE_COLUMNS, fallback_majority
from fcplan.experiments.workers import default_jobs, runtime_factories

__all__ = [
    "compare",
    "fallback_majority",
    "scheduler_variant",
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


@dataclass(frozen=True, slots=True)
class _Variant:
    """A scheduler as given (``label``, the spec) and as built (registered name and settings)."""

    label: str
    name: str
    settings: dict[str, Any]


def scheduler_variant(spec: str, *, deterministic: bool = True) -> tuple[str, dict[str, Any]]:
    """The registered name and settings of ``spec``, checked by building the scheduler once.

    ``deterministic=True`` adds ``deterministic=True`` to the settings of a scheduler that
    supports it (:func:`fcplan.scheduling.supports_deterministic`) unless the spec sets it.

    Raises
    ------
    fcplan.FcplanError
        The one-line error of :func:`fcplan.make_scheduler` (unknown name or setting, a value
        the scheduler refuses, a malformed spec).

    Examples
    --------
    >>> scheduler_variant("routing:time_limit=0.05")
    ('routing', {'time_limit': 0.05, 'deterministic': True})
    >>> scheduler_variant("greedy:route_length=2", deterministic=False)
    ('greedy', {'route_length': 2})
    """
    from fcplan.scheduling import make_scheduler, parse_scheduler_spec, supports_deterministic

    if not isinstance(spec, str):
        raise FcplanError(f"schedulers are given by registered name, got {spec!r}")
    name, settings = parse_scheduler_spec(spec)
    if deterministic and "deterministic" not in settings and supports_deterministic(name):
        settings["deterministic"] = True
    make_scheduler(name, **settings)
    return name, settings


def _check_schedulers(names: Sequence[str], deterministic: bool) -> list[_Variant]:
    """Check every spec and build each scheduler once (a one-line error otherwise)."""
    if isinstance(names, str):
        names = [names]
    names = list(dict.fromkeys(names))
    if not names:
        raise FcplanError("no schedulers to compare")
    out = []
    for spec in names:
        name, settings = scheduler_variant(spec, deterministic=deterministic)
        out.append(_Variant(spec, name, settings))
    return out


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
    variant: _Variant
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
        "scheduler": task.variant.label,
        "seed": task.seed,
    }


def _failed_row(task: _Task, error: str) -> dict[str, Any]:
    """The episode row of a task that produced no result, with its one-line error."""
    return {**_identity(task), "error": error.replace("\n", " ")}


def _run_task(task: _Task) -> tuple[int, dict[str, Any], list[float]]:
    """Play one episode; return its summary row and per-replan solve times (ms)."""
    from fcplan.scheduling import make_scheduler

    try:
        scheduler = make_scheduler(task.variant.name, **task.variant.settings)
        res = run_episode(
            task.scenario,
            scheduler,
            seed=task.seed,
            replan_period=task.replan_period,
            time_limit=task.time_limit,
        )
        summary = res.summary()
        times = (res.solve_times_s * 1e3).tolist()
    except Exception as exc:  # noqa: BLE001 - one failed episode must not stop the comparison
        return task.index, _failed_row(task, f"{type(exc).__name__}: {exc}"), []
    for k in ("scenario", "seed", "scheduler"):  # the spec as given is the row's label
        summary.pop(k, None)
    mode = {
        "deterministic": bool(getattr(scheduler, "deterministic", False)),
        "fallback_majority": fallback_majority(summary),
    }
    return task.index, {**_identity(task), **summary, **mode, "error": ""}, times


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
    deterministic: bool = True,
) -> ComparisonResult:
    """Run every (scenario, scheduler, seed) episode and collect the scores.

    Parameters
    ----------
    scenarios : sequence of Scenario, str or int
        Scenario objects (e.g. ``load_scenario(3).replace(duration_s=20)``) or names/paths for
        :func:`fcplan.load_scenario`; all are loaded (and so validated) before anything runs.
    schedulers : sequence of str
        Scheduler specs: registered names (:func:`fcplan.available_schedulers`), with settings as
        ``name:key=value``. Each is built once up front; every episode builds its own instance.
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
    deterministic : bool
        Run every scheduler that has a deterministic mode in it (the default, see the module
        docstring); False is the wall-time mode.

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
    if not isinstance(deterministic, bool):
        raise FcplanError(f"deterministic must be True or False, got {deterministic!r}")
    variants = _check_schedulers(schedulers, deterministic)
    seed_list = _check_seeds(seeds)
    tl = None if time_limit is None else _positive("time_limit", time_limit)
    rp = _positive("replan_period", replan_period)
    if jobs is None:
        jobs = default_jobs()
    if isinstance(jobs, bool) or not isinstance(jobs, (int, np.integer)) or jobs < 1:
        raise FcplanError(f"jobs must be an integer >= 1, got {jobs!r}")
    tasks = [
        _Task(len(seed_list) * (i * len(variants) + j) + k, s, v, seed, tl, rp)
        for i, s in enumerate(scen)
        for j, v in enumerate(variants)
        for k, seed in enumerate(seed_list)
    ]
    jobs = int(min(jobs, len(tasks)))
    t0 = time.perf_counter()
    rows, times = _play(tasks, jobs, runtime_factories([v.name for v in variants]), progress)
    settings = {"time_limit": tl, "replan_period": rp, "jobs": jobs, "deterministic": deterministic}
    return ComparisonResult(
        episodes=rows,
        solve_times_ms=times,
        scenarios=[s.name for s in scen],
        schedulers=[v.label for v in variants],
        seeds=seed_list,
        settings=settings,
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
