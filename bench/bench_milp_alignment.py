"""How far greedy's plans are from the MILP's optimum on the MILP's own objective, per suite.

Takes the task graphs of a greedy episode (seed 0, every ``--ticks``) of each scenario, plans
each graph with a fresh ``milp`` in its deterministic mode (no warm start) and with ``greedy``,
and scores both plans on the route model's objective
(:func:`solvers.milp_model.decode.plan_objective`). It prints, per suite, the median and 10th
percentile of ``greedy / milp`` over the graphs where the MILP's objective is positive, and how
many of greedy's plans lie in the model's feasible set (a plan may break rules only the model
imposes, such as one watcher per connected fire; its ratio is then indicative).

Read with the episode scores: where greedy's plans are far below the optimum on this objective
and greedy still scores higher in episodes (``fcplan compare``), the objective ranks plans
differently from the episode's score.

Usage::

    python bench/bench_milp_alignment.py --suites manual v2-hard
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from fcplan import make_scheduler
from fcplan.testing import episode_graphs
from solvers.milp_model.decode import plan_objective

SUITES = {
    "manual": [str(i) for i in range(1, 25)],
    "v2-hard": [f"fcplan-bench-v2/hard-{i:02d}" for i in range(1, 13)],
    "v1-hard": [f"fcplan-bench-v1/hard-{i:02d}" for i in range(1, 13)],
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--suites", nargs="+", default=["manual", "v2-hard"], choices=list(SUITES))
    ap.add_argument("--ticks", nargs="+", type=int, default=[600, 1500, 2400])
    args = ap.parse_args()
    print(f"# load average at start: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    print(f"{'suite':<8} {'graphs':>6} {'greedy/milp p50':>15} {'p10':>6} {'feasible':>9} {'s':>5}")
    greedy = make_scheduler("greedy")
    for suite in args.suites:
        t0 = time.perf_counter()
        ratios, feasible = [], 0
        for name in SUITES[suite]:
            for g in episode_graphs(name, args.ticks, seed=0):
                best, _ = plan_objective(g, make_scheduler("milp", deterministic=True).plan(g))
                mine, ok = plan_objective(g, greedy.plan(g, rng=np.random.default_rng(0)))
                if best > 0:
                    ratios.append(mine / best)
                    feasible += ok
        r = np.array(ratios)
        print(
            f"{suite:<8} {r.size:>6} {np.median(r):>15.3f} {np.percentile(r, 10):>6.3f} "
            f"{feasible:>4}/{r.size:<4} {time.perf_counter() - t0:>5.0f}"
        )
    print(f"# load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
