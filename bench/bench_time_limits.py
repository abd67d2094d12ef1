"""Does every scheduler honour its time limit? Solve times against the limit, per design.

For each design, task graphs are taken from ``greedy`` episodes (every ``--every`` simulated
seconds, :func:`fcplan.testing.episode_graphs`) or drawn with
:func:`fcplan.taskgraph.synthetic_task_graph`; each scheduler plans them through
:func:`fcplan.scheduling.solve`, one fresh scheduler per episode, the graphs of an episode in
order (so warm starts from the previous plan work as in an episode). Per (design, scheduler,
limit) it prints the wall time of the ``solve`` call (p50 / p95 / p99 / max, ms; fallbacks
included), the process's CPU time (p99), the bound ``limit * 1.1 + 5 ms`` and the share of calls
within it, the calls whose plan was replaced by greedy's (``fallbacks``; ``t/o``: of those, the
ones the clock caused: a time-out that left a role idle, or an exception past the limit), the
plans a MILP finished past its deadline instead of falling back (``late``,
:mod:`solvers.milp_model.scheduler`), the median gap where the scheduler proves a bound, and the load average when the row started and
ended.

``--episodes`` has each scheduler play its own episodes of the design's scenarios instead (seed
0, :func:`fcplan.run_episode` at the limit): every replan of the episode is a call, planned from
the scheduler's own states and warm-started from its own previous plan, about three replans per
simulated second on the scale tier (periodic and event replans). This is what issue 13's "0
fallbacks" is about; the graph mode is cheaper and the same for every scheduler.

``--floor`` adds a run at ``time_limit=1e-6``: what each scheduler costs when the clock has run out
before it starts (its *floor*: reading the graph, building its model, and greedy's plan when it
gives up).

Designs
-------
``suite``
    The manual's scenarios 1-24, seed 0.
``scale-tier``
    The benchmark's ``scale`` tier, ``fcplan-bench-v1/scale-01`` .. ``scale-06`` (18-30 agents,
    3,000-10,000 px maps), seed 0: what issue 13 measures.
``scale50``, ``scale100``
    Generated ``scale``-tier designs (:meth:`fcplan.scenario.GeneratorConfig.scale`) with 50 and
    100 agents (2 : 2 : 1 perception : action : hybrid) on a 4,000 px map, 240 s; scenario seeds
    0 and 1.
``synthetic``
    ``synthetic_task_graph`` at 10 / 50 / 100 agents x 200 / 2,000 tasks, ``--synthetic-seeds``
    graphs each (every call on a fresh graph).

Usage::

    nice python bench/bench_time_limits.py                       # all designs, 0.1 s (~15 min)
    nice python bench/bench_time_limits.py --designs suite --limits 0.05 0.1 --floor
    nice python bench/bench_time_limits.py --designs synthetic --schedulers routing,cbba
    python bench/bench_time_limits.py --designs scale-tier --episodes \
        --schedulers milp,milp-cvxpy,routing,routing-pyvrp,cbba     # whole episodes (~25 min)
"""

from __future__ import annotations

import argparse
import collections
import os
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from fcplan import load_scenario, run_episode
from fcplan.scenario import GeneratorConfig
from fcplan.scheduling import SolveStats, available_schedulers, make_scheduler, solve
from fcplan.taskgraph import TaskGraph, synthetic_task_graph
from fcplan.testing import episode_graphs

DESIGNS = ("suite", "scale-tier", "scale50", "scale100", "synthetic")
SYNTHETIC_SIZES = [(a, k) for a in (10, 50, 100) for k in (200, 2000)]


def scale_design(n_agents: int, seed: int):
    """A generated ``scale``-tier scenario with ``n_agents`` agents (2:2:1 perception, action,
    hybrid) on a 4,000 px map, 240 s long."""
    n_h = n_agents // 5
    n_p = (n_agents - n_h) // 2
    cfg = GeneratorConfig.scale(
        n_perception=n_p, n_action=n_agents - n_h - n_p, n_hybrid=n_h, world_size=4000,
        duration_s=240.0, late_delay_s=(30.0, 150.0),
    )  # fmt: skip
    return cfg(seed)


def scenarios_of(design: str) -> list[tuple[str, Any]]:
    """The (label, scenario) pairs of a design other than ``synthetic``."""
    if design == "suite":
        scenarios = [(str(i), load_scenario(i)) for i in range(1, 25)]
    elif design == "scale-tier":
        names = [f"fcplan-bench-v1/scale-{i:02d}" for i in range(1, 7)]
        scenarios = [(n.split("/")[1], load_scenario(n)) for n in names]
    else:
        n = int(design.removeprefix("scale"))
        scenarios = [(f"{design}-{s}", scale_design(n, s)) for s in (0, 1)]
    return scenarios


