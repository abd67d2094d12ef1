"""The result of a comparison: its episodes, per-scheduler tables with confidence intervals, files.

:class:`ComparisonResult` is what :func:`~fcplan.experiments.compare` returns:

* ``episodes``: one flat dict per episode, in grid order (scenario, then scheduler, then seed). The
  keys are those of :meth:`fcplan.EpisodeResult.summary` (``manual.final_score``,
  ``reference2020.final_score``, ``replans``, ``fallbacks``, ``wall_time_s``, ...) plus
  ``difficulty`` and ``error`` (``""`` for a completed episode).
* :meth:`ComparisonResult.table`: one row per scheduler (optionally per scheduler and difficulty):
  completed episodes and errors; mean and 95 % confidence half-width (Student t, see
  :mod:`fcplan.experiments.stats`) of every score column of
  :data:`~fcplan.experiments.tables.SCORE_COLUMNS` (the manual's final score, OFS, PS, AS, FPS,
  NRR and total negative reward, and the reference2020 final score); the median and 95th
  percentile of the solve time per replan in ms, pooled over all the scheduler's replans;
  fallbacks (replans where the scheduler failed and greedy stood in) and replans; the episodes
  that fell back on more than half of their replans (``fallback_majority``: their scores are
  mostly greedy's, and :meth:`~ComparisonResult.format` says so under the table); whether the
  scheduler ran in its deterministic mode (``deterministic``); the mean wall time per episode.
* :meth:`~ComparisonResult.format` (text table, ``mean ± ci`` cells),
  :meth:`~ComparisonResult.to_csv` (the table), :meth:`~ComparisonResult.to_json` (the table, the
  episodes and the solve times; :meth:`~ComparisonResult.from_json` reads it back).

The score columns are deterministic; the timing columns (solve times, wall time) are measurements
and vary from run to run.

Examples
--------
>>> result = ComparisonResult(
...     episodes=[{"scenario": "#3", "difficulty": "easy", "scheduler": "idle", "seed": 0,
...                "error": "boom"}], schedulers=["idle"])
>>> [(r["scheduler"], r["episodes"], r["errors"]) for r in result.table()]
[('idle', 0, 1)]
"""

from __future__ import annotations

import csv
import json
import math
import os
import textwrap
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import UnknownNameError
from fcplan.experiments.analysis import StudyStats, paired_scores, paired_table, study_stats
from fcplan.experiments.statblocks import blocks, fixed_width
from fcplan.experiments.stats import MeanCI, PairedComparison, mean_ci, paired_mean_ci
from fcplan.experiments.tables import (
    OUTCOME_COLUMNS,
    SCORE_COLUMNS,
    Column,
    difficulty_key,
    fallback_majority,
)

__all__ = ["ComparisonResult"]


def _share(x: float) -> str:
    return "-" if x != x else f"{100 * x:.0f}%"


