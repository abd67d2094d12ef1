"""Measure whether a candidate benchmark tier separates the schedulers (issue 12).

A tier is a list of generated scenarios (a :mod:`fcplan.scenario.generate` preset and its seeds).
This script plays every (scenario, scheduler, episode seed), then prints, per scheduler, the mean
and 95 % interval of the headline metric (the manual's final score) and of the outcome metrics,
how many scenarios the scheduler cleared with OFS = 100 % on every seed, and every pair of
schedulers compared on the same (scenario, seed) pairs: mean difference, paired interval,
Wilcoxon p-value and Holm-adjusted p-value (:func:`fcplan.experiments.stats.paired_comparisons`).
A tier is worth keeping when the non-baseline schedulers are not all within each other's
intervals and no scheduler clears every scenario.

Usage::

    python bench/design_suite.py --preset hard --scenarios 0-11 --seeds 0-9 \\
        --schedulers greedy,routing,milp,cbba,oracle --jobs 2
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from fcplan.experiments.ranges import parse_range
from fcplan.experiments.stats import mean_ci, paired_comparisons
from fcplan.scenario import GeneratorConfig


def play(job: tuple[str, int, str, int]) -> dict[str, Any]:
    """One episode of generated scenario (preset, scenario seed) with a scheduler and seed."""
    from fcplan import run_episode

    preset, sc_seed, scheduler, seed = job
    scenario = GeneratorConfig.preset(preset)(sc_seed)
    r = run_episode(scenario, scheduler, seed=seed)
    m = r.metrics["manual"]
    return dict(
        scenario=sc_seed,
        scheduler=scheduler,
        seed=seed,
        final=m.final_score,
        ofs=m.overall_firefighting,
        fallbacks=r.fallbacks,
        **r.outcomes.as_dict(),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="hard")
    ap.add_argument("--scenarios", default="0-11", help="generator seeds of the tier's scenarios")
    ap.add_argument("--seeds", default="0-4", help="episode seeds")
    ap.add_argument("--schedulers", default="greedy,milp,cbba,oracle")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    scenarios, seeds = parse_range(args.scenarios), parse_range(args.seeds)
    names = args.schedulers.split(",")
    jobs = [(args.preset, c, s, e) for c in scenarios for s in names for e in seeds]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.jobs) as pool:
        rows = list(pool.map(play, jobs, chunksize=1))
    wall = time.perf_counter() - t0
    print(
        f"# tier {args.preset} scenarios {args.scenarios} seeds {args.seeds}: {len(rows)} "
        f"episodes in {wall:.0f} s ({args.jobs} workers)"
    )
    by = {n: [r for r in rows if r["scheduler"] == n] for n in names}
    print(
        f"{'scheduler':<10} {'final':>16} {'contain s':>14} {'burned':>14} {'OFS100':>7} {'fb':>5}"
    )
    for n in names:
        rs = by[n]
        cleared = sum(all(r["ofs"] >= 100.0 for r in rs if r["scenario"] == c) for c in scenarios)
        print(
            f"{n:<10} {mean_ci([r['final'] for r in rs]).format(1):>16} "
            f"{mean_ci([r['time_to_containment_s'] for r in rs]).format(1):>14} "
            f"{mean_ci([r['burned_area_cells'] for r in rs]).format(0):>14} "
            f"{cleared:>3}/{len(scenarios):<3} {sum(r['fallbacks'] for r in rs):>5}"
        )
    key = {n: {(r["scenario"], r["seed"]): r["final"] for r in by[n]} for n in names}
    pairs = sorted(key[names[0]])
    scores = {n: np.array([key[n][p] for p in pairs]) for n in names}
    print(f"\npaired differences of the final score over {len(pairs)} (scenario, seed) pairs")
    print(f"{'a - b':<20} {'mean ± 95% CI':>16} {'p':>9} {'p Holm':>9} {'d_z':>6}")
    for c in paired_comparisons(scores):
        print(
            f"{c.a + ' - ' + c.b:<20} {c.diff.format(1):>16} {c.p:>9.2g} {c.p_holm:>9.2g} "
            f"{c.effect:>6.2f}"
        )


if __name__ == "__main__":
    main()
