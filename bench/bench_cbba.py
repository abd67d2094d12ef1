"""Benchmark the ``cbba`` scheduler: time limits, the deterministic round cap, rounds and messages.

Prints (the machine's load average first: the wall-clock figures depend on it):

* **The reference check**: fcplan's CBBA on the static cases of ``tests/solvers/data/cbba/``
  (``insertion="append"``, the reference's rule, and ``"anywhere"``, the scheduler's) against
  the reference's assignments, scores, iterations and last change, per communication graph
  kind; and both rules against the exact optimum on the small cases (no timing);
* **Wall mode on the manual suite**: whole episodes of scenarios 1-24 (seed 0) with a time limit
  per replan; per limit, the ``plan()`` wall time p50 / p95 / p99 / max (ms) against the bound
  ``limit * 1.1 + 5 ms``, the p99 of this process's CPU time per call, how many calls exceeded
  the bound in wall time (``over``) and in CPU time (``o.cpu``: the calls that overran by their
  own work, not because the operating system paused the process), how they ended (``heuristic``: converged,
  ``time_limit``: cut and completed, ``raised``: gave up, greedy fallback), agents completed
  greedily, and rounds / messages per replan;
* **Wall mode on synthetic graphs** of 50 x 500 and 100 x 2000 (agents x tasks, unlimited range
  and 300 px): the same per limit, plus the objective (sum of winning bids) relative to the
  unlimited run on the same graph;
* **Deterministic mode** on the same synthetic graphs: per ``max_rounds``, the time, the share
  converged, the objective relative to the unlimited run, and whether two runs gave identical
  plans;
* **Episodes**: per-replan solve time, rounds and messages for #1, #12 and #24 (seed 0, the
  scenario's range and 300 px);
* with ``--scores``: the mean manual final score of ``cbba`` and ``greedy`` on scenarios 1-24.

Usage::

    nice python bench/bench_cbba.py                  # everything but --scores (about 8 minutes)
    nice python bench/bench_cbba.py --quick          # fewer samples (about 2 minutes)
    nice python bench/bench_cbba.py --only synthetic --samples 100
    nice python bench/bench_cbba.py --scores --set half_life_s=3
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

import fcplan
from fcplan.taskgraph import TaskGraph, synthetic_task_graph
from solvers.cbba import CBBAScheduler
from solvers.cbba.clock import CBBATimeLimitError
from solvers.cbba.static import StaticInstance, solve_static

SIZES = ((50, 500), (100, 2000))
SYN_LIMITS = (0.05, 0.1, 0.2, 0.5)
SUITE_LIMITS = (0.002, 0.005, 0.02)
ROUND_CAPS = (1, 2, 5, 10, 500)


def pct(a, q) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


class Timed:
    """``CBBAScheduler`` that records the wall time and outcome of every ``plan()`` call."""

    name = "cbba"

    def __init__(self, **settings: Any) -> None:
        self.inner = CBBAScheduler(**settings)
        self.times: list[float] = []
        self.cpu: list[float] = []
        self.ends: list[str] = []
        self.sizes: list[dict] = []

    def plan(self, graph: TaskGraph, *, time_limit: float | None, rng: Any = None):
        t, c = time.perf_counter(), time.process_time()
        try:
            plan = self.inner.plan(graph, time_limit=time_limit, rng=rng)
        except CBBATimeLimitError:
            self.ends.append("raised")
            raise
        finally:
            self.times.append(time.perf_counter() - t)
            self.cpu.append(time.process_time() - c)
        self.ends.append(plan.stats.status)
        self.sizes.append(plan.stats.size)
        return plan


def limit_row(label: str, limit: float | None, t: Timed, extra: str = "") -> None:
    ms, cpu = np.array(t.times) * 1e3, np.array(t.cpu) * 1e3
    bound = None if limit is None else (1.1 * limit + 0.005) * 1e3
    over = 0 if bound is None else int((ms > bound).sum())
    over_cpu = 0 if bound is None else int((cpu > bound).sum())
    ends = Counter(t.ends)
    rounds = [s["rounds"] for s in t.sizes] or [0]
    msgs = [s["messages"] for s in t.sizes] or [0]
    completed = sum(s["completed"] for s in t.sizes)
    print(
        f"{label:<16} {'none' if limit is None else f'{limit * 1e3:g}':>6} {len(ms):>6} "
        f"{pct(ms, 50):>7.2f} {pct(ms, 95):>7.2f} {pct(ms, 99):>7.2f} {ms.max():>8.2f} "
        f"{pct(cpu, 99):>7.2f} "
        f"{'-' if bound is None else f'{bound:.1f}':>7} {over:>5} {over_cpu:>5} "
        f"{ends['heuristic']:>5} {ends['time_limit']:>5} {ends['raised']:>5} {completed:>6} "
        f"{int(np.median(rounds)):>6} {int(np.median(msgs)):>7}{extra}"
    )


HEADER = (
    f"{'case':<16} {'lim ms':>6} {'calls':>6} {'p50 ms':>7} {'p95 ms':>7} {'p99 ms':>7} "
    f"{'max ms':>8} {'cpu p99':>7} {'bound':>7} {'over':>5} {'o.cpu':>5} {'conv':>5} {'cut':>5} {'raise':>5} {'compl':>6} "
    f"{'rounds':>6} {'msgs':>7}"
)


def bench_suite(settings: dict, scenarios: range) -> None:
    print("## Wall mode on the manual suite: plan() per replan, scenarios 1-24, seed 0")
    print(HEADER + f" {'fallbk':>6}")
    for limit in (None, *SUITE_LIMITS):
        t = Timed(**settings)
        fallbacks = 0
        for name in scenarios:
            fallbacks += fcplan.run_episode(name, t, seed=0, time_limit=limit).fallbacks
        limit_row("suite", limit, t, f" {fallbacks:>6}")
    print()


def _synthetic(a: int, k: int, seed: int, comm: float | None) -> TaskGraph:
    return synthetic_task_graph(a, k, np.random.default_rng(seed), comm_range=comm)


def bench_synthetic(settings: dict, samples: int) -> None:
    print(f"## Wall mode on synthetic graphs: {samples} plan() calls per row (fresh graphs)")
    print(HEADER + f" {'obj/unlim':>9}")
    seeds = max(samples // 5, 1)
    for a, k in SIZES:
        for comm in (None, 300.0):
            base = {
                s: CBBAScheduler(**settings).run(_synthetic(a, k, s, comm)).objective
                for s in range(seeds)
            }
            label = f"{a}x{k} {'all' if comm is None else int(comm)}"
            for limit in SYN_LIMITS:
                t = Timed(**settings)
                ratios = []
                for n in range(samples):
                    s = n % seeds
                    g = _synthetic(a, k, s, comm)
                    try:
                        p = t.plan(g, time_limit=limit)
                        ratios.append(p.stats.objective / base[s])
                    except CBBATimeLimitError:
                        pass
                med = f"{np.median(ratios):9.3f}" if ratios else f"{'-':>9}"
                limit_row(label, limit, t, f" {med}")
    print()


def bench_deterministic(settings: dict, samples: int) -> None:
    print("## Deterministic mode (max_rounds per auction) on the same synthetic graphs")
    print(
        f"{'case':<16} {'rounds':>6} {'calls':>6} {'p50 ms':>7} {'p99 ms':>7} {'max ms':>8} "
        f"{'conv':>5} {'compl':>6} {'obj/unlim':>9} {'same plan twice':>15}"
    )
    seeds = max(samples // 5, 1)
    for a, k in SIZES:
        for comm in (None, 300.0):
            label = f"{a}x{k} {'all' if comm is None else int(comm)}"
            gs = [_synthetic(a, k, s, comm) for s in range(seeds)]
            base = [CBBAScheduler(**settings).run(g).objective for g in gs]
            for cap in ROUND_CAPS:
                cbba = CBBAScheduler(**{**settings, "deterministic": True, "max_rounds": cap})
                ts, conv, compl, ratio, same = [], 0, 0, [], True
                for g, b in zip(gs, base, strict=True):
                    t = time.perf_counter()
                    p = cbba.plan(g, time_limit=1e-3, rng=None)
                    ts.append((time.perf_counter() - t) * 1e3)
                    q = cbba.plan(g, time_limit=None, rng=None)
                    same &= dict(p.routes) == dict(q.routes) and p.stats.size == q.stats.size
                    conv += p.stats.size["converged"]
                    compl += p.stats.size["completed"]
                    ratio.append(p.stats.objective / b)
                print(
                    f"{label:<16} {cap:>6} {len(ts):>6} {pct(ts, 50):>7.1f} {pct(ts, 99):>7.1f} "
                    f"{max(ts):>8.1f} {conv:>5} {compl:>6} {np.median(ratio):>9.3f} "
                    f"{'yes' if same else 'NO':>15}"
                )
    print()


def bench_reference() -> None:
    """fcplan's static CBBA against the reference cases of tests/solvers/data/cbba/."""
    from tests.solvers.test_cbba_reference import CASES, SMALL, instance, optimum

    print("## Static cases against zehuilu/CBBA-Python (tests/solvers/data/cbba/), per graph kind")
    print(
        f"{'graph':<6} {'cases':>5} {'append=ref':>10} {'any>=ref':>8} {'any/ref mean':>12} "
        f"{'min':>6} {'max':>6} {'rounds app/any/ref':>18} {'last change app/any/ref':>23}"
    )
    rows: dict[str, list] = {}
    for case in CASES:
        inst, ref = StaticInstance.from_dict(case), case["reference"]
        app, anyw = solve_static(inst, insertion="append"), solve_static(inst)
        rows.setdefault(case["comm"], []).append((case, ref, app, anyw))
    for kind, got in rows.items():
        ratio = [a.score / r["score"] for _, r, _, a in got]
        mean = lambda xs: float(np.mean(xs))  # noqa: E731
        print(
            f"{kind:<6} {len(got):>5} {sum(p.paths == r['paths'] for _, r, p, _ in got):>10} "
            f"{sum(x >= 1 - 1e-12 for x in ratio):>8} {mean(ratio):>12.4f} {min(ratio):>6.4f} "
            f"{max(ratio):>6.4f} "
            f"{mean([p.rounds for *_, p, _ in got]):>6.1f}/{mean([a.rounds for *_, a in got]):.1f}/"
            f"{mean([r['iterations'] for _, r, *_ in got]):.1f}"
            f"{mean([p.last_change for *_, p, _ in got]):>13.1f}/"
            f"{mean([a.last_change for *_, a in got]):.1f}/{mean([r['last_change'] for _, r, *_ in got]):.1f}"
        )
    ratios = {"append": [], "anywhere": []}
    for name in SMALL:
        best = optimum(instance(name))
        for rule, xs in ratios.items():
            xs.append(solve_static(instance(name), insertion=rule).score / best)
    for rule, xs in ratios.items():
        print(
            f"{rule:<8} / exact optimum on {len(xs)} small cases: min {min(xs):.4f} "
            f"mean {np.mean(xs):.4f}, optimal on {sum(x > 1 - 1e-9 for x in xs)}"
        )
    print()


