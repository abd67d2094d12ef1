"""Planning latency: how much does it cost a scheduler that the world keeps running while it
thinks?

``run_episode(..., latency=...)`` (:meth:`fcplan.mission.Mission.run`) lets a plan made at tick
``t`` apply only from tick ``t + N``; the team flies its last orders meanwhile. This script plays
each scheduler on a few manual scenarios and seeds three ways:

* ``none``: ``latency=None``, the world waits for the planner (the manual's game);
* ``own``: ``latency="ticks:N"`` with ``N = ceil(median solve CPU seconds x ticks per second)``,
  the scheduler's own planning time, measured as the median CPU time of its ``plan`` calls in
  the ``none`` episodes (CPU, not wall time, so that a loaded machine does not inflate it; at
  least one tick);
* ``fixed``: ``latency="ticks:K"`` with the same ``K`` (``--fixed-ticks``, default 5: half a
  second) for every scheduler, to compare schedulers at an equal planning delay.

Schedulers that have one run in their deterministic mode, so each episode is reproducible and
the ``ticks:N`` rule makes the whole comparison so. It prints, per scheduler, ``N``, the mean
final score (manual) of each condition and the paired difference to ``none`` (mean and 95 %
t-interval over the (scenario, seed) pairs, ``n`` pairs; "cannot tell" when the interval holds
0), then every pair of schedulers under each condition (paired, Holm-adjusted Wilcoxon
p-values, :func:`fcplan.experiments.stats.paired_comparisons`).

Usage::

    nice python bench/bench_latency.py                        # ~10 min on 2 quiet cores
    nice python bench/bench_latency.py --scenarios 2,12,24 --seeds 0-3 --schedulers greedy,cbba
"""

from __future__ import annotations

import argparse
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from fcplan import run_episode
from fcplan.experiments.ranges import parse_range
from fcplan.experiments.stats import mean_ci, paired_comparisons
from fcplan.scheduling import make_scheduler, supports_deterministic


class CpuTimed:
    """A scheduler that records the CPU seconds of every ``plan`` call of the one it wraps."""

    def __init__(self, inner: Any) -> None:
        self.inner, self.name, self.cpu = inner, inner.name, []
        self.deterministic = getattr(inner, "deterministic", False)

    def plan(self, graph: Any, *, time_limit: float | None, rng: Any) -> Any:
        t0 = time.process_time()
        try:
            return self.inner.plan(graph, time_limit=time_limit, rng=rng)
        finally:
            self.cpu.append(time.process_time() - t0)


def scheduler(name: str) -> Any:
    settings = {"deterministic": True} if supports_deterministic(name) else {}
    return make_scheduler(name, **settings)


def play(job: tuple[str, Any, int, str | None]) -> dict[str, Any]:
    """One episode; with ``latency=None`` also the median CPU seconds of a plan call."""
    name, scenario, seed, latency = job
    timed = CpuTimed(scheduler(name))
    res = run_episode(scenario, timed, seed=seed, latency=latency)
    return {
        "name": name, "scenario": scenario, "seed": seed, "latency": latency,
        "final": res.metrics["manual"].final_score, "fallbacks": res.fallbacks,
        "cpu_median": float(np.median(timed.cpu)) if timed.cpu else 0.0,
    }  # fmt: skip


def interval(d: np.ndarray) -> str:
    ci = mean_ci(d)
    tell = "" if ci.low > 0 or ci.high < 0 else "  cannot tell"
    return f"{ci.mean:+7.2f} [{ci.low:+7.2f}, {ci.high:+7.2f}]{tell}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", default="2,4,12,21,24")
    ap.add_argument("--seeds", default="0-3")
    ap.add_argument("--schedulers", default="greedy,routing,cbba")
    ap.add_argument("--fixed-ticks", type=int, default=5)
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    scenarios = [int(s) if s.isdigit() else s for s in args.scenarios.split(",")]
    seeds, names = parse_range(args.seeds), args.schedulers.split(",")
    pairs = [(sc, s) for sc in scenarios for s in seeds]
    load0, t0 = os.getloadavg()[0], time.time()
    with ProcessPoolExecutor(args.jobs) as ex:
        base = list(ex.map(play, [(n, sc, s, None) for n in names for sc, s in pairs]))
        own_ticks = {
            n: max(1, math.ceil(np.median([r["cpu_median"] for r in base if r["name"] == n]) * 10))
            for n in names
        }
        jobs = [(n, sc, s, f"ticks:{own_ticks[n]}") for n in names for sc, s in pairs]
        jobs += [(n, sc, s, f"ticks:{args.fixed_ticks}") for n in names for sc, s in pairs]
        rest = list(ex.map(play, jobs))
    rows = base + rest
    final = {(r["name"], r["scenario"], r["seed"], r["latency"]): r["final"] for r in rows}
    conditions = {
        "none": lambda n: None,
        "own": lambda n: f"ticks:{own_ticks[n]}",
        "fixed": lambda n: f"ticks:{args.fixed_ticks}",
    }

    def scores(n: str, cond: str) -> np.ndarray:
        return np.array([final[(n, sc, s, conditions[cond](n))] for sc, s in pairs])

    print(f"# scenarios {args.scenarios}, seeds {args.seeds} ({len(pairs)} pairs); load "
          f"{load0:.1f}-{os.getloadavg()[0]:.1f}; {time.time() - t0:.0f} s; ticks at 10 Hz")  # fmt: skip
    print(f"{'scheduler':<14} {'N':>3} {'none':>8} {'own':>8} {'fixed':>8}  "
          f"{'own - none (95 % CI)':<38} fixed - none (95 % CI)")  # fmt: skip
    for n in names:
        none, own, fixed = scores(n, "none"), scores(n, "own"), scores(n, "fixed")
        print(f"{n:<14} {own_ticks[n]:>3} {none.mean():>8.2f} {own.mean():>8.2f} "
              f"{fixed.mean():>8.2f}  {interval(own - none):<38} {interval(fixed - none)}")  # fmt: skip
    fb = sum(r["fallbacks"] for r in rows)
    print(f"fallbacks over all episodes: {fb}")
    for cond in conditions:
        print(f"\n## pairs of schedulers, latency {cond}")
        for c in paired_comparisons({n: scores(n, cond) for n in names}):
            tell = "" if c.resolved else "  cannot tell"
            print(f"{c.a:>12} - {c.b:<12} {c.diff.mean:+7.2f} [{c.diff.low:+7.2f}, "
                  f"{c.diff.high:+7.2f}]  p_holm {c.p_holm:.3g}{tell}")  # fmt: skip


if __name__ == "__main__":
    main()
