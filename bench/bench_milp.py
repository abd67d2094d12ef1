"""Benchmark the MILP schedulers: time per replan against the limit, statuses, model sizes.

Plays whole episodes of the manual suite in a process pool with ``milp`` (and ``milp-cvxpy`` on
a few scenarios) and times every ``plan()`` call itself (model building, solve and decoding; the
greedy fallback and plan validation of :func:`fcplan.scheduling.solve` are not in it):

* **deterministic mode** (no time limit, the default in comparisons): wall and CPU ms per call
  p50 / p95 / p99 / max, statuses (share proved optimal), fallbacks, CP-SAT deterministic time,
  model sizes (routes, variables, rows, nonzeros) p50 / p95 / max;
* **wall-clock mode** (``--limits``, e.g. 0.02 0.05 0.2 s passed as ``time_limit``): per limit,
  the call's wall time over the limit p50 / p95 / p99 / max, the share of calls within
  ``limit * 1.1 + 5 ms`` (the promise), and how the calls ended (optimal, time_limit, raised:
  then :func:`fcplan.scheduling.solve` falls back to greedy).

Usage::

    python bench/bench_milp.py                                  # 1-24 seed 0, both modes
    python bench/bench_milp.py --scenarios 1-24 --seeds 0-1 --limits 0.05 0.2 --jobs 2
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import fcplan
from fcplan.experiments.ranges import parse_range
from fcplan.scheduling import make_scheduler


class _Timed:
    """Wraps a scheduler and records the wall and CPU time and the outcome of every call."""

    def __init__(self, inner) -> None:
        self.inner, self.name, self.rows = inner, inner.name, []

    def plan(self, graph, *, time_limit=None, rng=None):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            plan = self.inner.plan(graph, time_limit=time_limit, rng=rng)
            outcome, size = plan.stats.status, plan.stats.size
        except Exception as exc:  # noqa: BLE001 - recorded, then solve() falls back
            plan, outcome, size = None, f"raised {type(exc).__name__}", {}
        self.rows.append((time.perf_counter() - t0, time.process_time() - c0, outcome, size))
        if plan is None:
            raise RuntimeError(outcome)
        return plan


def _episode(job):
    name, scenario, seed, limit = job
    sched = _Timed(make_scheduler(name))
    r = fcplan.run_episode(scenario, sched, seed=seed, time_limit=limit)
    return {"job": job, "rows": sched.rows, "final": r.metrics["manual"].final_score}


def _pct(a, q) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


def report_deterministic(name: str, results) -> None:
    rows = [row for r in results for row in r["rows"]]
    wall = np.array([w for w, *_ in rows]) * 1e3
    cpu = np.array([c for _, c, *_ in rows]) * 1e3
    st = Counter(o for *_, o, _ in rows)
    n = len(rows)
    print(f"## {name}, deterministic mode: {len(results)} episodes, {n} calls")
    for label, a in (("wall ms", wall), ("cpu ms", cpu)):
        print(
            f"{label:<8} p50 {_pct(a, 50):7.1f}  p95 {_pct(a, 95):7.1f}  p99 {_pct(a, 99):7.1f}"
            f"  max {a.max():7.1f}"
        )
    print(f"optimal {st['optimal'] / n:.2%};  outcomes {dict(st)}")
    for key in ("deterministic_time", "routes", "variables", "constraints", "nonzeros"):
        v = [s[key] for *_, s in rows if key in s]
        if v:
            print(f"{key:<18} p50 {_pct(v, 50):9.3f}  p95 {_pct(v, 95):9.3f}  max {max(v):9.3f}")
    print(f"mean manual final score {np.mean([r['final'] for r in results]):.2f}\n")


def report_limits(name: str, results, limits) -> None:
    print(f"## {name}, wall-clock mode: plan() wall time / limit")
    print(f"{'limit s':>8} {'calls':>6} {'p50':>6} {'p95':>6} {'p99':>6} {'max':>6} "
          f"{'in promise':>10}  outcomes")  # fmt: skip
    for limit in limits:
        rows = [row for r in results if r["job"][3] == limit for row in r["rows"]]
        wall = np.array([w for w, *_ in rows])
        ratio = wall / limit
        ok = np.mean(wall <= 1.1 * limit + 0.005)
        st = Counter(o for *_, o, _ in rows)
        print(
            f"{limit:>8g} {len(rows):>6} {_pct(ratio, 50):>6.2f} {_pct(ratio, 95):>6.2f} "
            f"{_pct(ratio, 99):>6.2f} {ratio.max():>6.2f} {ok:>10.2%}  {dict(st)}"
        )
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", default="1-24")
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--cvxpy-scenarios", default="1,12,24")
    ap.add_argument("--limits", nargs="*", type=float, default=[0.02, 0.05, 0.2])
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    scenarios, seeds = parse_range(args.scenarios), parse_range(args.seeds, names=False)
    jobs = [("milp", sc, sd, None) for sc in scenarios for sd in seeds]
    jobs += [
        ("milp-cvxpy", sc, sd, None) for sc in parse_range(args.cvxpy_scenarios) for sd in seeds
    ]
    jobs += [("milp", sc, sd, lim) for lim in args.limits for sc in scenarios for sd in seeds]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.jobs) as ex:
        results = list(ex.map(_episode, jobs, chunksize=1))
    print(f"({len(jobs)} episodes took {time.perf_counter() - t0:.0f} s with {args.jobs} jobs)\n")
    for name in ("milp", "milp-cvxpy"):
        mine = [r for r in results if r["job"][0] == name and r["job"][3] is None]
        if mine:
            report_deterministic(name, mine)
    if args.limits:
        report_limits("milp", [r for r in results if r["job"][3] is not None], args.limits)


if __name__ == "__main__":
    main()