def bench_episodes(settings: dict) -> None:
    print("## Episodes (seed 0, no limit): per-replan solve time, rounds and messages")
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
    print()


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="20 samples, scenarios 1-8")
    p.add_argument("--samples", type=int, default=50, help="plan() calls per synthetic row")
    p.add_argument(
        "--only", choices=("reference", "suite", "synthetic", "deterministic", "episodes")
    )
    p.add_argument("--scores", action="store_true", help="also the 24-scenario score table")
    p.add_argument("--set", action="append", default=[], help="scheduler setting name=value")
    args = p.parse_args()
    settings: dict[str, Any] = {}
    for kv in args.set:
        key, _, val = kv.partition("=")
        settings[key] = float(val) if "." in val or "e" in val else int(val)
    samples = 20 if args.quick else args.samples
    scenarios = range(1, 9) if args.quick else range(1, 25)
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"load average {load} on {os.cpu_count()} cores; settings {settings or 'defaults'}\n")
    if args.only in (None, "reference"):
        bench_reference()
    if args.only in (None, "suite"):
        bench_suite(settings, scenarios)
    if args.only in (None, "synthetic"):
        bench_synthetic(settings, samples)
    if args.only in (None, "deterministic"):
        bench_deterministic(settings, samples)
    if args.only in (None, "episodes"):
        bench_episodes(settings)
    if args.scores:
        bench_scores(settings)
    print(f"load average at the end {', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