def sequences(design: str, every_s: int, synthetic_seeds: int) -> list[tuple[str, list[TaskGraph]]]:
    """The design's graphs as (label, graphs planned in order by one scheduler) pairs."""
    if design == "synthetic":
        return [
            (f"{a}x{k}", [synthetic_task_graph(a, k, np.random.default_rng(s))])
            for a, k in SYNTHETIC_SIZES
            for s in range(synthetic_seeds)
        ]
    return [
        (label, episode_graphs(sc, range(0, sc.n_ticks, every_s * sc.ticks_per_second)))
        for label, sc in scenarios_of(design)
    ]


def pct(a: np.ndarray, q: float) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


def record(st: SolveStats, limit: float, cpu: float) -> dict:
    """One call's record: wall and CPU time, status, whether the clock caused a fallback, the
    proven gap and whether a MILP finished the plan late."""
    return dict(
        wall=st.wall_time_s, cpu=cpu, status=st.status,
        timed_out=st.timed_out or (st.status == "fallback" and st.solver_s >= limit),
        gap=st.gap, late=bool(st.size.get("late")),
    )  # fmt: skip


def calls(
    name: str, seqs: list[tuple[str, list[TaskGraph]]], limit: float, by_size: bool
) -> Iterator[tuple[str, dict]]:
    """Plan every graph with ``name`` at ``limit``; yield (group, record) per call."""
    for label, graphs in seqs:
        scheduler = make_scheduler(name)
        for g in graphs:
            c0 = time.process_time()
            plan = solve(scheduler, g, time_limit=limit, rng=np.random.default_rng(0))
            st = plan.stats
            yield (label if by_size else ""), record(st, limit, time.process_time() - c0)


def episode_calls(name: str, design: str, limit: float) -> Iterator[tuple[str, dict]]:
    """Play one episode (seed 0) of each of the design's scenarios with ``name`` at ``limit``;
    yield ("", record) per replan. CPU time per call is not measured (nan)."""
    for _label, sc in scenarios_of(design):
        res = run_episode(sc, make_scheduler(name), seed=0, time_limit=limit)
        for st in res.solves:
            yield "", record(st, limit, float("nan"))


def row(design: str, group: str, name: str, limit: float, recs: list[dict], load: str) -> str:
    wall = np.array([r["wall"] for r in recs]) * 1e3
    cpu = np.array([r["cpu"] for r in recs]) * 1e3
    bound = (1.1 * limit + 0.005) * 1e3
    fb = [r for r in recs if r["status"] == "fallback"]
    gaps = np.array([r["gap"] for r in recs if np.isfinite(r["gap"])])
    gap = f"{100 * np.median(gaps):.2f}%" if gaps.size else "-"
    where = f"{design}{' ' + group if group else ''}"
    return (
        f"{where:<16} {name:<13} {limit * 1e3:>8.3g} {len(recs):>5} {pct(wall, 50):>7.1f} "
        f"{pct(wall, 95):>7.1f} {pct(wall, 99):>7.1f} {wall.max():>7.1f} {pct(cpu, 99):>7.1f} "
        f"{bound:>6.1f} {100 * np.mean(wall <= bound):>6.1f}% "
        f"{len(fb):>4}/{sum(r['timed_out'] for r in fb):<4} {sum(r['late'] for r in recs):>4} "
        f"{gap:>7}  {load}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", nargs="+", default=list(DESIGNS), choices=DESIGNS)
    ap.add_argument("--schedulers", default=",".join(available_schedulers()))
    ap.add_argument("--limits", type=float, nargs="+", default=[0.1])
    ap.add_argument("--floor", action="store_true", help="also run at time_limit=1e-6")
    ap.add_argument("--every", type=int, default=10, help="simulated seconds between graphs")
    ap.add_argument("--synthetic-seeds", type=int, default=5)
    ap.add_argument(
        "--episodes",
        action="store_true",
        help="each scheduler plays its own episodes (seed 0) instead of greedy's graphs",
    )
    args = ap.parse_args()
    if args.episodes and "synthetic" in args.designs:
        ap.error("--episodes: the synthetic design has no episodes")
    names = args.schedulers.split(",")
    limits = list(args.limits) + ([1e-6] if args.floor else [])
    print(f"# load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    print(f"{'design':<16} {'scheduler':<13} {'limit ms':>8} {'calls':>5} {'p50 ms':>7} "
          f"{'p95 ms':>7} {'p99 ms':>7} {'max ms':>7} {'cpu p99':>7} {'bound':>6} {'within':>7} "
          f"{'fb/t/o':<9} {'late':>4} {'gap p50':>7}  load")  # fmt: skip
    for design in args.designs:
        seqs = [] if args.episodes else sequences(design, args.every, args.synthetic_seeds)
        for limit in limits:
            for name in names:
                load0 = os.getloadavg()[0]
                groups: dict[str, list[dict]] = collections.defaultdict(list)
                recs = (
                    episode_calls(name, design, limit)
                    if args.episodes
                    else calls(name, seqs, limit, by_size=design == "synthetic")
                )
                for group, rec in recs:
                    groups[group].append(rec)
                load = f"{load0:.1f}-{os.getloadavg()[0]:.1f}"
                for group, recs in groups.items():
                    print(row(design, group, name, limit, recs, load), flush=True)
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
