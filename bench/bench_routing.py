"""Benchmark the ``routing`` scheduler: solve times and scores.

Prints:

* per-replan solve time (p50 / p95, ms, measured by :func:`fcplan.scheduling.solve`), statuses
  and fallbacks over whole episodes of the shipped scenarios #1, #12 and #24 (seed 0, the default
  100 ms limit);
* solve time, model size, task visits planned and status on synthetic graphs of 10 x 100, 50 x 500 and 100 x 2000
  (agents x tasks; several seeds; default settings, then deterministic mode);
* the mean manual final score (and OFS) of ``routing`` and ``greedy`` over scenarios 1-24, seed 0,
  played in a process pool of 2;
* with ``--time-limit``, whether ``plan()`` honours its wall-time limit (issue 15): on the task
  graphs of greedy episodes of scenarios 1-24 (seed 0, every ``--every`` simulated seconds), each
  backend plans every graph of a scenario in order (warm-started from its previous plan) at each
  limit; prints the wall time of ``plan()`` as a multiple of the limit (p50 / p99 / max), the share
  of calls within ``limit * 1.1 + 5 ms``, statuses and failures (RoutingFailedError: greedy stands
  in), and the machine's load average;
* with ``--first-solutions``, the objective of each OR-Tools first-solution strategy on the
  scheduler's own models (graphs of greedy episodes of scenarios 2, 4, 12, 21, 24 and the
  open-world example at 10, 30, 60, 90, 120 s, and three 10 x 100 synthetic graphs;
  deterministic mode, no warm start), relative to the best strategy on each graph;
* with ``--paired BEFORE.json AFTER.json`` (two ``fcplan compare --json`` files over the same
  scenarios and seeds), the paired difference AFTER - BEFORE of each scheduler's manual final
  score, and of routing - greedy within each file: mean and 95 % t-interval over the
  (scenario, seed) pairs.

Usage::

    python bench/bench_routing.py                   # everything (~15 min on 2 cores)
    python bench/bench_routing.py --scores-only --set fire_value_px=1000
    python bench/bench_routing.py --no-scores --seeds 2
    python bench/bench_routing.py --time-limit 0.1 0.02      # issue 15 only (~3 min)
    python bench/bench_routing.py --first-solutions          # ~2 min
    python bench/bench_routing.py --paired before.json after.json
"""

from __future__ import annotations

import argparse
import collections
import os
import statistics
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import fcplan
from fcplan.scheduling import make_scheduler, solve
from fcplan.taskgraph import TaskGraph, build_task_graph, synthetic_task_graph
from solvers.routing import RoutingFailedError, RoutingScheduler


def pct(a, q) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


def bench_episodes(settings: dict) -> None:
    print("## Episodes (seed 0): per-replan solve time")
    print(
        f"{'scenario':<9} {'replans':>7} {'p50 ms':>7} {'p95 ms':>7} {'max ms':>7} "
        f"{'fallbacks':>9}  statuses"
    )
    for sc in (1, 12, 24):
        r = fcplan.run_episode(sc, RoutingScheduler(**settings), seed=0)
        st = r.solve_times_s * 1e3
        statuses = collections.Counter(s.status for s in r.solves)
        print(
            f"{sc!s:<9} {len(st):>7} {pct(st, 50):>7.1f} {pct(st, 95):>7.1f} {st.max():>7.1f} "
            f"{r.fallbacks:>9}  {dict(statuses)}"
        )


def bench_synthetic(settings: dict, seeds: int) -> None:
    print("\n## Synthetic graphs: wall time per replan (solve(), ms), model size, status")
    print(
        f"{'size':<10} {'mode':<13} {'p50 ms':>7} {'max ms':>7} {'vehicles':>8} {'nodes':>6} "
        f"{'visits':>6}  statuses"
    )
    for n_agents, n_tasks in ((10, 100), (50, 500), (100, 2000)):
        graphs = [
            synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(s)) for s in range(seeds)
        ]
        for mode, extra in (("time 100 ms", {}), ("deterministic", {"deterministic": True})):
            sched = RoutingScheduler(**{**settings, **extra})
            times, statuses, nodes, visits = [], collections.Counter(), [], []
            for g in graphs:
                p = solve(sched, g, time_limit=None, rng=np.random.default_rng(0))
                times.append(p.stats.wall_time_s * 1e3)
                statuses[p.stats.status] += 1
                nodes.append(p.stats.size.get("nodes", 0))
                visits.append(p.n_assignments)
            print(
                f"{n_agents}x{n_tasks:<7} {mode:<13} {pct(times, 50):>7.1f} {max(times):>7.1f} "
                f"{n_agents:>8} {statistics.mean(nodes):>6.0f} {statistics.mean(visits):>6.0f}  "
                f"{dict(statuses)}"
            )


