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

import contextlib
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fcplan.errors import FcplanError
from fcplan.experiments.autoseeds import AutoSeeds
from fcplan.experiments.backends import select_backend
from fcplan.experiments.comparison import ComparisonResult
from fcplan.experiments.config import short_hash
from fcplan.experiments.progress import Progress, ProgressCallback, episode_progress
from fcplan.experiments.ranges import RangeError, parse_range
from fcplan.experiments.tables import SCORE_COLUMNS, check_metric, fallback_majority
from fcplan.experiments.workers import check_jobs, runtime_factories
from fcplan.mission import check_replan_period, check_time_limit

__all__ = [
    "compare",
    "fallback_majority",
    "scheduler_variant",
    "study_hash",
    "ComparisonResult",
    "parse_range",
    "RangeError",
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
    from fcplan.scheduling import deterministic_settings, make_scheduler, parse_scheduler_spec

    if not isinstance(spec, str):
        raise FcplanError(f"schedulers are given by registered name, got {spec!r}")
    name, settings = parse_scheduler_spec(spec)
    if deterministic:
        settings = deterministic_settings(name, settings)
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
    from fcplan.world import seed_list

    out = seed_list(seeds)
    if not out:
        raise FcplanError("seeds: no seeds to compare")
    return out


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
        "scheduler_name": task.variant.name,
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
    progress: Progress = True,
    deterministic: bool = True,
    metrics: Sequence[str] = ("manual.final_score",),
    max_seeds: int = 50,
    seed_batch: int = 5,
    resume: ComparisonResult | str | os.PathLike[str] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
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
    seeds : sequence of int, or ``"auto"``
        Seeds >= 0; each (scenario, scheduler) pair is played once per seed. ``"auto"`` plays
        seeds 0, 1, 2, ... in batches of ``seed_batch`` until every pair of schedulers is
        resolved on the headline metric, or ``max_seeds`` seeds are played
        (:mod:`fcplan.experiments.autoseeds`; the result's ``stopped`` says why it stopped).
    jobs : int, optional
        Worker processes (default: the CPUs this process may use). ``jobs=1`` runs the episodes
        in this process, one after another.
    time_limit : float, optional
        Seconds per scheduler call (default: each scheduler's own).
    replan_period : float
        Simulated seconds between periodic replans.
    progress : bool or callable
        ``True`` (default): a progress bar on stderr counted in episodes
        (:mod:`fcplan.experiments.progress`); ``False``: silent; or a ``progress(done, total,
        row)`` callback called after each episode in completion order.
    deterministic : bool
        Run every scheduler that has a deterministic mode in it (the default, see the module
        docstring); False is the wall-time mode.
    metrics : sequence of str
        Metrics with a paired table (:meth:`ComparisonResult.comparisons`); the first is the
        headline (fractions of the oracle, the ``"auto"`` stopping rule).
    max_seeds, seed_batch : int
        The cap and the batch of ``seeds="auto"``.
    resume : ComparisonResult or path, optional
        A comparison of the same study (same scenarios, schedulers and settings; checked by its
        ``study_hash``) whose completed episodes are reused instead of played again. A path that
        does not exist yet is ignored (nothing to resume).
    checkpoint : path, optional
        Where the JSON of the comparison so far is written after each batch of ``"auto"``
        (resume from it after an interruption).

    Returns
    -------
    ComparisonResult

    Raises
    ------
    fcplan.UnknownNameError
        An unknown scenario or scheduler name.
    fcplan.FcplanError
        A scheduler that cannot be constructed, a bad seed, ``jobs``, ``time_limit``,
        ``replan_period``, metric or auto setting, or a ``resume`` of another study. Nothing has
        run when these are raised.
    KeyboardInterrupt
        After cancelling the pending episodes and stopping the workers.
    """
    scen = _load_scenarios(scenarios)
    if not isinstance(deterministic, bool):
        raise FcplanError(f"deterministic must be True or False, got {deterministic!r}")
    variants = _check_schedulers(schedulers, deterministic)
    metric_list = _check_metrics(metrics)
    auto = AutoSeeds(seed_batch, max_seeds, metric_list[0]) if _is_auto(seeds) else None
    seed_list = [] if auto else _check_seeds(seeds)
    tl = check_time_limit(time_limit)
    rp = check_replan_period(replan_period)
    jobs = _check_jobs(jobs)
    settings = {"time_limit": tl, "replan_period": rp, "deterministic": deterministic}
    study = study_hash(scen, variants, settings)
    runner = _Runner(scen, variants, tl, rp, jobs, episode_progress(progress, "compare"))
    runner.reuse(_resumed(resume, study))
    meta = {**settings, "jobs": jobs, "study_hash": study, "metrics": metric_list}
    t0 = time.perf_counter()
    try:
        if auto is None:
            runner.play(seed_list)
            return runner.result(seed_list, meta, time.perf_counter() - t0)
        return _auto(runner, auto, meta, t0, checkpoint)
    finally:
        close = getattr(runner.progress, "close", None)
        if close is not None:
            close()


def _auto(
    runner: _Runner,
    auto: AutoSeeds,
    meta: dict[str, Any],
    t0: float,
    checkpoint: str | os.PathLike[str] | None,
) -> ComparisonResult:
    """Play batches of seeds until :meth:`AutoSeeds.decide` stops; the result says why."""
    meta = {**meta, "seeds": "auto", "seed_batch": auto.batch, "max_seeds": auto.max_seeds}
    look = 0
    while True:
        look += 1
        seeds = auto.seeds(look)
        runner.play(seeds)
        result = runner.result(seeds, meta, time.perf_counter() - t0)
        pairs = result.comparisons(
            auto.metric, confidence=auto.look_confidence, alpha=auto.look_alpha
        )
        decision = auto.decide(pairs, look)
        result.stopped = decision.reason if decision.stop else ""
        if checkpoint is not None:
            _write_checkpoint(result, checkpoint)
        if decision.stop:
            return result


def _check_jobs(jobs: Any) -> int:
    """``jobs`` (default: the CPUs this process may use), or a one-line error."""
    return check_jobs(jobs)


def _is_auto(seeds: Any) -> bool:
    return isinstance(seeds, str) and seeds.strip().lower() == "auto"


def _check_metrics(metrics: Sequence[str]) -> list[str]:
    if isinstance(metrics, str):
        metrics = [metrics]
    out = [check_metric(m) for m in dict.fromkeys(metrics)]
    if not out:
        raise FcplanError("metrics: give at least one metric")
    return out


def study_hash(scenarios: Sequence[Any], variants: Sequence[_Variant], settings: dict) -> str:
    """Hash of what a comparison's episodes depend on besides the seed: the scenario documents,
    the scheduler specs (label, registered name, settings), time limit, replan period and mode.

    Examples
    --------
    >>> from fcplan.scenario import load_scenario
    >>> v = [_Variant("greedy", "greedy", {})]
    >>> len(study_hash([load_scenario(3)], v, {"time_limit": None}))
    12
    """
    return short_hash(
        {
            "scenarios": [s.to_dict() for s in scenarios],
            "schedulers": [[v.label, v.name, v.settings] for v in variants],
            "settings": settings,
        },
        12,
    )


def _resumed(
    resume: ComparisonResult | str | os.PathLike[str] | None, study: str
) -> ComparisonResult | None:
    """The comparison to resume from (None: nothing to resume), checked to be of ``study``."""
    if resume is None:
        return None
    if not isinstance(resume, ComparisonResult):
        if not Path(resume).exists():
            return None
        try:
            resume = ComparisonResult.from_json(resume)
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise FcplanError(
                f"{resume}: not a comparison JSON file to resume from: {exc}"
            ) from None
    theirs = resume.settings.get("study_hash")
    if theirs != study:
        raise FcplanError(
            f"cannot resume from a comparison of another study (study hash {theirs}, this one "
            f"{study}: different scenarios, schedulers or settings); remove it or write elsewhere"
        )
    return resume


def _write_checkpoint(result: ComparisonResult, path: str | os.PathLike[str]) -> None:
    """Write ``result`` as JSON atomically (a temporary file renamed over ``path``)."""
    target = Path(path)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        result.to_json(tmp)
        os.replace(tmp, target)
    except OSError as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise FcplanError(f"cannot write {target}: {exc.strerror or exc}") from None


class _Runner:
    """Plays episodes of a fixed (scenarios x schedulers) grid for growing seed lists, keeping
    every finished episode (keyed by scenario index, scheduler index and seed)."""

    def __init__(
        self,
        scenarios: list[Any],
        variants: list[_Variant],
        time_limit: float | None,
        replan_period: float,
        jobs: int,
        progress: ProgressCallback | None,
    ) -> None:
        self.scenarios = scenarios
        self.variants = variants
        self.time_limit = time_limit
        self.replan_period = replan_period
        self.jobs = jobs
        self.progress = progress
        self.runtime = runtime_factories([v.name for v in variants])
        self.done: dict[tuple[int, int, int], tuple[dict[str, Any], list[float]]] = {}
        self.played = 0  # episodes played by this runner (for the progress count)
        self.planned = 0

    def reuse(self, old: ComparisonResult | None) -> None:
        """Keep the completed episodes of ``old`` (failed ones are played again)."""
        if old is None:
            return
        names = [s.name for s in self.scenarios]
        labels = [v.label for v in self.variants]
        times = old.solve_times_ms or [[] for _ in old.episodes]
        for row, t in zip(old.episodes, times, strict=True):
            if row.get("error") or names.count(row["scenario"]) != 1:
                continue  # failed, or a scenario name that does not identify one scenario
            if row["scheduler"] in labels:
                key = (names.index(row["scenario"]), labels.index(row["scheduler"]), row["seed"])
                self.done[key] = (row, list(t))

    def play(self, seeds: Sequence[int]) -> None:
        """Play the episodes of ``seeds`` not done yet."""
        todo = [
            (i, j, seed)
            for i in range(len(self.scenarios))
            for j in range(len(self.variants))
            for seed in seeds
            if (i, j, seed) not in self.done
        ]
        tasks = [
            _Task(k, self.scenarios[i], self.variants[j], seed, self.time_limit, self.replan_period)
            for k, (i, j, seed) in enumerate(todo)
        ]
        self.planned += len(tasks)
        jobs = max(1, min(self.jobs, len(tasks)))
        _, outcomes = select_backend(tasks, jobs, self.runtime, play=_run_task)
        try:
            for task, result, lost in outcomes:
                if result is None:  # its worker process kept dying, or it could not be sent
                    row, times = _failed_row(task, str(lost)), []
                else:
                    _, row, times = result
                self.done[todo[task.index]] = (row, times)
                self.played += 1
                if self.progress is not None:
                    self.progress(self.played, self.planned, row)
        finally:
            outcomes.close()

    def result(
        self, seeds: Sequence[int], settings: dict[str, Any], wall: float
    ) -> ComparisonResult:
        """The comparison of ``seeds`` (grid order: scenario, scheduler, seed)."""
        rows, times = [], []
        for i in range(len(self.scenarios)):
            for j in range(len(self.variants)):
                for seed in seeds:
                    row, t = self.done[(i, j, seed)]
                    rows.append(row)
                    times.append(t)
        return ComparisonResult(
            episodes=rows,
            solve_times_ms=times,
            scenarios=[s.name for s in self.scenarios],
            schedulers=[v.label for v in self.variants],
            seeds=list(seeds),
            settings={**settings, "jobs": min(self.jobs, max(len(rows), 1))},
            wall_time_s=wall,
        )
