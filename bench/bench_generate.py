"""Is a hard-preset generated scenario non-trivial? Scores of greedy, idle and random on it.

Draws ``--scenarios`` scenarios from ``GeneratorConfig.hard()`` (seeds 0, 1, ...) and plays each
with every scheduler for ``--seeds`` episode seeds. Prints, per scheduler, the mean manual final
score, overall firefighting score (OFS), facility protection (FPS) and negative reward ratio (NRR)
over the episodes, the spread of the final score and the grades. On the manual's 24 scenarios every
competent scheduler gets "Excellent" with OFS = FPS = 100 % in most of them. A useful tier leaves
room between ``idle``/``random`` and ``greedy``, and below the ceiling.

Usage::

    python bench/bench_generate.py [--scenarios 3] [--seeds 3] [--jobs 1]
                                   [--schedulers greedy,idle,random] [--preset hard]
"""

from __future__ import annotations

import argparse
import statistics
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import fcplan
from fcplan.scenario.generate import GeneratorConfig


def _episode(job: tuple[str, int, str, int]) -> tuple[str, int, dict[str, Any]]:
    preset, scenario_seed, scheduler, seed = job
    scenario = GeneratorConfig.preset(preset)(scenario_seed)
    m = fcplan.run_episode(scenario, scheduler, seed=seed).metrics["manual"]
    return scheduler, scenario_seed, m.as_dict()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="hard")
    ap.add_argument("--scenarios", type=int, default=3)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--schedulers", default="greedy,idle,random")
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args()
    schedulers = args.schedulers.split(",")

    print(f"## Generated '{args.preset}' scenarios")
    for k in range(args.scenarios):
        s = GeneratorConfig.preset(args.preset)(k)
        print(f"{s.summary()}  facilities {len(s.facilities)}")

    jobs = [
        (args.preset, k, name, seed)
        for name in schedulers
        for k in range(args.scenarios)
        for seed in range(args.seeds)
    ]
    with ProcessPoolExecutor(args.jobs) as ex:
        results = list(ex.map(_episode, jobs))

    n = args.scenarios * args.seeds
    print(f"\n## Manual metrics, mean over {args.scenarios} scenarios x {args.seeds} seeds ({n})")
    print(
        f"{'scheduler':<10} {'final':>7} {'sd':>6} {'min':>7} {'max':>7} {'OFS %':>6} "
        f"{'FPS %':>6} {'NRR %':>6}  grades"
    )
    for name in schedulers:
        rows = [m for sched, _, m in results if sched == name]
        final = [m["final_score"] for m in rows]
        grades = Counter(m["grade"] for m in rows)
        print(
            f"{name:<10} {statistics.mean(final):7.1f} {statistics.pstdev(final):6.1f} "
            f"{min(final):7.1f} {max(final):7.1f} "
            f"{statistics.mean(m['overall_firefighting'] for m in rows):6.1f} "
            f"{statistics.mean(m['facility_protection'] for m in rows):6.1f} "
            f"{statistics.mean(m['negative_reward_ratio'] for m in rows):6.1f}  "
            + ", ".join(f"{g} {c}" for g, c in grades.most_common())
        )

    print("\n## Mean final score per generated scenario")
    print(f"{'scenario':<10}" + "".join(f"{name:>9}" for name in schedulers))
    for k in range(args.scenarios):
        means = [
            statistics.mean(m["final_score"] for s, kk, m in results if s == name and kk == k)
            for name in schedulers
        ]
        print(f"{k:<10}" + "".join(f"{v:9.1f}" for v in means))


if __name__ == "__main__":
    main()