def _score(job):
    sc, name, settings = job
    sched = RoutingScheduler(**settings) if name == "routing" else name
    r = fcplan.run_episode(sc, sched, seed=0)
    m = r.metrics["manual"]
    return sc, name, m.final_score, m.overall_firefighting, r.fallbacks


def bench_scores(settings: dict) -> None:
    print("\n## Manual final score, scenarios 1-24, seed 0 (process pool of 2)")
    jobs = [(sc, name, settings) for sc in range(1, 25) for name in ("routing", "greedy")]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(2) as pool:
        rows = list(pool.map(_score, jobs))
    by = collections.defaultdict(dict)
    for sc, name, final, ofs, fb in rows:
        by[sc][name] = (final, ofs, fb)
    print(
        f"{'scenario':>8} {'routing':>9} {'greedy':>9} {'r OFS':>7} {'g OFS':>7} {'fallbacks':>9}"
    )
    for sc in sorted(by):
        r, g = by[sc]["routing"], by[sc]["greedy"]
        print(f"{sc:>8} {r[0]:>9.2f} {g[0]:>9.2f} {r[1]:>7.2f} {g[1]:>7.2f} {r[2]:>9}")
    mr = statistics.mean(by[sc]["routing"][0] for sc in by)
    mg = statistics.mean(by[sc]["greedy"][0] for sc in by)
    wins = sum(by[sc]["routing"][0] > by[sc]["greedy"][0] for sc in by)
    print(f"mean final: routing {mr:.2f}, greedy {mg:.2f}; routing better on {wins}/24")
    print(f"({time.perf_counter() - t0:.0f} s)")


def suite_graphs(every_s: int) -> dict[int, list[TaskGraph]]:
    """Task graphs of a greedy episode of each scenario 1-24 (seed 0), every ``every_s`` s."""
    from fcplan import World, load_scenario
    from fcplan.belief import Belief
    from fcplan.plan import plan_commands

    out = {}
    for sc_id in range(1, 25):
        sc = load_scenario(sc_id)
        world, belief, greedy = World().reset(sc, seed=0), Belief(sc), make_scheduler("greedy")
        graphs = []
        while not world.done:
            commands = None
            if world.tick % sc.ticks_per_second == 0:
                g = build_task_graph(sc, world.team, belief)
                if world.tick % (every_s * sc.ticks_per_second) == 0:
                    graphs.append(g)
                plan = solve(greedy, g, time_limit=None, rng=world.controller_rng)
                commands = plan_commands(plan, g)
            belief.update(world.step(commands))
        out[sc_id] = graphs
    return out


def bench_time_limit(settings: dict, limits: list[float], every_s: int) -> None:
    graphs = suite_graphs(every_s)
    n = sum(len(v) for v in graphs.values())
    print(f"\n## plan() wall time against its limit: {n} graphs of scenarios 1-24 (seed 0, every "
          f"{every_s} s), warm-started in order")  # fmt: skip
    print(f"{'backend':<8} {'limit s':>7} {'p50 x':>6} {'p99 x':>6} {'max x':>6} "
          f"{'within':>7} {'failed':>6}  statuses  (load)")  # fmt: skip
    for backend in ("ortools", "pyvrp"):
        for limit in limits:
            walls, statuses, failed = [], collections.Counter(), 0
            load0 = os.getloadavg()[0]
            for sc_graphs in graphs.values():
                sched = RoutingScheduler(**{**settings, "backend": backend})
                for g in sc_graphs:
                    t0 = time.perf_counter()
                    try:
                        statuses[sched.plan(g, time_limit=limit, rng=None).stats.status] += 1
                    except RoutingFailedError:
                        failed += 1
                    walls.append(time.perf_counter() - t0)
            w = np.array(walls)
            within = float(np.mean(w <= 1.1 * limit + 0.005))
            print(f"{backend:<8} {limit:>7g} {pct(w, 50) / limit:>6.2f} {pct(w, 99) / limit:>6.2f} "
                  f"{w.max() / limit:>6.2f} {100 * within:>6.1f}% {failed:>6}  {dict(statuses)}  "
                  f"({load0:.1f}-{os.getloadavg()[0]:.1f})", flush=True)  # fmt: skip


