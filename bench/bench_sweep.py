"""Sweep throughput: episodes per minute of scenarios 1-24 x greedy x 4 seeds (96 episodes).

Three runs of the same grid, each into a fresh results folder (so nothing is skipped):
serial (``jobs=1``, in this process), the local process pool (``jobs=2``) and ``dask="local"``
(a LocalCluster of 2 single-threaded workers, started inside the timing). Ratios are against
serial, measured in the same run; the metrics of the three runs are checked to be identical.

Usage::

    python bench/bench_sweep.py [--seeds 4] [--scenarios 1-24] [--jobs 2]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from fcplan.experiments import load_results, sweep


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--scenarios", default="1-24")
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    config = {
        "scenarios": [args.scenarios],
        "schedulers": ["greedy"],
        "seeds": list(range(args.seeds)),
    }
    print(f"load average before: {os.getloadavg()}")
    runs = {}
    metrics = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, kwargs in (
            ("serial", {"jobs": 1}),
            (f"pool ({args.jobs} workers)", {"jobs": args.jobs}),
            (f"dask local ({args.jobs} workers)", {"jobs": args.jobs, "dask": "local"}),
        ):
            out = os.path.join(tmp, label.split()[0])
            t0 = time.perf_counter()
            s = sweep(config, out, progress=False, **kwargs)
            dt = time.perf_counter() - t0
            assert s.ran == s.total and s.failed == 0 and not s.lost, s.format()
            runs[label] = (s.ran, dt)
            df = load_results(out).set_index("key").sort_index()
            metrics[label] = df[[c for c in df.columns if c.startswith("manual.")]]
    base = runs["serial"][1]
    print(f"{'backend':<26} {'episodes':>8} {'wall s':>8} {'episodes/min':>13} {'speed-up':>9}")
    for label, (n, dt) in runs.items():
        print(f"{label:<26} {n:>8} {dt:>8.1f} {60 * n / dt:>13.1f} {base / dt:>8.2f}x")
    first = next(iter(metrics.values()))
    same = all(m.equals(first) for m in metrics.values())
    print(f"identical manual metrics across backends: {same}")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
