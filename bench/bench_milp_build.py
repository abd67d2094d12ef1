"""Benchmark building the MILP route model (issue 13's blocker at 50-100 agents).

Builds :func:`solvers.milp_model.build_milp_model` on the graphs of a greedy episode (every
``--every`` simulated seconds) of the manual's scenarios 1-24 (``suite``), of the benchmark's
``scale`` tier (``scale-tier``: scale-01..06, 18-30 agents) and of generated ``scale`` designs
with 10, 50 and 100 agents (as ``bench_time_limits.py``'s ``scale50`` / ``scale100``), and
prints per design the build's median and p95 wall ms over ``--repeat`` rounds, the ms per agent,
the routes and nonzeros, and a digest of every model built (objective, rows, routes): two source
trees that build the same models print the same digest, so an A/B run (``bench/ab.py``) checks
that a speed-up left the models unchanged while it measures it.

``--per-agent`` also times the readable build, one agent at a time (``batched=False``), on
the same graphs interleaved with the default build (across agents,
:mod:`solvers.milp_model.batch`), and prints its figures, the ratio of the medians and whether
the two builds' digests are equal.

``--given-greedy`` builds each model from greedy's route of each agent (one column per agent)
instead of enumerating routes: the per-agent cost that remains when nothing is enumerated.
``--set KEY=VALUE`` builds with other model settings (:class:`solvers.milp_model.MilpParams`
fields, e.g. ``search_candidates=5`` or ``max_scored_ends=64``), and ``--solve`` also times CP-SAT on each model
in the scheduler's deterministic mode (5 deterministic seconds, one worker): what smaller
candidate sets buy at the scale tier.

Usage::

    python bench/bench_milp_build.py
    python bench/bench_milp_build.py --designs scale-tier --solve --set search_candidates=5
    python bench/bench_milp_build.py --designs scale-tier scale50 scale100 --per-agent
    git worktree add ../fcplan-old HEAD~1
    python bench/ab.py ../fcplan-old . bench/bench_milp_build.py --rounds 5
"""

from __future__ import annotations

import argparse
import hashlib
import os
import sys
import time

import numpy as np

from fcplan import load_scenario, make_scheduler
from fcplan.testing import episode_graphs
from solvers.milp import solve_cpsat
from solvers.milp_model import MilpParams, build_milp_model

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_time_limits import scale_design  # noqa: E402


def digest(models: list) -> str:
    """A short hash of the models' objective, rows and routes (equal models: equal digests)."""
    h = hashlib.sha256()
    for m in models:
        for a in (m.c, m.b_ub, m.A_ub.data, m.A_ub.indices, m.A_ub.indptr, m.route_tasks):
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:12]


def greedy_routes(graph) -> dict[int, list[list[int]]]:
    """Greedy's plan of ``graph`` as one given route (task rows) per agent: the least a build
    that keeps each agent's current route as a column must value."""
    plan = make_scheduler("greedy").plan(graph, rng=np.random.default_rng(0))
    row = {tid: k for k, tid in enumerate(graph.task_ids)}
    return {
        a: [[row[t] for t in plan.routes.get(agent, ()) if t in row]]
        for a, agent in enumerate(graph.agent_ids)
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--designs", nargs="+", default=["suite", "scale-tier", "scale10", "scale50", "scale100"]
    )
    ap.add_argument("--every", type=int, default=30, help="simulated seconds between graphs")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE",
                    help="model settings (MilpParams fields)")  # fmt: skip
    ap.add_argument("--solve", action="store_true", help="also time CP-SAT on every model")
    ap.add_argument("--given-greedy", action="store_true",
                    help="build from greedy's route of each agent instead of enumerating")  # fmt: skip
    ap.add_argument("--per-agent", action="store_true",
                    help="also time the per-agent build, interleaved, and print the ratio")  # fmt: skip
    args = ap.parse_args()
    changes = {k: float(v) if "." in v else int(v) for k, v in (a.split("=", 1) for a in args.set)}
    params = MilpParams(**changes)  # type: ignore[arg-type]
    print(f"# load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    given = " (greedy's routes given)" if args.given_greedy else ""
    print(f"# settings: {' '.join(args.set) or 'defaults'}{given}")
    print(f"{'design':<10} {'graphs':>6} {'build p50 ms':>13} {'p95 ms':>8} {'ms/agent':>9} "
          f"{'routes':>7} {'nonzeros':>9}  digest"
          + (f"  {'solve p50 ms':>12} {'p95 ms':>8} {'optimal':>7}" if args.solve else ""))  # fmt: skip
    for design in args.designs:
        if design == "suite":
            scenarios = [load_scenario(i) for i in range(1, 25)]
        elif design == "scale-tier":  # fcplan-bench-v1's scale-01..scale-06 (18-30 agents)
            scenarios = [load_scenario(f"scale-{i:02d}") for i in range(1, 7)]
        else:
            scenarios = [scale_design(int(design.removeprefix("scale")), 0)]
        graphs = [
            g
            for sc in scenarios
            for g in episode_graphs(sc, range(0, sc.n_ticks, args.every * sc.ticks_per_second))
        ]
        times = np.zeros((args.repeat, len(graphs)))
        base = np.zeros((args.repeat, len(graphs)))
        for r in range(args.repeat):
            models, base_models = [], []
            for i, g in enumerate(graphs):
                given = greedy_routes(g) if args.given_greedy else None
                t0 = time.perf_counter()
                models.append(build_milp_model(g, params, routes=given))
                times[r, i] = time.perf_counter() - t0
                if args.per_agent:  # the readable build on the same graph, right after
                    t0 = time.perf_counter()
                    base_models.append(build_milp_model(g, params, routes=given, batched=False))
                    base[r, i] = time.perf_counter() - t0
        per_graph = times.min(axis=0) * 1e3  # each graph's best round: the least disturbed
        agents = np.array([g.n_agents for g in graphs])
        routes = int(np.median([m.n_routes for m in models]))
        nnz = int(np.median([m.A_ub.nnz for m in models]))
        solve = ""
        if args.solve:
            ms, optimal = [], 0
            for m in models:
                t0 = time.perf_counter()
                _, stats = solve_cpsat(m)
                ms.append((time.perf_counter() - t0) * 1e3)
                optimal += stats.status == "optimal"
            solve = (
                f"  {np.median(ms):>12.1f} {np.percentile(ms, 95):>8.1f} {optimal:>3}/{len(ms):<3}"
            )
        print(
            f"{design:<10} {len(graphs):>6} {np.median(per_graph):>13.1f} "
            f"{np.percentile(per_graph, 95):>8.1f} {np.median(per_graph / agents):>9.2f} "
            f"{routes:>7} {nnz:>9}  {digest(models)}{solve}"
        )
        if args.per_agent:
            b = base.min(axis=0) * 1e3
            same = "equal" if digest(base_models) == digest(models) else "DIFFERENT"
            print(
                f"{'  per-agent':<10} {len(graphs):>6} {np.median(b):>13.1f} "
                f"{np.percentile(b, 95):>8.1f} {np.median(b / agents):>9.2f} "
                f"{'':>7} {'':>9}  {digest(base_models)}  models {same}; per-agent / across "
                f"agents: p50 {np.median(b) / np.median(per_graph):.2f}x, per graph median "
                f"{np.median(b / per_graph):.2f}x"
            )
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
