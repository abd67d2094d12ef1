"""Paired comparison of schedulers against a baseline on the manual suite: mean difference, CI,
Wilcoxon.

Plays every (scenario, seed) pair with each scheduler ``A`` (default ``milp``; ``--a`` may be
given several times) and the baseline ``B`` (default ``greedy``) in a process pool, and prints,
for each ``A``: the mean manual final score of each, the mean paired difference ``A - B`` with
its 95 % Student-t interval, the two-sided Wilcoxon signed-rank p-value on the pairs (zero
differences dropped, ``scipy.stats.wilcoxon``), how many pairs ``A`` wins / ties / loses, and the
fallbacks, statuses and CPU seconds of each scheduler's episodes; ``--per-scenario`` adds the
table by scenario. The load average is printed at the start and the end (the CPU seconds are
the figure to compare under load).

Schedulers are given as specs, ``"milp:horizon_s=60"`` (:func:`fcplan.scheduling.parse_scheduler_spec`).
``--cache FILE`` keeps each episode's result (keyed by spec, scenario, seed and wind model) in a
JSON file, written as episodes finish, so that iterating on ``A`` does not replay ``B``.
``--wind tables|fresh`` plays every scenario with that wind model instead of its own.

Usage::

    python bench/bench_milp_vs_greedy.py --scenarios 1-24 --seeds 0-9 --jobs 2
    python bench/bench_milp_vs_greedy.py --seeds 10-14 --a milp --a "milp:slots=2" \\
        --cache /tmp/pairs.json --per-scenario
"""

from __future__ import annotations

import argparse
import dataclasses
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


def _key(spec: str, scenario: int | str, seed: int, wind: str | None) -> str:
    return f"{spec}|{scenario}|{seed}" + ("" if wind is None else f"|{wind}")


def _episode(job: tuple[str, int | str, int, str | None]) -> dict:
    spec, scenario, seed, wind = job
    t0 = time.process_time()
    sc = fcplan.load_scenario(scenario)
    if wind is not None:
        sc = dataclasses.replace(sc, wind_model=wind)
    r = fcplan.run_episode(sc, make_scheduler(spec), seed=seed)
    return {
        "key": _key(spec, scenario, seed, wind),
        "final": r.metrics["manual"].final_score,
        "nrr": r.metrics["manual"].negative_reward_ratio,
        "status": dict(Counter(s.status for s in r.solves)),
        "cpu_s": time.process_time() - t0,
    }


def run(
    specs: list[str],
    scenarios: list,
    seeds: list[int],
    jobs: int,
    cache: Path | None,
    wind: str | None = None,
) -> dict[str, dict]:
    """Every (spec, scenario, seed) episode's summary, from the cache where it is there."""
    done: dict[str, dict] = {}
    if cache is not None and cache.exists():
        done = json.loads(cache.read_text())
    todo = [
        (sp, sc, sd, wind)
        for sp in specs
        for sc in scenarios
        for sd in seeds
        if _key(sp, sc, sd, wind) not in done
    ]
    if todo:
        with ProcessPoolExecutor(jobs) as ex:
            for i, row in enumerate(ex.map(_episode, todo, chunksize=1)):
                done[row["key"]] = row
                if cache is not None and (i % 20 == 19 or i == len(todo) - 1):
                    cache.write_text(json.dumps(done))
    return done


def paired_summary(a: np.ndarray, b: np.ndarray) -> dict[str, float]:
    """Mean paired difference ``a - b``, its 95 % t interval, the Wilcoxon p and the counts."""
    d = (a - b).ravel()
    n = d.size
    half = stats.t.ppf(0.975, n - 1) * d.std(ddof=1) / np.sqrt(n) if n > 1 else float("nan")
    nz = d[d != 0]
    p = float(stats.wilcoxon(nz).pvalue) if nz.size else float("nan")
    return {
        "mean": float(d.mean()),
        "lo": float(d.mean() - half),
        "hi": float(d.mean() + half),
        "p": p,
        "wins": int((d > 0).sum()),
        "ties": int((d == 0).sum()),
        "losses": int((d < 0).sum()),
    }


def _report(done: dict, spec: str, base: str, scenarios: list, seeds: list, args) -> None:
    def final(sp: str, sc, sd: int) -> float:
        return done[_key(sp, sc, sd, args.wind)]["final"]

    a = np.array([[final(spec, sc, sd) for sd in seeds] for sc in scenarios])
    b = np.array([[final(base, sc, sd) for sd in seeds] for sc in scenarios])
    print(f"\nA = {spec}, B = {base}; scenarios {args.scenarios} x seeds {args.seeds}")
    if args.per_scenario:
        print(f"{'scenario':>8} {'A':>8} {'B':>8} {'A-B':>8}")
        for i, sc in enumerate(scenarios):
            print(
                f"{sc!s:>8} {a[i].mean():>8.1f} {b[i].mean():>8.1f} {a[i].mean() - b[i].mean():>+8.1f}"
            )
    s = paired_summary(a, b)
    print(f"mean final   A {a.mean():.2f}   B {b.mean():.2f}   ({a.size} pairs)")
    print(
        f"A - B        {s['mean']:+.2f}  95% CI [{s['lo']:+.2f}, {s['hi']:+.2f}]"
        f"  Wilcoxon p {s['p']:.2g}"
    )
    print(f"A wins / ties / losses   {s['wins']} / {s['ties']} / {s['losses']}")
    for sp in (spec, base):
        st: Counter = Counter()
        cpu = 0.0
        for sc in scenarios:
            for sd in seeds:
                row = done[_key(sp, sc, sd, args.wind)]
                st.update(row["status"])
                cpu += row["cpu_s"]
        print(
            f"{sp}: fallbacks {st['fallback']}  statuses {dict(st)}"
            f"  cpu {cpu:.0f} s ({cpu / a.size:.1f} s per episode)"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--a", action="append", help="scheduler spec A (repeatable; default milp)")
    ap.add_argument("--b", default="greedy", help="baseline spec B (default greedy)")
    ap.add_argument("--scenarios", default="1-24")
    ap.add_argument("--seeds", default="0-9")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--cache", type=Path, default=None)
    ap.add_argument("--wind", choices=("tables", "fresh"), default=None)
    ap.add_argument("--per-scenario", action="store_true", help="print the per-scenario table")
    args = ap.parse_args()
    specs = args.a or ["milp"]
    scenarios, seeds = parse_range(args.scenarios), parse_range(args.seeds, names=False)
    print(f"load average at start: {os.getloadavg()[0]:.2f} (cores: {os.cpu_count()})")
    t0 = time.perf_counter()
    done = run([*specs, args.b], scenarios, seeds, args.jobs, args.cache, args.wind)
    wall = time.perf_counter() - t0
    print(f"{wall:.0f} s wall with {args.jobs} jobs; load average at end {os.getloadavg()[0]:.2f}")
    for spec in specs:
        _report(done, spec, args.b, scenarios, seeds, args)


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
