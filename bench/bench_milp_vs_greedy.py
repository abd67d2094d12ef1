"""Paired comparison of two schedulers on the manual suite: mean difference, CI and Wilcoxon.

Plays every (scenario, seed) pair with scheduler ``A`` (default ``milp``) and scheduler ``B``
(default ``greedy``) in a process pool, and prints per scenario the mean manual final score of
each, then over all pairs: the means, the mean paired difference ``A - B`` with its 95 %
Student-t interval, the two-sided Wilcoxon signed-rank p-value on the pairs (zero differences
dropped, ``scipy.stats.wilcoxon``), how many pairs ``A`` wins / ties / loses, and the fallbacks
and statuses of each scheduler's replans.

Schedulers are given as specs, ``"milp:horizon_s=60"`` (:func:`fcplan.scheduling.parse_scheduler_spec`).
``--cache FILE`` keeps each episode's result (keyed by spec, scenario and seed) in a JSON file,
so that iterating on ``A`` does not replay ``B``.

Usage::

    python bench/bench_milp_vs_greedy.py --scenarios 1-24 --seeds 0-9 --jobs 2
    python bench/bench_milp_vs_greedy.py --seeds 0-1 --a "milp:slots=3" --cache /tmp/pairs.json
"""

from __future__ import annotations

import argparse
import json
import os
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from scipy import stats

import fcplan
from fcplan.experiments.ranges import parse_range
from fcplan.scheduling import make_scheduler


def _episode(job: tuple[str, int, int]) -> dict:
    spec, scenario, seed = job
    t0 = time.process_time()
    r = fcplan.run_episode(scenario, make_scheduler(spec), seed=seed)
    return {
        "key": f"{spec}|{scenario}|{seed}",
        "final": r.metrics["manual"].final_score,
        "nrr": r.metrics["manual"].negative_reward_ratio,
        "status": dict(Counter(s.status for s in r.solves)),
        "cpu_s": time.process_time() - t0,
    }


def run(specs: list[str], scenarios: list[int], seeds: list[int], jobs: int, cache: Path | None):
    """Every (spec, scenario, seed) episode's summary, from the cache where it is there."""
    done: dict[str, dict] = {}
    if cache is not None and cache.exists():
        done = json.loads(cache.read_text())
    todo = [
        (sp, sc, sd)
        for sp in specs
        for sc in scenarios
        for sd in seeds
        if f"{sp}|{sc}|{sd}" not in done
    ]
    if todo:
        with ProcessPoolExecutor(jobs) as ex:
            for row in ex.map(_episode, todo, chunksize=1):
                done[row["key"]] = row
        if cache is not None:
            cache.write_text(json.dumps(done))
    return done


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a", default="milp", help="scheduler spec A (default milp)")
    ap.add_argument("--b", default="greedy", help="scheduler spec B (default greedy)")
    ap.add_argument("--scenarios", default="1-24")
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--cache", type=Path, default=None)
    ap.add_argument("--per-scenario", action="store_true", help="print the per-scenario table")
    args = ap.parse_args()
    scenarios, seeds = parse_range(args.scenarios), parse_range(args.seeds, names=False)
    t0 = time.perf_counter()
    done = run([args.a, args.b], scenarios, seeds, args.jobs, args.cache)
    wall = time.perf_counter() - t0

    def final(spec, sc, sd):
        return done[f"{spec}|{sc}|{sd}"]["final"]

    a = np.array([[final(args.a, sc, sd) for sd in seeds] for sc in scenarios])
    b = np.array([[final(args.b, sc, sd) for sd in seeds] for sc in scenarios])
    print(f"A = {args.a}, B = {args.b}; scenarios {args.scenarios} x seeds {args.seeds}")
    print(f"({a.size} pairs; {wall:.0f} s wall with {args.jobs} jobs, cache {args.cache})")
    if args.per_scenario:
        print(f"{'scenario':>8} {'A':>8} {'B':>8} {'A-B':>8}")
        for i, sc in enumerate(scenarios):
            print(
                f"{sc:>8} {a[i].mean():>8.1f} {b[i].mean():>8.1f} {a[i].mean() - b[i].mean():>+8.1f}"
            )
    d = (a - b).ravel()
    n = d.size
    half = stats.t.ppf(0.975, n - 1) * d.std(ddof=1) / np.sqrt(n) if n > 1 else float("nan")
    nz = d[d != 0]
    p = float(stats.wilcoxon(nz).pvalue) if nz.size else float("nan")
    print(f"mean final   A {a.mean():.2f}   B {b.mean():.2f}")
    print(
        f"A - B        {d.mean():+.2f}  95% CI [{d.mean() - half:+.2f}, {d.mean() + half:+.2f}]"
        f"  Wilcoxon p {p:.2g}"
    )
    print(f"A wins / ties / losses   {(d > 0).sum()} / {(d == 0).sum()} / {(d < 0).sum()}")
    for spec in (args.a, args.b):
        st: Counter = Counter()
        cpu = 0.0
        for sc in scenarios:
            for sd in seeds:
                row = done[f"{spec}|{sc}|{sd}"]
                st.update(row["status"])
                cpu += row["cpu_s"]
        print(f"{spec}: fallbacks {st['fallback']}  statuses {dict(st)}  cpu {cpu:.0f} s")


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