def _pct(values: np.ndarray, q: float) -> float:
    return float(np.percentile(values, q)) if values.size else math.nan


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
        ``time_limit``, ``replan_period``, ``deterministic``, ``jobs``, ``study_hash`` (what
        the episodes depend on besides the seed: a comparison can only resume from one of the
        same study), ``metrics`` (the paired tables' metrics, headline first) and, for
        ``seeds="auto"``, ``seeds``, ``seed_batch`` and ``max_seeds``.
    wall_time_s : float
        Wall time of the whole comparison.
    stopped : str
        Why a ``seeds="auto"`` comparison stopped (``""`` for a fixed seed list).
    """

    episodes: list[dict[str, Any]]
    solve_times_ms: list[list[float]] = field(default_factory=list)
    scenarios: list[str] = field(default_factory=list)
    schedulers: list[str] = field(default_factory=list)
    seeds: list[int] = field(default_factory=list)
    settings: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0
    stopped: str = ""

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
        for col in SCORE_COLUMNS + OUTCOME_COLUMNS:
            ci = mean_ci([e.get(col.name, math.nan) for e in good])
            row[f"{col.key}_mean"] = ci.mean
            row[f"{col.key}_ci"] = ci.half_width
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
        row["fallback_majority"] = sum(fallback_majority(e) for e in good)
        modes = {e.get("deterministic") for e in good}
        row["deterministic"] = None if not modes or None in modes else bool(modes == {True})
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
            column of :data:`~fcplan.experiments.tables.SCORE_COLUMNS` ``<key>_mean`` and
            ``<key>_ci`` (95 % half-width; NaN with
            fewer than 2 episodes), ``replans``, ``solve_p50_ms``, ``solve_p95_ms`` (pooled over
            all replans), ``fallbacks``, ``fallback_rate`` (fallbacks / replans),
            ``fallback_majority`` (episodes that fell back on more than half of their replans),
            ``deterministic`` (every episode in the scheduler's deterministic mode; None when
            not recorded), ``wall_time_s_mean`` (per episode).
        """
        groups: dict[tuple[Any, ...], list[int]] = {}
        for name in self._schedulers():
            if by_difficulty:
                diffs = sorted(
                    {e["difficulty"] for e in self.episodes if e["scheduler"] == name},
                    key=difficulty_key,
                )
                for d in diffs:
                    groups[(name, d)] = []
            else:
                groups[(name,)] = []
        for i, e in enumerate(self.episodes):
            group = (e["scheduler"], e["difficulty"]) if by_difficulty else (e["scheduler"],)
            groups[group].append(i)
        out = []
        for names, idx in groups.items():
            label = {"scheduler": names[0]}
            if by_difficulty:
                label["difficulty"] = names[1]
            out.append(self._row(label, idx))
        return out

    def paired(self, a: str, b: str, metric: str = "manual.final_score") -> MeanCI:
        """Mean and 95 % CI of ``metric(a) - metric(b)`` over the (scenario, seed) pairs both
        schedulers completed.

        Examples
        --------
        >>> from fcplan.experiments import compare
        >>> from fcplan.scenario import load_scenario
        >>> r = compare([load_scenario(3).replace(duration_s=10)], ["greedy"], [0], jobs=1,
        ...             progress=False)
        >>> r.paired("greedy", "greedy").mean
        0.0
        """
        for name in (a, b):
            self._check_name(name)
        scores = paired_scores(self.pair_rows(), [a, b], metric, _pair_key)
        common = [k for k in scores[a] if k in scores[b]]
        return paired_mean_ci([scores[a][k] for k in common], [scores[b][k] for k in common])

    def _check_name(self, name: str) -> None:
        if name not in self._schedulers():
            raise UnknownNameError(
                f"scheduler {name!r} is not in this comparison: {', '.join(self._schedulers())}"
            )

    def pair_rows(self) -> list[dict[str, Any]]:
        """The completed episodes, each with ``_pair``: (scenario, seed, occurrence), the
        instance it played (a scenario name given twice counts its occurrences apart)."""
        count: dict[tuple[str, str, Any], int] = {}
        out = []
        for e in self.episodes:
            k = (e["scheduler"], e["scenario"], e["seed"])
            n = count.get(k, 0)
            count[k] = n + 1
            if not e.get("error"):
                out.append({**e, "_pair": (e["scenario"], e["seed"], n)})
        return out

    @property
    def references(self) -> list[str]:
        """The clairvoyant schedulers (registered name ``oracle``): references, not policies."""
        names = {e["scheduler"]: e.get("scheduler_name") for e in self.episodes}
        return [s for s in self._schedulers() if (names.get(s) or s.split(":")[0]) == "oracle"]

    @property
    def metrics(self) -> list[str]:
        """The metrics of the paired tables, headline first."""
        return list(self.settings.get("metrics") or ["manual.final_score"])

    def statistics(self, *, confidence: float = 0.95) -> StudyStats:
        """Paired tables (per metric of :attr:`metrics`), fractions of the oracle and rankings
        per metric (:func:`fcplan.experiments.analysis.study_stats`).

        Examples
        --------
        >>> from fcplan.experiments import compare
        >>> from fcplan.scenario import load_scenario
        >>> r = compare([load_scenario(3).replace(duration_s=10)], ["greedy", "idle"], [0, 1],
        ...             jobs=1, progress=False)
        >>> st = r.statistics()
        >>> [(c.a, c.b, c.n) for c in st.paired["manual.final_score"]]
        [('greedy', 'idle', 2)]
        """
        return study_stats(
            self.pair_rows(),
            self._schedulers(),
            self.metrics,
            _pair_key,
            references=self.references,
            confidence=confidence,
        )

    def comparisons(
        self, metric: str | None = None, *, confidence: float = 0.95, alpha: float = 0.05
    ) -> list[PairedComparison]:
        """Every pair of compared schedulers (the oracle left out) on ``metric`` (default: the
        headline), Holm-adjusted over the pairs (:func:`~fcplan.experiments.analysis.paired_table`).
        """
        metric = metric or self.metrics[0]
        policies = [s for s in self._schedulers() if s not in self.references]
        rows = self.pair_rows()
        return paired_table(rows, policies, metric, _pair_key, confidence=confidence, alpha=alpha)

    # ---- text ---------------------------------------------------------------------------

    def format(self, *, by_difficulty: bool = False, statistics: bool = True) -> str:
        """A fixed-width text table: one line per scheduler, ``mean ± ci`` cells; then (with
        ``statistics``) the paired differences of every metric of :attr:`metrics`, the fraction
        of the oracle and the ranking per metric (:meth:`statistics`), and why a
        ``seeds="auto"`` comparison stopped.

        Scores are the manual's unless marked ref2020; ``± nan`` means fewer than two episodes.
        """
        rows = self.table(by_difficulty=by_difficulty)
        n_eps = len(self.episodes)
        head = (
            f"{n_eps} episodes: {len(self.scenarios)} scenario(s) x {len(self._schedulers())} "
            f"scheduler(s) x {len(self.seeds)} seed(s); mean ± 95% CI half-width (Student t); "
            f"wall time {self.wall_time_s:.1f} s"
        )
        cols = _text_columns(by_difficulty)
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
        for r in rows:
            if r["fallback_majority"]:
                where = f" ({r['difficulty']})" if by_difficulty else ""
                out.append(
                    f"warning: {r['scheduler']}{where}: {r['fallback_majority']} of "
                    f"{r['episodes']} episode(s) fell back to greedy on more than half of their "
                    "replans; their scores are mostly greedy's"
                )
        if statistics:
            for block in blocks(self.statistics()):
                note = textwrap.fill(f"{block.title}. {block.note}", 100)
                out += ["", note, fixed_width(*block.cells)]
        if self.stopped:
            out += ["", f"seeds auto: {self.stopped}"]
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
            "stopped": self.stopped,
            "table": self.table(),
            "paired": self.statistics().paired_records(),
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
        keep = {"scenario", "difficulty", "scheduler", "scheduler_name", "seed", "error"}
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
            stopped=str(doc.get("stopped") or ""),
        )


