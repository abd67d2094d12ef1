"""Compare schedulers: run every (scenario, scheduler, seed) episode and tabulate the scores.

:func:`compare` plays the full grid ``scenarios x schedulers x seeds`` with
:func:`fcplan.run_episode`, in parallel over the machine's cores (one process per core,
:class:`concurrent.futures.ProcessPoolExecutor`), and returns a :class:`ComparisonResult`:

* ``episodes``: one flat dict per episode, in grid order (scenario, then scheduler, then seed, each
  in the order given) whatever order the workers finished in. The keys are those of
  :meth:`fcplan.EpisodeResult.summary` (``manual.final_score``, ``reference2020.final_score``,
  ``replans``, ``fallbacks``, ``wall_time_s``, ...) plus ``difficulty`` and ``error`` (``""`` for a
  completed episode). Workers send back these numbers and the per-replan solve times, never the
  trace.
* :meth:`ComparisonResult.table`: one row per scheduler (optionally per scheduler and difficulty):
  completed episodes and errors; mean and 95 % confidence half-width (Student t, see
  :mod:`fcplan.experiments.stats`) of the manual metrics (final score, OFS, PS, AS, FPS, NRR, total
  negative reward) and of the reference2020 final score; the median and 95th percentile of the
  solve time per replan in ms, pooled over all the scheduler's replans; fallbacks (replans where
  the scheduler failed and greedy stood in) and replans; the mean wall time per episode.
* :meth:`~ComparisonResult.format` (text table, ``mean ± ci`` cells),
  :meth:`~ComparisonResult.to_csv` (the table), :meth:`~ComparisonResult.to_json` (the table, the
  episodes and the solve times; :meth:`~ComparisonResult.from_json` reads it back).

Reproducibility. Every episode is seeded by its seed alone, so the scores do not depend on
``jobs``, on the worker an episode ran in, or on the order episodes finished: a serial and a
parallel comparison give identical score columns. The timing columns (solve times, wall time) are
measurements and vary from run to run.

Failures. A scheduler that raises or returns an invalid plan does not fail its episode (the
episode loop falls back to greedy for that replan and counts a fallback). An episode that fails
anyway (an exception escaping :func:`fcplan.run_episode`) is recorded with its error message and
counted in the ``errors`` column; the other episodes run on. Scheduler names are checked, and every
scheduler is constructed once with its default settings, before any episode runs, so a typo or a
scheduler that cannot be built fails at once with a one-line :class:`fcplan.FcplanError`.
Ctrl-C (:class:`KeyboardInterrupt`) cancels the pending episodes, stops the workers and re-raises.

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

import csv
import json
import math
import os
import re
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError, UnknownNameError
from fcplan.experiments.progress import ProgressPrinter
from fcplan.experiments.stats import MeanCI, mean_ci, paired_mean_ci
from fcplan.experiments.workers import (
    default_jobs,
    init_worker,
    runtime_factories,
    stop_workers,
)

__all__ = [
    "compare",
    "ComparisonResult",
    "parse_range",
    "RangeError",
    "ProgressPrinter",
    "METRICS",
]

#: Table metrics: short name -> (episode key, column label in :meth:`ComparisonResult.format`).
METRICS: dict[str, tuple[str, str]] = {
    "final_score": ("manual.final_score", "final score"),
    "ofs": ("manual.overall_firefighting", "OFS %"),
    "ps": ("manual.perception", "PS %"),
    "as": ("manual.action", "AS %"),
    "fps": ("manual.facility_protection", "FPS %"),
    "nrr": ("manual.negative_reward_ratio", "NRR %"),
    "neg_reward": ("manual.total_negative_reward", "neg. reward"),
    "ref2020_final_score": ("reference2020.final_score", "ref2020 final"),
}

_DIFFICULTY_ORDER = ("practice", "easy", "moderate", "hard", "custom")
_MAX_RANGE = 100_000


class RangeError(FcplanError, ValueError):
    """A range list such as ``"1-24"`` or ``"0,2,5-7"`` is malformed."""


# --------------------------------------------------------------------------------------------
# ranges and validation


def parse_range(text: str, *, names: bool = True) -> list[int | str]:
    """Read a comma-separated list of integers, inclusive ranges and (optionally) names.

    Parameters
    ----------
    text : str
        e.g. ``"1-24"``, ``"1,3,5-7"``, ``"practice,1-3"``, ``"0"``.
    names : bool
        Accept items that are not integers (scenario names or paths) and return them as strings.
        With ``names=False`` (seeds) every item must be an integer >= 0 or a range ``a-b``.

    Returns
    -------
    list of int or str
        In the order given, duplicates removed.

    Raises
    ------
    RangeError
        An empty list or item, a descending range (``5-3``), a range of more than 100000 items, or
        (``names=False``) an item that is not a non-negative integer or range.

    Examples
    --------
    >>> parse_range("1-4")
    [1, 2, 3, 4]
    >>> parse_range("practice, 1,3,5-7, 3")
    ['practice', 1, 3, 5, 6, 7]
    >>> parse_range("a-b", names=False)
    Traceback (most recent call last):
    ...
    fcplan.experiments.compare.RangeError: expected an integer >= 0 or a range like 0-4, got 'a-b'
    """
    if not isinstance(text, str):
        raise RangeError(f"expected a string like '1-24' or '1,3,5-7', got {text!r}")
    out: list[int | str] = []
    seen: set[int | str] = set()
    items = [t.strip() for t in text.split(",")]
    if not text.strip() or any(not t for t in items):
        raise RangeError(f"empty item in {text!r}; expected e.g. '1-24' or '1,3,5-7'")
    for item in items:
        if re.fullmatch(r"\d+", item):
            values: Iterable[int | str] = [int(item)]
        elif m := re.fullmatch(r"(\d+)\s*-\s*(\d+)", item):
            lo, hi = int(m.group(1)), int(m.group(2))
            if lo > hi:
                raise RangeError(f"empty range {item!r}: {lo} > {hi}")
            if hi - lo + 1 > _MAX_RANGE:
                raise RangeError(f"range {item!r} has more than {_MAX_RANGE} items")
            values = range(lo, hi + 1)
        elif names:
            values = [item]
        else:
            raise RangeError(f"expected an integer >= 0 or a range like 0-4, got {item!r}")
        for v in values:
            if v not in seen:
                seen.add(v)
                out.append(v)
    return out


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


def _positive(name: str, value: Any, *, allow_none: bool) -> float | None:
    if value is None and allow_none:
        return None
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise FcplanError(f"{name} must be a number > 0, got {value!r}")
    return v


# --------------------------------------------------------------------------------------------
# workers


@dataclass(frozen=True, slots=True)
class _Task:
    index: int
    scenario: Any  # Scenario
    scheduler: str
    seed: int
    time_limit: float | None
    replan_period: float


def _run_task(task: _Task) -> tuple[int, dict[str, Any], list[float]]:
    """Play one episode; return its summary row and per-replan solve times (ms)."""
    row: dict[str, Any] = {
        "scenario": task.scenario.name,
        "difficulty": task.scenario.difficulty,
        "scheduler": task.scheduler,
        "seed": task.seed,
    }
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
        row["error"] = f"{type(exc).__name__}: {exc}".replace("\n", " ")
        return task.index, row, []
    summary.pop("scenario", None)
    summary.pop("seed", None)
    summary.pop("scheduler", None)  # the registered name is the row's label
    row.update(summary)
    row["error"] = ""
    return task.index, row, times


def run_episode(*args: Any, **kwargs: Any):
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
    tl = _positive("time_limit", time_limit, allow_none=True)
    rp = _positive("replan_period", replan_period, allow_none=False)
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
    total = len(tasks)
    jobs = int(min(jobs, total))
    rows: list[dict[str, Any] | None] = [None] * total
    times: list[list[float]] = [[] for _ in range(total)]
    t0 = time.perf_counter()
    done = 0

    def record(result: tuple[int, dict[str, Any], list[float]]) -> None:
        nonlocal done
        idx, row, st = result
        rows[idx], times[idx] = row, st
        done += 1
        if progress is not None:
            progress(done, total, row)

    if jobs == 1:
        for task in tasks:
            record(_run_task(task))
    else:
        executor = ProcessPoolExecutor(
            max_workers=jobs, initializer=init_worker, initargs=(runtime_factories(names),)
        )
        futures: dict[Future, _Task] = {}
        try:
            futures = {executor.submit(_run_task, t): t for t in tasks}
            pending = set(futures)
            while pending:
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in sorted(finished, key=lambda f: futures[f].index):
                    try:
                        record(fut.result())
                    except Exception as exc:  # noqa: BLE001 - e.g. a worker process died
                        t = futures[fut]
                        row = {
                            "scenario": t.scenario.name,
                            "difficulty": t.scenario.difficulty,
                            "scheduler": t.scheduler,
                            "seed": t.seed,
                            "error": f"{type(exc).__name__}: {exc}".replace("\n", " "),
                        }
                        record((t.index, row, []))
        except BaseException:
            stop_workers(executor, futures)
            raise
        executor.shutdown(wait=True)
    return ComparisonResult(
        episodes=[r for r in rows if r is not None],
        solve_times_ms=times,
        scenarios=[s.name for s in scen],
        schedulers=names,
        seeds=seed_list,
        settings={"time_limit": tl, "replan_period": rp, "jobs": jobs},
        wall_time_s=time.perf_counter() - t0,
    )


# --------------------------------------------------------------------------------------------
# results


def _share(x: float) -> str:
    return "-" if x != x else f"{100 * x:.0f}%"


def _pct(values: np.ndarray, q: float) -> float:
    return float(np.percentile(values, q)) if values.size else math.nan


def _difficulty_key(d: str) -> tuple[int, str]:
    return (_DIFFICULTY_ORDER.index(d) if d in _DIFFICULTY_ORDER else len(_DIFFICULTY_ORDER), d)


@dataclass
class ComparisonResult:
    """The episodes of a comparison and their summaries.

    Attributes
    ----------
    episodes : list of dict
        One flat dict per episode in grid order (scenario, scheduler, seed): ``scenario``,
        ``difficulty``, ``scheduler``, ``seed``, ``error`` (``""`` if it completed), and for a
        completed episode the keys of :meth:`fcplan.EpisodeResult.summary`.
    solve_times_ms : list of list of float
        Per episode (same order), the wall time of each replan's scheduler call in ms (empty for a
        failed episode).
    scenarios, schedulers : list of str
        Scenario names and scheduler names, in the order given.
    seeds : list of int
    settings : dict
        ``time_limit``, ``replan_period``, ``jobs``.
    wall_time_s : float
        Wall time of the whole comparison.
    """

    episodes: list[dict[str, Any]]
    solve_times_ms: list[list[float]] = field(default_factory=list)
    scenarios: list[str] = field(default_factory=list)
    schedulers: list[str] = field(default_factory=list)
    seeds: list[int] = field(default_factory=list)
    settings: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0

    # ---- tables -------------------------------------------------------------------------

    @property
    def errors(self) -> list[dict[str, Any]]:
        """The episodes that failed (each with its ``error`` message)."""
        return [e for e in self.episodes if e.get("error")]

    def _schedulers(self) -> list[str]:
        names = list(self.schedulers)
        for e in self.episodes:
            if e["scheduler"] not in names:
                names.append(e["scheduler"])
        return names

    def _row(self, label: dict[str, Any], idx: list[int]) -> dict[str, Any]:
        eps = [self.episodes[i] for i in idx]
        ok = [i for i, e in zip(idx, eps, strict=True) if not e.get("error")]
        good = [self.episodes[i] for i in ok]
        row: dict[str, Any] = dict(label)
        row["episodes"] = len(good)
        row["errors"] = len(eps) - len(good)
        for short, (key, _) in METRICS.items():
            ci = mean_ci([e[key] for e in good])
            row[f"{short}_mean"] = ci.mean
            row[f"{short}_ci"] = ci.half_width
        st = (
            np.concatenate([np.asarray(self.solve_times_ms[i], np.float64) for i in ok])
            if ok and self.solve_times_ms
            else np.zeros(0)
        )
        replans = int(sum(e["replans"] for e in good))
        fallbacks = int(sum(e["fallbacks"] for e in good))
        row["replans"] = replans
        row["solve_p50_ms"] = _pct(st, 50)
        row["solve_p95_ms"] = _pct(st, 95)
        row["fallbacks"] = fallbacks
        row["fallback_rate"] = fallbacks / replans if replans else math.nan
        row["optimal_rate"] = (
            sum(e.get("optimal_replans", 0) for e in good) / replans if replans else math.nan
        )
        row["time_limit_rate"] = (
            sum(e.get("time_limit_replans", 0) for e in good) / replans if replans else math.nan
        )
        for key in ("rounds_per_replan", "messages_per_replan"):
            vals = [e.get(key, math.nan) for e in good]
            vals = [v for v in vals if v == v]  # drop NaN (schedulers without consensus rounds)
            row[key] = float(np.mean(vals)) if vals else math.nan
        row["wall_time_s_mean"] = (
            float(np.mean([e["wall_time_s"] for e in good])) if good else math.nan
        )
        return row

    def table(self, *, by_difficulty: bool = False) -> list[dict[str, Any]]:
        """Per-scheduler summary rows (flat dicts, the columns of :meth:`to_csv`).

        Parameters
        ----------
        by_difficulty : bool
            One row per (scheduler, difficulty) instead, difficulties in the order practice,
            easy, moderate, hard, custom.

        Returns
        -------
        list of dict
            Keys: ``scheduler`` (and ``difficulty``), ``episodes`` (completed), ``errors``, for each
            name in :data:`METRICS` ``<name>_mean`` and ``<name>_ci`` (95 % half-width; NaN with
            fewer than 2 episodes), ``replans``, ``solve_p50_ms``, ``solve_p95_ms`` (pooled over
            all replans), ``fallbacks``, ``fallback_rate`` (fallbacks / replans),
            ``wall_time_s_mean`` (per episode).
        """
        groups: dict[tuple[str, ...], list[int]] = {}
        for name in self._schedulers():
            if by_difficulty:
                diffs = sorted(
                    {e["difficulty"] for e in self.episodes if e["scheduler"] == name},
                    key=_difficulty_key,
                )
                for d in diffs:
                    groups[(name, d)] = []
            else:
                groups[(name,)] = []
        for i, e in enumerate(self.episodes):
            key = (e["scheduler"], e["difficulty"]) if by_difficulty else (e["scheduler"],)
            groups[key].append(i)
        out = []
        for key, idx in groups.items():
            label = {"scheduler": key[0]}
            if by_difficulty:
                label["difficulty"] = key[1]
            out.append(self._row(label, idx))
        return out

    def paired(self, a: str, b: str, metric: str = "manual.final_score") -> MeanCI:
        """Mean and 95 % CI of ``metric(a) - metric(b)`` over the (scenario, seed) pairs both
        schedulers completed.

        Examples
        --------
        >>> from fcplan.scenario import load_scenario
        >>> r = compare([load_scenario(3).replace(duration_s=10)], ["greedy"], [0], jobs=1)
        >>> r.paired("greedy", "greedy").mean
        0.0
        """
        for name in (a, b):
            if name not in self._schedulers():
                raise UnknownNameError(
                    f"scheduler {name!r} is not in this comparison: {', '.join(self._schedulers())}"
                )
        rows_a = {(i, e["scenario"], e["seed"]): e for i, e in self._by_pair(a)}
        rows_b = {(i, e["scenario"], e["seed"]): e for i, e in self._by_pair(b)}
        keys = [k for k in rows_a if k in rows_b]
        va = [rows_a[k][metric] for k in keys if not (rows_a[k]["error"] or rows_b[k]["error"])]
        vb = [rows_b[k][metric] for k in keys if not (rows_a[k]["error"] or rows_b[k]["error"])]
        return paired_mean_ci(va, vb)

    def _by_pair(self, name: str) -> list[tuple[int, dict[str, Any]]]:
        """(occurrence number of its (scenario, seed), episode) of one scheduler, in order."""
        count: dict[tuple[str, Any], int] = {}
        out = []
        for e in self.episodes:
            if e["scheduler"] == name:
                k = (e["scenario"], e["seed"])
                out.append((count.get(k, 0), e))
                count[k] = count.get(k, 0) + 1
        return out

    # ---- text ---------------------------------------------------------------------------

    def format(self, *, by_difficulty: bool = False) -> str:
        """A fixed-width text table: one line per scheduler, ``mean ± ci`` cells.

        Scores are the manual's unless marked ref2020; ``± nan`` means fewer than two episodes.
        """
        rows = self.table(by_difficulty=by_difficulty)
        n_eps = len(self.episodes)
        head = (
            f"{n_eps} episodes: {len(self.scenarios)} scenario(s) x {len(self._schedulers())} "
            f"scheduler(s) x {len(self.seeds)} seed(s); mean ± 95% CI half-width (Student t); "
            f"wall time {self.wall_time_s:.1f} s"
        )
        cols: list[tuple[str, Callable[[dict[str, Any]], str], str]] = [
            ("scheduler", lambda r: str(r["scheduler"]), "<")
        ]
        if by_difficulty:
            cols.append(("difficulty", lambda r: str(r["difficulty"]), "<"))
        cols += [
            ("n", lambda r: str(r["episodes"]), ">"),
            ("err", lambda r: str(r["errors"]), ">"),
        ]
        for short, (_, label) in METRICS.items():

            def cell(r: dict[str, Any], s: str = short) -> str:
                d = 0 if s == "neg_reward" else 1  # penalties run into the tens of thousands
                return f"{r[f'{s}_mean']:.{d}f} ± {r[f'{s}_ci']:.{d}f}"

            cols.append((label, cell, ">"))
        cols += [
            (
                "solve ms p50/p95",
                lambda r: f"{_ms(r['solve_p50_ms'])}/{_ms(r['solve_p95_ms'])}",
                ">",
            ),
            ("fallbacks", lambda r: f"{r['fallbacks']}/{r['replans']}", ">"),
            ("optimal", lambda r: _share(r["optimal_rate"]), ">"),
            ("t-limit", lambda r: _share(r["time_limit_rate"]), ">"),
            (
                "rounds/msgs",
                lambda r: (
                    "-"
                    if r["rounds_per_replan"] != r["rounds_per_replan"]
                    else f"{r['rounds_per_replan']:.1f}/{r['messages_per_replan']:.0f}"
                ),
                ">",
            ),
            ("wall s", lambda r: f"{r['wall_time_s_mean']:.2f}", ">"),
        ]
        cells = [[fn(r) for _, fn, _ in cols] for r in rows]
        widths = [max([len(h)] + [len(c[k]) for c in cells]) for k, (h, _, _) in enumerate(cols)]

        def line(values: Sequence[str]) -> str:
            parts = [f"{v:{a}{w}}" for v, w, (_, _, a) in zip(values, widths, cols, strict=True)]
            return "  ".join(parts).rstrip()

        out = [head, line([h for h, _, _ in cols])]
        out += [line(c) for c in cells]
        if self.errors:
            e = self.errors[0]
            out.append(
                f"{len(self.errors)} episode(s) failed; first: {e['scenario']} {e['scheduler']} "
                f"seed {e['seed']}: {e['error']}"
            )
        return "\n".join(out)

    def __str__(self) -> str:
        return self.format()

    # ---- files --------------------------------------------------------------------------

    def to_csv(self, path: str | os.PathLike[str], *, by_difficulty: bool = False) -> None:
        """Write :meth:`table` as CSV (stdlib :mod:`csv`; NaN written as ``nan``)."""
        rows = self.table(by_difficulty=by_difficulty)
        with open(path, "w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ["scheduler"])
            writer.writeheader()
            writer.writerows(rows)

    def to_dict(self) -> dict[str, Any]:
        """Everything as plain JSON-ready data (NaN as None)."""
        from fcplan import __version__

        doc = {
            "fcplan_version": __version__,
            "scenarios": self.scenarios,
            "schedulers": self.schedulers,
            "seeds": self.seeds,
            "settings": self.settings,
            "wall_time_s": self.wall_time_s,
            "table": self.table(),
            "table_by_difficulty": self.table(by_difficulty=True),
            "episodes": self.episodes,
            "solve_times_ms": self.solve_times_ms,
        }
        return _nan_to_none(doc)

    def to_json(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_dict` as JSON (standard JSON: NaN written as null)."""
        text = json.dumps(self.to_dict(), indent=1, allow_nan=False)
        Path(path).write_text(text + "\n", encoding="utf-8")

    @classmethod
    def from_json(cls, path: str | os.PathLike[str]) -> ComparisonResult:
        """Read a file written by :meth:`to_json` (its tables are recomputed from the episodes)."""
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
        keep = {"scenario", "difficulty", "scheduler", "seed", "error"}
        episodes = [
            {k: (math.nan if v is None and k not in keep else v) for k, v in e.items()}
            for e in doc["episodes"]
        ]
        return cls(
            episodes=episodes,
            solve_times_ms=[list(map(float, t)) for t in doc.get("solve_times_ms", [])],
            scenarios=list(doc.get("scenarios", [])),
            schedulers=list(doc.get("schedulers", [])),
            seeds=list(doc.get("seeds", [])),
            settings=dict(doc.get("settings", {})),
            wall_time_s=float(doc.get("wall_time_s") or 0.0),
        )


def _ms(v: float) -> str:
    if not math.isfinite(v):
        return "nan"
    return f"{v:.2f}" if v < 10 else f"{v:.1f}" if v < 100 else f"{v:.0f}"


def _nan_to_none(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _nan_to_none(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_nan_to_none(v) for v in x]
    if isinstance(x, np.generic):
        return _nan_to_none(x.item())
    return x
