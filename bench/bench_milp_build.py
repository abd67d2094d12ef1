"""Benchmark building the MILP route model (issue 13's blocker at 50-100 agents).

Builds :func:`solvers.milp_model.build_milp_model` on the graphs of a greedy episode (every
``--every`` simulated seconds) of the manual's scenarios 1-24 (``suite``), of the benchmark's
``scale`` tier (``scale-tier``: scale-01..06, 18-30 agents) and of generated ``scale`` designs
with 10, 50 and 100 agents (as ``bench_time_limits.py``'s ``scale50`` / ``scale100``), and
prints per design the build's median and p95 wall ms over ``--repeat`` rounds, the ms per agent,
the routes and nonzeros, and a digest of every model built (objective, rows, routes): two source
trees that build the same models print the same digest, so an A/B run (``bench/ab.py``) checks
that a speed-up left the models unchanged while it measures it.

Usage::

    python bench/bench_milp_build.py
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

from fcplan import load_scenario
from fcplan.testing import episode_graphs
from solvers.milp_model import build_milp_model

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_time_limits import scale_design  # noqa: E402


def digest(models: list) -> str:
    """A short hash of the models' objective, rows and routes (equal models: equal digests)."""
    h = hashlib.sha256()
    for m in models:
        for a in (m.c, m.b_ub, m.A_ub.data, m.A_ub.indices, m.A_ub.indptr, m.route_tasks):
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:12]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--designs", nargs="+", default=["suite", "scale-tier", "scale10", "scale50", "scale100"]
    )
    ap.add_argument("--every", type=int, default=30, help="simulated seconds between graphs")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"# load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    print(f"{'design':<10} {'graphs':>6} {'build p50 ms':>13} {'p95 ms':>8} {'ms/agent':>9} "
          f"{'routes':>7} {'nonzeros':>9}  digest")  # fmt: skip
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
        for r in range(args.repeat):
            models = []
            for i, g in enumerate(graphs):
                t0 = time.perf_counter()
                models.append(build_milp_model(g))
                times[r, i] = time.perf_counter() - t0
        per_graph = times.min(axis=0) * 1e3  # each graph's best round: the least disturbed
        agents = np.array([g.n_agents for g in graphs])
        routes = int(np.median([m.n_routes for m in models]))
        nnz = int(np.median([m.A_ub.nnz for m in models]))
        print(
            f"{design:<10} {len(graphs):>6} {np.median(per_graph):>13.1f} "
            f"{np.percentile(per_graph, 95):>8.1f} {np.median(per_graph / agents):>9.2f} "
            f"{routes:>7} {nnz:>9}  {digest(models)}"
        )
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
