"""Do comparison results depend on --jobs? The same compare run with jobs=1 and jobs=2, in the
default deterministic mode and in the wall-time mode (issue 17).

For each scheduler and mode it prints the episodes compared, how many manual final scores differ
between the serial and the parallel run, and the largest difference. Schedulers whose factory
takes ``deterministic`` run in that mode by default; the others (greedy, idle, random never read
the clock) are run as they are. Run it on a busy machine: that is when wall-clock limits bind.

Usage::

    PYTHONPATH=$PWD nice python bench/bench_determinism.py [--schedulers greedy,routing,milp]
"""

from __future__ import annotations

import argparse

from fcplan.experiments import compare
from fcplan.scenario import load_scenario


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--schedulers", default="greedy,routing,milp,idle,random")
    ap.add_argument("--scenarios", default="1,12,24")
    ap.add_argument("--seeds", default="0,1")
    ap.add_argument("--duration", type=float, default=60.0)
    args = ap.parse_args()
    scen = [load_scenario(s).replace(duration_s=args.duration) for s in args.scenarios.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    names = args.schedulers.split(",")
    print(f"{'scheduler':<10} {'mode':<5} {'episodes':>8} {'differ':>7} {'max |diff|':>10}")
    for deterministic in (True, False):
        runs = [
            compare(scen, names, seeds, jobs=jobs, deterministic=deterministic) for jobs in (1, 2)
        ]
        for name in names:
            a, b = ([e for e in r.episodes if e["scheduler"] == name] for r in runs)
            diffs = [
                abs(x["manual.final_score"] - y["manual.final_score"])
                for x, y in zip(a, b, strict=True)
            ]
            mode = {True: "det", False: "wall"}[bool(a[0]["deterministic"])]
            n = sum(d > 0 for d in diffs)
            print(f"{name:<10} {mode:<5} {len(diffs):>8} {n:>7} {max(diffs):>10.2f}")


if __name__ == "__main__":
    main()