FIRST_SOLUTIONS = (
    "PATH_CHEAPEST_ARC",
    "PARALLEL_CHEAPEST_INSERTION",
    "CHRISTOFIDES",
    "SAVINGS",
    "LOCAL_CHEAPEST_INSERTION",
    "GLOBAL_CHEAPEST_ARC",
)


def bench_first_solutions(settings: dict) -> None:
    from tests.solvers.graphs import episode_graphs

    graphs = [
        g
        for sc in (2, 4, 12, 21, 24, "open_world_example")
        for g in episode_graphs(sc, (100, 300, 600, 900, 1200))
    ]
    graphs += [synthetic_task_graph(10, 100, np.random.default_rng(s)) for s in range(3)]
    objective = np.array([
        [
            RoutingScheduler(**{**settings, "first_solution": fs, "deterministic": True,
                                "warm_start": False})
            .plan(g, time_limit=None, rng=None).stats.objective
            for g in graphs
        ]
        for fs in FIRST_SOLUTIONS
    ])  # fmt: skip
    best = objective.min(axis=0)
    print(f"\n## First solutions on the scheduler's models ({len(graphs)} graphs, deterministic)")
    print(f"{'first solution':<28} {'mean above best':>15} {'max above best':>14} {'best on':>8}")
    for fs, row in zip(FIRST_SOLUTIONS, objective, strict=True):
        rel = 100 * (row / best - 1)
        print(f"{fs:<28} {rel.mean():>14.2f}% {rel.max():>13.2f}% "
              f"{int(np.sum(row <= best + 1e-6)):>4}/{len(best)}")  # fmt: skip


def _scores(path: str, metric: str) -> dict[tuple[str, int, str], float]:
    import json
    from pathlib import Path

    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    return {
        (str(e["scenario"]), int(e["seed"]), e["scheduler"]): float(e[metric])
        for e in doc["episodes"]
        if e.get(metric) is not None and not e.get("error")
    }


def _mean_ci(d: np.ndarray) -> str:
    from scipy import stats

    half = stats.t.ppf(0.975, len(d) - 1) * d.std(ddof=1) / np.sqrt(len(d))
    return f"{d.mean():+7.2f} [{d.mean() - half:+.2f}, {d.mean() + half:+.2f}] (n={len(d)})"


def bench_paired(before: str, after: str, metric: str = "manual.final_score") -> None:
    b, a = _scores(before, metric), _scores(after, metric)
    print(f"\n## Paired differences of {metric} (mean, 95 % t-interval)")
    for sched in sorted({k[2] for k in a}):
        keys = sorted(k for k in a if k[2] == sched and k in b)
        d = np.array([a[k] - b[k] for k in keys])
        print(f"{sched:<10} after - before  {_mean_ci(d)}")
    for name, sc in (("before", b), ("after", a)):
        keys = sorted(k for k in sc if k[2] == "routing" and (k[0], k[1], "greedy") in sc)
        d = np.array([sc[k] - sc[(k[0], k[1], "greedy")] for k in keys])
        print(f"routing - greedy ({name}) {_mean_ci(d)}")


def _parse(v: str):
    if v in ("True", "False", "None"):
        return {"True": True, "False": False, "None": None}[v]
    for cast in (int, float):
        try:
            return cast(v)
        except ValueError:
            pass
    return v


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", action="append", default=[], help="scheduler setting key=value")
    ap.add_argument("--seeds", type=int, default=3, help="synthetic graphs per size")
    ap.add_argument("--scores-only", action="store_true")
    ap.add_argument("--no-scores", action="store_true")
    ap.add_argument(
        "--time-limit",
        type=float,
        nargs="+",
        default=None,
        help="only check plan() against these wall-time limits (s)",
    )
    ap.add_argument("--every", type=int, default=5, help="seconds between graphs (--time-limit)")
    ap.add_argument("--first-solutions", action="store_true")
    ap.add_argument("--paired", nargs=2, metavar=("BEFORE", "AFTER"))
    args = ap.parse_args()
    settings = {}
    for kv in args.set:
        k, _, v = kv.partition("=")
        settings[k] = _parse(v)
    if args.paired:
        bench_paired(*args.paired)
        return
    if args.first_solutions:
        bench_first_solutions(settings)
        return
    if args.time_limit:
        bench_time_limit(settings, args.time_limit, args.every)
        return
    if not args.scores_only:
        bench_episodes(settings)
        bench_synthetic(settings, args.seeds)
    if not args.no_scores:
        bench_scores(settings)


if __name__ == "__main__":
    main()
