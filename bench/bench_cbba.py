"""Benchmark the ``cbba`` scheduler: solve times, consensus rounds and messages, and scores.

Prints:

* per-replan solve time (p50 / p95, ms), rounds and messages per replan over whole episodes of
  the shipped scenarios #1, #12 and #24 (seed 0; the scenario's own comm range, and 300 px);
* solve time, rounds and messages on synthetic graphs of 10 x 100, 50 x 500 and 100 x 2000
  (agents x tasks; unlimited range and 300 px; several seeds);
* the mean manual final score of ``cbba`` and ``greedy`` over scenarios 1-24, seed 0, played in
  a process pool of 2.

Usage::

    python bench/bench_cbba.py              # everything (a few minutes on 2 cores)
    python bench/bench_cbba.py --quick      # fewer synthetic seeds, no 100 x 2000
    python bench/bench_cbba.py --scores-only --set half_life_s=3 --set watch_weight=2
"""

from __future__ import annotations

import argparse
import statistics
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import fcplan
from fcplan.taskgraph import synthetic_task_graph
from solvers.cbba import CBBAScheduler


def pct(a, q) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


def bench_episodes(settings: dict) -> None:
    print("## Episodes (seed 0): per-replan solve time, rounds and messages")
    print(
        f"{'scenario':<9} {'comm px':>8} {'replans':>7} {'p50 ms':>7} {'p95 ms':>7} "
        f"{'rounds p50/max':>15} {'msgs p50/max':>14} {'comps max':>9} {'final':>7}"
    )
    for name in (1, 12, 24):
        base = fcplan.load_scenario(name)
        for comm in (base.comm_range, 300.0):
            sc = base.replace(comm_range=comm)
            res = fcplan.run_episode(sc, CBBAScheduler(**settings), seed=0)
            st = res.solve_times_s * 1e3
            rounds = [s.size["rounds"] for s in res.solves]
            msgs = [s.size["messages"] for s in res.solves]
            comps = max(s.size["components"] for s in res.solves)
            print(
                f"#{name:<8} {str(comm):>8} {len(res.solves):>7} {pct(st, 50):>7.2f} "
                f"{pct(st, 95):>7.2f} {int(np.median(rounds)):>7}/{max(rounds):<7} "
                f"{int(np.median(msgs)):>6}/{max(msgs):<7} {comps:>9} "
                f"{res.metrics['manual'].final_score:>7.1f}"
            )
    print()


def bench_synthetic(sizes, seeds: int, settings: dict) -> None:
    print("## Synthetic graphs (1200 px map): one solve each, median over seeds")
    print(
        f"{'agents x tasks':<15} {'comm px':>8} {'seeds':>5} {'ms p50':>8} {'ms max':>8} "
        f"{'rounds':>7} {'messages':>9} {'assigned':>8} {'converged':>9}"
    )
    for a, k in sizes:
        for comm in (None, 300.0):
            ts, rounds, msgs, assigned, conv = [], [], [], [], []
            for seed in range(seeds):
                g = synthetic_task_graph(a, k, np.random.default_rng(seed), comm_range=comm)
                t = time.perf_counter()
                res = CBBAScheduler(**settings).run(g)
                ts.append((time.perf_counter() - t) * 1e3)
                rounds.append(res.rounds)
                msgs.append(res.messages)
                assigned.append(sum(len(r) for r in res.routes.values()))
                conv.append(res.converged)
            print(
                f"{f'{a} x {k}':<15} {str(comm):>8} {seeds:>5} {statistics.median(ts):>8.1f} "
                f"{max(ts):>8.1f} {statistics.median(rounds):>7.0f} "
                f"{statistics.median(msgs):>9.0f} {statistics.median(assigned):>8.0f} "
                f"{sum(conv):>5}/{seeds:<3}"
            )
    print()


def _episode(job):
    name, scheduler, settings = job
    sched = CBBAScheduler(**settings) if scheduler == "cbba" else scheduler
    res = fcplan.run_episode(name, sched, seed=0)
    return name, scheduler, res.metrics["manual"].final_score, res.fallbacks


def bench_scores(settings: dict, jobs: int = 2) -> None:
    print("## Mean manual final score, scenarios 1-24, seed 0 (process pool of 2)")
    work = [(n, s, settings) for n in range(1, 25) for s in ("cbba", "greedy")]
    with ProcessPoolExecutor(jobs) as pool:
        out = list(pool.map(_episode, work))
    score = {(n, s): f for n, s, f, _ in out}
    fallbacks = {s: sum(fb for _, s2, _, fb in out if s2 == s) for s in ("cbba", "greedy")}
    better = sum(score[(n, "cbba")] > score[(n, "greedy")] + 1e-9 for n in range(1, 25))
    worse = sum(score[(n, "cbba")] < score[(n, "greedy")] - 1e-9 for n in range(1, 25))
    for s in ("cbba", "greedy"):
        vals = [score[(n, s)] for n in range(1, 25)]
        print(f"{s:<7} mean {np.mean(vals):7.2f}  min {min(vals):7.2f}  fallbacks {fallbacks[s]}")
    print(f"cbba better on {better}, worse on {worse} of 24 scenarios")
    print(
        "per scenario (cbba - greedy): "
        + " ".join(f"{n}:{score[(n, 'cbba')] - score[(n, 'greedy')]:+.1f}" for n in range(1, 25))
    )
    print()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--scores-only", action="store_true")
    p.add_argument("--set", action="append", default=[], help="scheduler setting name=value")
    args = p.parse_args()
    settings = {}
    for kv in args.set:
        key, _, val = kv.partition("=")
        settings[key] = float(val) if "." in val or "e" in val else int(val)
    if settings:
        print(f"settings: {settings}\n")
    if not args.scores_only:
        bench_episodes(settings)
        sizes = [(10, 100), (50, 500)] if args.quick else [(10, 100), (50, 500), (100, 2000)]
        bench_synthetic(sizes, 2 if args.quick else 5, settings)
    bench_scores(settings)


if __name__ == "__main__":
    main()