_Cell = Callable[[dict[str, Any]], str]


def _pair_key(row: Mapping[str, Any]) -> Hashable:
    """The instance of a :meth:`ComparisonResult.pair_rows` row."""
    return row["_pair"]


def _score_cell(col: Column) -> _Cell:
    """``mean ± ci`` of a score column with its decimals."""
    d = col.decimals
    return lambda r: f"{r[f'{col.key}_mean']:.{d}f} ± {r[f'{col.key}_ci']:.{d}f}"


def _rounds(r: dict[str, Any]) -> str:
    if r["rounds_per_replan"] != r["rounds_per_replan"]:
        return "-"
    return f"{r['rounds_per_replan']:.1f}/{r['messages_per_replan']:.0f}"


def _text_columns(by_difficulty: bool) -> list[tuple[str, _Cell, str]]:
    """(header, cell of a table row, alignment) of every column of the text table."""
    cols: list[tuple[str, _Cell, str]] = [("scheduler", lambda r: str(r["scheduler"]), "<")]
    if by_difficulty:
        cols.append(("difficulty", lambda r: str(r["difficulty"]), "<"))
    cols += [("n", lambda r: str(r["episodes"]), ">"), ("err", lambda r: str(r["errors"]), ">")]
    cols += [(col.label, _score_cell(col), ">") for col in SCORE_COLUMNS]
    cols += [
        ("solve ms p50/p95", lambda r: f"{_ms(r['solve_p50_ms'])}/{_ms(r['solve_p95_ms'])}", ">"),
        ("fallbacks", lambda r: f"{r['fallbacks']}/{r['replans']}", ">"),
        ("fb>50%", lambda r: str(r["fallback_majority"]), ">"),
        ("optimal", lambda r: _share(r["optimal_rate"]), ">"),
        ("t-limit", lambda r: _share(r["time_limit_rate"]), ">"),
        ("rounds/msgs", _rounds, ">"),
        ("mode", _mode, ">"),
        ("wall s", lambda r: f"{r['wall_time_s_mean']:.2f}", ">"),
    ]
    return cols


def _mode(r: dict[str, Any]) -> str:
    """``det`` (deterministic mode), ``wall`` (plans may depend on the wall clock) or ``-``."""
    return {True: "det", False: "wall"}.get(r["deterministic"], "-")


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
