"""Benchmark the schedulers: solve times on the shipped scenarios and a scaling study.

Part 1 plays scenarios 1-24 (seed 0) with each scheduler and pools its per-replan solve times:
p50 / p95 / max, the share of replans that hit their time limit or fell back, the worst overrun of
the time limit, and (for MILP schedulers) the share of replans solved to proven optimality.

Part 2 solves synthetic task graphs (10, 50, 100 agents x 100, 500, 2,000 tasks) once per
scheduler: median solve time over repeats, the scheduler's own objective, and, where the MILP
proves one, the MILP's best bound and each scheduler's gap to it, all measured on the MILP's
objective (``solvers.milp_model.plan_objective``) so the numbers are comparable.

Usage::

    python bench/bench_schedulers.py                         # all registered schedulers
    python bench/bench_schedulers.py --schedulers greedy,milp --quick
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import fcplan
from fcplan.scheduling import available_schedulers, make_scheduler, solve
from fcplan.taskgraph import synthetic_task_graph

DEFAULT = ("greedy", "routing", "milp", "milp-cvxpy", "cbba")
SIZES = [(a, k) for a in (10, 50, 100) for k in (100, 500, 2000)]


def _episode(args):
    scenario, name, seed = args
    res = fcplan.run_episode(scenario, name, seed=seed)
    return (
        name,
        [s.wall_time_s for s in res.solves],
        [s.status for s in res.solves],
        [s.overrun_s for s in res.solves],
        [s.time_limit_s for s in res.solves],
        res.metrics["manual"].final_score,
    )


def shipped(schedulers, scenarios, jobs: int) -> None:
    print("## Per-replan solve time on the shipped scenarios (seed 0, replan every 1 s)")
    print(
        f"{'scheduler':<11} {'replans':>7} {'p50 ms':>8} {'p95 ms':>8} {'max ms':>8} "
        f"{'optimal':>8} {'t-limit':>8} {'fallback':>8} {'max overrun ms':>15} {'final':>7}"
    )
    jobs_list = [(s, n, 0) for n in schedulers for s in scenarios]
    with ProcessPoolExecutor(jobs) as ex:
        out = list(ex.map(_episode, jobs_list))
    for name in schedulers:
        rows = [r for r in out if r[0] == name]
        t = np.array([x for r in rows for x in r[1]]) * 1e3
        st = [x for r in rows for x in r[2]]
        over = max((x for r in rows for x in r[3]), default=0.0) * 1e3
        n = len(st)
        share = {k: sum(s == k for s in st) / n for k in ("optimal", "time_limit", "fallback")}
        final = statistics.mean(r[5] for r in rows)
        print(
            f"{name:<11} {n:>7} {np.percentile(t, 50):>8.2f} {np.percentile(t, 95):>8.2f} "
            f"{t.max():>8.2f} {share['optimal']:>8.1%} {share['time_limit']:>8.1%} "
            f"{share['fallback']:>8.1%} {over:>15.2f} {final:>7.1f}"
        )
    print()


def _objective_fn():
    try:
        from solvers.milp_model import plan_objective
    except ImportError:  # the MILP scheduler is not installed
        return None
    return plan_objective


def full_bound(graph, limit_s: float = 20.0) -> float:
    """Best bound of the MILP without candidate pruning (every task offered to every agent),
    or NaN when that model is too big to solve here (A x K > 5,000) or CP-SAT finds nothing."""
    if graph.n_agents * graph.n_tasks > 5_000:
        return math.nan
    sched = make_scheduler("milp", fire_candidates=graph.n_tasks, search_candidates=graph.n_tasks)
    try:
        plan = sched.plan(graph, time_limit=limit_s, rng=None)
    except RuntimeError:
        return math.nan
    return plan.stats.bound


def scaling(schedulers, sizes, repeats: int, time_limit: float | None) -> None:
    evaluate = _objective_fn()
    print("## Scaling on synthetic task graphs (one replan; median wall time over repeats)")
    print("objective: the plan scored on the full (unpruned) MILP model; bound: that model's")
    print("best bound (20 s CP-SAT), only where it fits (A x K <= 5,000); * = the plan breaks a")
    print("row only the MILP imposes (search spread), so its gap is not meaningful")
    print(
        f"{'agents':>6} {'tasks':>6} {'scheduler':<11} {'ms':>9} {'status':<10} "
        f"{'objective':>10} {'bound':>9} {'gap':>7}"
    )
    for a, k in sizes:
        graph = synthetic_task_graph(a, k, np.random.default_rng(a * 10_000 + k))
        bound = full_bound(graph) if evaluate else math.nan
        for name in schedulers:
            sched = make_scheduler(name)
            times, plan = [], None
            for r in range(repeats):
                t0 = time.perf_counter()
                plan = solve(sched, graph, time_limit=time_limit, rng=np.random.default_rng(r))
                times.append(time.perf_counter() - t0)
            if evaluate:
                obj, feasible = evaluate(graph, plan)
            else:
                obj, feasible = plan.stats.objective, True
            gap = (bound - obj) / abs(bound) if math.isfinite(bound) and bound else math.nan
            flag = "" if feasible else "*"
            print(
                f"{a:>6} {k:>6} {name:<11} {statistics.median(times) * 1e3:>9.1f} "
                f"{plan.stats.status:<10} {obj:>9.1f}{flag:1} {bound:>9.1f} {gap:>7.1%}"
            )
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--schedulers", default=",".join(DEFAULT))
    ap.add_argument("--quick", action="store_true", help="fewer scenarios, sizes and repeats")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument(
        "--time-limit",
        type=float,
        default=None,
        help="seconds per solve in the scaling study (default: each scheduler's own)",
    )
    args = ap.parse_args()
    names = [n for n in args.schedulers.split(",") if n]
    missing = sorted(set(names) - set(available_schedulers()))
    if missing:
        raise SystemExit(f"unknown schedulers: {', '.join(missing)}")
    print(
        f"fcplan {fcplan.__version__}, numpy {np.__version__}, Python "
        f"{platform.python_version()}, {os.cpu_count()} cores\n"
    )
    scenarios = ["1", "12", "24"] if args.quick else [str(i) for i in range(1, 25)]
    shipped(names, scenarios, args.jobs)
    sizes = SIZES[:2] if args.quick else SIZES
    scaling(names, sizes, 1 if args.quick else 3, args.time_limit)


if __name__ == "__main__":
    main()
