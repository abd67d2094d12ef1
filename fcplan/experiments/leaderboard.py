"""The benchmark leaderboard: every scheduler on every tier of a suite, from a results folder.

:func:`leaderboard` reads episodes (a results folder written by ``fcplan sweep``, or the JSON of
``fcplan compare --json``), groups them by suite and tier from the scenario names
(``"fcplan-bench-v1/hard-01"`` is tier ``hard`` of suite ``fcplan-bench-v1``; other scenarios form
the tier ``other``) and computes, per tier and scheduler:

* the **headline metric** (default the manual's final score, ``manual.final_score``): mean and
  95 % Student-t interval over the tier's completed (scenario, seed) episodes, the same numbers
  ``fcplan report`` prints (the interval includes the spread between scenarios, so it is wide;
  compare schedulers with the paired table instead);
* the **fraction of the oracle**: ``F = sum_i (s_i - idle_i) / sum_i (oracle_i - idle_i)`` over
  the (scenario, seed) pairs ``i`` where the scheduler, the clairvoyant reference and the
  ``idle`` team all completed (the reference ``oracle_i`` is the best of the oracle variants run
  on the pair, ``oracle``, ``oracle[routing]``, ...: :func:`reference_scores`): the share of the
  oracle's improvement over doing nothing that the scheduler achieved on the same pairs (1 = as
  good as the oracle, 0 = no better than idle). It
  is a **ratio of means**, not a mean of per-pair ratios: a pair where the oracle barely beats
  idle (nothing was at stake) would give a huge or undefined per-pair ratio, while the ratio of
  means weights each pair by what was achievable there. Normalising by idle makes it independent
  of the score's zero: final scores are often negative on this suite, where a raw ratio
  ``s_i / oracle_i`` would mean nothing. ``fcplan compare`` and ``fcplan report`` give the same
  number (:func:`~fcplan.experiments.analysis.oracle_fractions`) when idle was run. Its 95 %
  interval is a percentile bootstrap (2,000 draws, seed 0) that resamples seeds within each
  scenario: the suite's scenarios are fixed, seeds are the random part;
* OFS, time to containment and burned area (means), the scenarios *cleared* (OFS 100 % on every
  seed), the solve time per replan (p50 and p95 over every replan of the tier), the proven
  optimality gap per replan of the schedulers that prove a bound on their own model (p50 and p95
  over the replans that have one), and the replans that fell back to greedy;
* **paired comparisons** of the policies (every scheduler except the oracle references and the
  ``idle`` and ``random`` baselines), each pair on the (scenario, seed) instances both completed:
  mean difference and its interval, Wilcoxon p-value Holm-adjusted over the tier's pairs of
  policies, Cohen's d_z and a verdict (:func:`~fcplan.experiments.analysis.paired_table`, the
  statistics of ``fcplan compare`` and ``fcplan report``);
* the **tier check** of issue 12: a tier separates the schedulers when the policies are not all
  within each other's 95 % intervals and no scheduler clears every scenario; its acceptance
  asks that at least half of the policy pairs differ with Holm p < 0.01 and that the oracle's mean
  be at least every policy's. A policy that has not played every (scenario, seed) pair of the
  tier is ranked after the complete ones and makes the check provisional.

:func:`fcplan.experiments.leaderboard_page.markdown` writes the page (``docs/leaderboard.md``):
the suite version, seeds, library versions, date and wall time of producing the results, then one
section per tier.

Examples
--------
>>> rows = [{"scenario": "fcplan-bench-v1/hard-01", "scheduler": name, "seed": seed,
...          "status": "ok", "manual.final_score": score + seed,
...          "manual.overall_firefighting": 50.0, "fallbacks": 0, "replans": 10}
...         for seed in range(3)
...         for name, score in (("greedy", 10.0), ("oracle", 20.0), ("idle", -100.0))]
>>> board = leaderboard(rows)
>>> tier = board.tiers[0]
>>> tier.suite, tier.tier, tier.stats["greedy"].mean.mean, round(tier.stats["greedy"].fraction, 3)
('fcplan-bench-v1', 'hard', 11.0, 0.917)
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.experiments.analysis import metric_label, paired_table
from fcplan.experiments.oracle_reference import (
    complete_variants,
    fraction_of_oracle,
    fraction_on_pairs,
    on_top,
    reference_scores,
)
from fcplan.experiments.stats import MeanCI, PairedComparison, mean_ci
from fcplan.experiments.tables import REPORT_COLUMNS, higher_is_better
from fcplan.metrics import metric_spec
from fcplan.provenance import count_code_versions
from fcplan.scenario.suite import suite_of

__all__ = [
    "HEADLINE",
    "Leaderboard",
    "SchedulerStats",
    "TierCheck",
    "TierResult",
    "finite",
    "fraction_of_oracle",
    "is_policy",
    "leaderboard",
    "metric_direction",
    "read_episodes",
    "reference_scores",
    "tier_of",
]

HEADLINE = "manual.final_score"
"""The suite's headline metric (the manual's final score, Eq. 6)."""

ORACLE, IDLE = "oracle", "idle"
BASELINES = ("idle", "random")
HOLM_LEVEL = 0.01

_OFS = "manual.overall_firefighting"
_TTC = "outcome.time_to_containment_s"
_BURNED = "outcome.burned_area_cells"


def metric_direction(metric: str) -> tuple[str, int, bool]:
    """Label, decimals and whether higher is better for a result column.

    Examples
    --------
    >>> metric_direction("outcome.burned_area_cells"), metric_direction("manual.final_score")
    (('burned', 0, False), ('final score', 1, True))
    """
    decimals = next((c.decimals for c in REPORT_COLUMNS if c.name == metric), None)
    if decimals is None:
        try:
            decimals = metric_spec(metric.partition(".")[2]).decimals
        except FcplanError:
            decimals = 2
    return metric_label(metric), decimals, higher_is_better(metric)


def is_policy(label: str) -> bool:
    """Whether a scheduler label is a policy to rank (not an oracle reference or a baseline).

    Examples
    --------
    >>> is_policy("cbba"), is_policy("oracle[routing]"), is_policy("idle")
    (True, False, False)
    """
    return not label.startswith(ORACLE) and label not in BASELINES


def tier_of(scenario: str) -> tuple[str, str]:
    """``(suite, tier)`` of a scenario name; ``("", "other")`` outside the suites.

    Examples
    --------
    >>> tier_of("fcplan-bench-v1/scale-03"), tier_of("#12")
    (('fcplan-bench-v1', 'scale'), ('', 'other'))
    """
    suite = suite_of(scenario)
    if suite is None:
        return "", "other"
    return suite, scenario.split("/", 1)[1].rsplit("-", 1)[0]


@dataclass(frozen=True)
class SchedulerStats:
    """One scheduler on one tier (see the module docstring for each number)."""

    episodes: int
    failed: int
    mean: MeanCI
    instances: int = 0
    """Distinct (scenario, seed) pairs completed (below the tier's count: the row is partial)."""
    fraction: float = math.nan
    fraction_ci: tuple[float, float] = (math.nan, math.nan)
    fraction_median_pair: float = math.nan
    ofs: float = math.nan
    containment_s: float = math.nan
    burned: float = math.nan
    cleared: int = 0
    solve_p50_ms: float = math.nan
    solve_p95_ms: float = math.nan
    bounded_replans: int = 0
    gap_p50: float = math.nan
    gap_p95: float = math.nan
    fallbacks: int = 0
    replans: int = 0
    deterministic: bool | None = None


@dataclass(frozen=True)
class TierCheck:
    """Issue 12's rule for keeping a tier, and its acceptance test, on the tier's policies."""

    policies: tuple[str, ...]
    separated: bool
    """Not every policy's mean lies inside every other policy's 95 % interval."""
    cleared_all: tuple[str, ...]
    """Schedulers with OFS 100 % on every seed of every scenario."""
    resolved: int
    """Policy pairs with Holm-adjusted p < 0.01."""
    pairs: int
    oracle_top: bool | None
    """The clairvoyant reference's mean (the best oracle variant per pair,
    :func:`reference_scores`) is at least as good as every policy's (None without oracle
    episodes)."""
    incomplete: tuple[str, ...] = ()
    """Policies short of some of the tier's (scenario, seed) pairs: the check is provisional."""

    @property
    def keep(self) -> bool:
        """The tier separates (the issue's rule for keeping it)."""
        return self.separated and not self.cleared_all

    @property
    def accepted(self) -> bool:
        """The issue's acceptance: every policy on every pair, kept, half the pairs resolved at
        Holm p < 0.01, oracle on top."""
        return (
            not self.incomplete
            and self.keep
            and 2 * self.resolved >= self.pairs > 0
            and self.oracle_top is True
        )


@dataclass
class TierResult:
    """Every scheduler on one tier."""

    suite: str
    tier: str
    scenarios: list[str]
    seeds: list[int]
    metric: str
    stats: dict[str, SchedulerStats]
    order: list[str]
    """Policies with every (scenario, seed) pair ranked by mean, then partial ones (ranked
    apart: their means are over fewer instances), then the references and baselines."""
    pairs: list[PairedComparison]
    check: TierCheck
    instances: int = 0
    """Distinct (scenario, seed) pairs any scheduler of the tier played."""
    settings: dict[str, str] = field(default_factory=dict)
    """Scheduler label -> its settings as recorded in the results (``key=value, ...``)."""
    per_scenario: dict[str, dict[str, tuple[float, float, int]]] = field(default_factory=dict)
    """Scenario -> scheduler label -> (mean headline metric, mean OFS %, episodes): which
    scenarios of the tier tell the schedulers apart."""
    reference: tuple[str, ...] = ()
    """The oracle variants that make up the reference (:func:`complete_variants`)."""


@dataclass
class Leaderboard:
    """Tier results and where they came from (see :func:`leaderboard`)."""

    metric: str
    tiers: list[TierResult]
    meta: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Every number, JSON-ready (NaN as None)."""
        return _plain(
            {
                "metric": self.metric,
                "meta": self.meta,
                "tiers": [
                    {
                        "suite": t.suite,
                        "tier": t.tier,
                        "scenarios": t.scenarios,
                        "seeds": t.seeds,
                        "instances": t.instances,
                        "order": t.order,
                        "settings": t.settings,
                        "stats": {k: _stats_dict(v) for k, v in t.stats.items()},
                        "pairs": [_pair_dict(c) for c in t.pairs],
                        "per_scenario": {
                            sc: {
                                k: dict(zip(("mean", "ofs", "n"), v, strict=True))
                                for k, v in means.items()
                            }
                            for sc, means in t.per_scenario.items()
                        },  # fmt: skip
                        "check": {
                            **_fields(t.check),
                            "keep": t.check.keep,
                            "accepted": t.check.accepted,
                        },
                    }
                    for t in self.tiers
                ],
            }
        )


def _fields(obj: Any) -> dict[str, Any]:
    return {k: getattr(obj, k) for k in obj.__dataclass_fields__}


def _stats_dict(s: SchedulerStats) -> dict[str, Any]:
    d = _fields(s)
    d["mean"] = {"mean": s.mean.mean, "ci": s.mean.half_width, "n": s.mean.n}
    return d


def _pair_dict(c: PairedComparison) -> dict[str, Any]:
    return {"a": c.a, "b": c.b, "diff": c.diff.mean, "ci": c.diff.half_width, "n": c.diff.n,
            "p": c.p, "p_holm": c.p_holm, "d_z": c.effect}  # fmt: skip


def _plain(v: Any) -> Any:
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, (float, np.floating)):
        return None if math.isnan(v) else float(v)
    if isinstance(v, np.integer):
        return int(v)
    return v


# ------------------------------------------------------------------------------------- reading
def read_episodes(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """Episode rows of a results folder (``fcplan sweep``) or a comparison's JSON file
    (``fcplan compare --json``).

    Raises
    ------
    FcplanError
        The path is neither (one line naming it).
    """
    p = Path(path)
    if p.is_dir():
        from fcplan.experiments.results import load_results

        return list(load_results(p).to_dict("records"))
    if p.is_file() and p.suffix == ".json":
        doc = json.loads(p.read_text(encoding="utf-8"))
        episodes = doc.get("episodes")
        if not isinstance(episodes, list):
            raise FcplanError(f"{p}: not a comparison file of fcplan compare --json (no episodes)")
        times = doc.get("solve_times_ms") or [[] for _ in episodes]
        out = []
        for e, t in zip(episodes, times, strict=False):
            row = {k: (math.nan if v is None else v) for k, v in e.items()}
            row.update(status="failed" if e.get("error") else "ok", replan_solve_ms=list(t))
            out.append(row)
        if doc.get("wall_time_s"):
            out.append({"__wall_time_s": float(doc["wall_time_s"])})
        return out
    raise FcplanError(
        f"{p}: expected a results folder of fcplan sweep or a .json file of fcplan compare --json"
    )


# ------------------------------------------------------------------------------------- numbers
def _pooled_percentiles(rows: list[dict[str, Any]]) -> tuple[float, float]:
    times: list[float] = []
    for r in rows:
        t = r.get("replan_solve_ms")
        if t is not None and len(t):
            times.extend(float(x) for x in t)
    if not times:
        p50 = [float(r["solve_p50_ms"]) for r in rows if finite(r.get("solve_p50_ms"))]
        return (float(np.median(p50)), math.nan) if p50 else (math.nan, math.nan)
    a = np.asarray(times)
    return float(np.percentile(a, 50)), float(np.percentile(a, 95))


def _pooled_gaps(rows: list[dict[str, Any]]) -> tuple[int, float, float]:
    """(replans with a proven bound, p50, p95 of their relative gaps) over every replan of
    ``rows`` (``replan_gap`` lists; rows of ``fcplan compare --json``, which have none, give
    the median of their ``gap_p50`` and no p95)."""
    gaps: list[float] = []
    listed = False
    for r in rows:
        g = r.get("replan_gap")  # results of an older fcplan have none (None or NaN)
        if isinstance(g, (list, tuple, np.ndarray)):
            listed = True
            gaps.extend(float(x) for x in g if finite(x))
    if gaps:
        a = np.asarray(gaps)
        return a.size, float(np.percentile(a, 50)), float(np.percentile(a, 95))
    if listed:
        return 0, math.nan, math.nan
    p50 = [float(r["gap_p50"]) for r in rows if finite(r.get("gap_p50"))]
    n = int(sum(int(r["bounded_replans"]) for r in rows if finite(r.get("bounded_replans"))))
    return (n, float(np.median(p50)), math.nan) if p50 else (0, math.nan, math.nan)


def finite(v: Any) -> bool:
    """Whether ``v`` is a finite number (not None, NaN or text)."""
    return isinstance(v, (int, float, np.integer, np.floating)) and math.isfinite(float(v))


def _mean_of(rows: list[dict[str, Any]], key: str) -> float:
    vals = [float(r[key]) for r in rows if finite(r.get(key))]
    return float(np.mean(vals)) if vals else math.nan


def _cleared(rows: list[dict[str, Any]], scenarios: list[str]) -> int:
    """Scenarios where every episode of ``rows`` on it has OFS 100 %."""
    n = 0
    for sc in scenarios:
        ofs = [r.get(_OFS) for r in rows if r["scenario"] == sc]
        n += bool(ofs) and all(finite(v) and float(v or 0.0) >= 100.0 for v in ofs)
    return n


def _scheduler_stats(
    rows: list[dict[str, Any]],
    failed: int,
    metric: str,
    scenarios: list[str],
    refs: dict[str, dict[tuple[str, int], float]],
    mine: Mapping[tuple[str, int], float],
) -> SchedulerStats:
    p50, p95 = _pooled_percentiles(rows)
    bounded, gap50, gap95 = _pooled_gaps(rows)
    frac: tuple[float, tuple[float, float], float] = (math.nan, (math.nan, math.nan), math.nan)
    if ORACLE in refs and IDLE in refs:
        sign = 1.0 if metric_direction(metric)[2] else -1.0  # lower is better: negate
        frac, _ = fraction_on_pairs(mine, refs[ORACLE], refs[IDLE], sign, lambda k: k[0])
    flags = {bool(r["deterministic"]) for r in rows if isinstance(r.get("deterministic"), bool)}
    return SchedulerStats(
        episodes=len(rows),
        failed=failed,
        mean=mean_ci([float(r[metric]) for r in rows]),
        instances=len(mine),
        fraction=frac[0],
        fraction_ci=frac[1],
        fraction_median_pair=frac[2],
        ofs=_mean_of(rows, _OFS),
        containment_s=_mean_of(rows, _TTC),
        burned=_mean_of(rows, _BURNED),
        cleared=_cleared(rows, scenarios),
        solve_p50_ms=p50,
        solve_p95_ms=p95,
        bounded_replans=bounded,
        gap_p50=gap50,
        gap_p95=gap95,
        fallbacks=int(sum(int(r.get("fallbacks") or 0) for r in rows)),
        replans=int(sum(int(r.get("replans") or 0) for r in rows)),
        deterministic=flags.pop() if len(flags) == 1 else None,
    )


def _check(
    stats: dict[str, SchedulerStats],
    pairs: list[PairedComparison],
    scenarios: list[str],
    sign: float,
    reference: Mapping[tuple[str, int], float] | None = None,
    scores: Mapping[str, Mapping[tuple[str, int], float]] | None = None,
    instances: int = 0,
) -> TierCheck:
    policies = tuple(k for k in stats if is_policy(k))
    cis = {k: stats[k].mean for k in policies}
    inside = all(
        cis[b].low <= cis[a].mean <= cis[b].high for a in policies for b in policies if a != b
    )
    top = None
    if reference and policies:
        top = all(on_top(reference, (scores or {}).get(k), cis[k].mean, sign) for k in policies)
    return TierCheck(
        policies=policies,
        separated=len(policies) > 1 and not inside,
        cleared_all=tuple(k for k, s in stats.items() if s.cleared == len(scenarios) > 0),
        resolved=sum(c.p_holm < HOLM_LEVEL for c in pairs),
        pairs=len(pairs),
        oracle_top=top,
        incomplete=tuple(k for k in policies if stats[k].instances < instances),
    )


def _tier(suite: str, tier: str, rows: list[dict[str, Any]], metric: str) -> TierResult:
    ok = [r for r in rows if r.get("status", "ok") == "ok" and finite(r.get(metric))]
    labels = list(dict.fromkeys(str(r["scheduler"]) for r in rows))
    scenarios = sorted({str(r["scenario"]) for r in rows})
    by = {k: [r for r in ok if r["scheduler"] == k] for k in labels}
    sign = 1.0 if metric_direction(metric)[2] else -1.0
    scores = {k: _scores(by[k], metric) for k in labels}
    refs = {IDLE: scores[IDLE]} if by.get(IDLE) else {}
    oracles = [k for k in labels if k.startswith(ORACLE) and by[k]]
    used = complete_variants({k: scores[k] for k in oracles})
    if used:
        refs[ORACLE] = reference_scores([scores[k] for k in used], sign)
    stats = {
        k: _scheduler_stats(by[k], sum(r["scheduler"] == k for r in rows) - len(by[k]),
                            metric, scenarios, refs, scores[k])
        for k in labels if by[k]
    }  # fmt: skip
    instances = len({_instance(r) for r in rows})
    policies = sorted(
        (k for k in stats if is_policy(k)),
        key=lambda k: (stats[k].instances < instances, -sign * stats[k].mean.mean),
    )
    others = [k for k in stats if not is_policy(k)]
    order = policies + sorted(others, key=lambda k: (k != ORACLE, not k.startswith(ORACLE), k))
    pairs = paired_table(ok, policies, metric, _instance) if len(policies) > 1 else []
    return TierResult(
        suite=suite,
        tier=tier,
        scenarios=scenarios,
        seeds=sorted({int(r["seed"]) for r in rows}),
        metric=metric,
        stats=stats,
        order=order,
        pairs=pairs,
        check=_check(
            stats,
            pairs,
            scenarios,
            sign,
            refs.get(ORACLE),
            {k: scores[k] for k in policies},
            instances,
        ),  # fmt: skip
        instances=instances,
        settings={k: _settings(by[k]) for k in order if _settings(by[k])},
        per_scenario={sc: _scenario_means(by, order, sc, metric) for sc in scenarios},
        reference=tuple(used),
    )


def _scenario_means(
    by: Mapping[str, list[dict[str, Any]]], order: list[str], scenario: str, metric: str
) -> dict[str, tuple[float, float, int]]:
    """Label -> (mean ``metric``, mean OFS, episodes) on one scenario (labels with episodes)."""
    out = {}
    for k in order:
        rows = [r for r in by[k] if r["scenario"] == scenario]
        if rows:
            out[k] = (_mean_of(rows, metric), _mean_of(rows, _OFS), len(rows))
    return out


def _scores(rows: list[dict[str, Any]], metric: str) -> dict[tuple[str, int], float]:
    return {(str(r["scenario"]), int(r["seed"])): float(r[metric]) for r in rows}


def _instance(row: Mapping[str, Any]) -> tuple[str, int]:
    """The (scenario, seed) an episode played: the pair key of the comparisons."""
    return str(row["scenario"]), int(row["seed"])


def _settings(rows: list[dict[str, Any]]) -> str:
    """The scheduler settings the rows recorded (JSON text in sweep results), as text."""
    texts = {r.get("settings") for r in rows if isinstance(r.get("settings"), str)}
    out = []
    for text in sorted(t for t in texts if t):
        doc = json.loads(text)
        out.append(", ".join(f"{k}={json.dumps(v)}" for k, v in sorted(doc.items())))
    return "; ".join(o for o in out if o)


def _meta(rows: list[dict[str, Any]], wall: float | None) -> dict[str, Any]:
    versions = sorted({str(r["versions"]) for r in rows if isinstance(r.get("versions"), str)})
    done = [str(r["finished_at"]) for r in rows if isinstance(r.get("finished_at"), str)]
    busy, last = math.nan, -math.inf  # the union of the episodes' run intervals (pauses left out)
    if done and all(finite(r.get("episode_wall_s")) for r in rows):
        ends = [_dt.datetime.fromisoformat(str(r["finished_at"])).timestamp() for r in rows]
        busy = 0.0
        for a, b in sorted((e - float(r["episode_wall_s"]), e) for e, r in zip(ends, rows, strict=True)):  # fmt: skip
            busy, last = busy + max(b - max(a, last), 0.0), max(last, b)
    return {
        "episodes": len(rows),
        "failed": sum(r.get("status", "ok") != "ok" for r in rows),
        "libraries": [json.loads(v) for v in versions],
        "finished": max(done) if done else "",
        "wall_time_s": wall if wall is not None else busy,
        "episode_time_s": float(sum(float(r.get("episode_wall_s") or 0.0) for r in rows)),
        "hosts": sorted({str(r["host"]) for r in rows if r.get("host")}),
        "code": count_code_versions(r.get("code") for r in rows),
        "suites": sorted({tier_of(str(r["scenario"]))[0] for r in rows} - {""}),
    }


def leaderboard(
    source: str | os.PathLike[str] | Iterable[dict[str, Any]] | Sequence[Any],
    *,
    metric: str = HEADLINE,
) -> Leaderboard:
    """The leaderboard of episodes: a results folder, a ``compare --json`` file, a list of those,
    or episode rows (dicts with ``scenario``, ``scheduler``, ``seed``, ``status`` and the metric).

    Raises
    ------
    FcplanError
        No episodes, or an unknown metric column (one line).
    """
    paths = [source] if isinstance(source, (str, os.PathLike)) else list(source)
    rows: list[dict[str, Any]] = []
    for item in paths:
        rows.extend(read_episodes(item) if isinstance(item, (str, os.PathLike)) else [dict(item)])
    walls = [float(r["__wall_time_s"]) for r in rows if "__wall_time_s" in r]
    rows = [r for r in rows if "__wall_time_s" not in r]
    if not rows:
        raise FcplanError("leaderboard: no episodes in the results")
    if not any(metric in r for r in rows):
        raise FcplanError(f"leaderboard: no column {metric!r} in the results")
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(tier_of(str(r["scenario"])), []).append(r)
    order = sorted(groups, key=lambda k: (k[0] == "", k))
    tiers = [_tier(suite, tier, groups[(suite, tier)], metric) for suite, tier in order]
    return Leaderboard(metric, tiers, _meta(rows, sum(walls) if walls else None))
