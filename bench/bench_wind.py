"""Between-episode spread of the fire's drift under the two wind models (issue 15).

For each wind model (``fresh``: new draws every step; ``tables``: the original's per-episode
tables, see :mod:`fcplan.fire`) the script runs the fire alone (no agents, no pruning) for
``--seeds`` episodes of ``--steps`` fire steps and prints, over episodes:

* the drift along the wind: per episode, the mean over fronts of the displacement projected on
  the wind azimuth (px); its mean and its between-episode standard deviation (the spread);
* the spread across the wind (same, projected on the perpendicular);
* burning cells at the end;
* the ratio of the spreads (tables / fresh) with a 95 % interval from the F distribution.

The default setting is scenario #1's region (10 fronts, fuel 10, wind 5 at 45 degrees, 1,200 px)
moved to the map centre so that no front leaves the map.

Usage::

    python bench/bench_wind.py                 # 40 seeds x 1,800 steps (about a minute)
    python bench/bench_wind.py --seeds 10 --steps 600
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy import stats

from fcplan.fire import Fire
from fcplan.scenario import FireRegion


def episode(model: str, seed: int, args: argparse.Namespace) -> tuple[float, float, int]:
    """Drift along and across the wind (px, mean over fronts) and burning cells at the end."""
    c = args.world / 2
    region = FireRegion(
        center=(c, c),
        fronts=args.fronts,
        delay_s=0,
        fuel=args.fuel,
        wind_speed=args.wind,
        wind_dir_deg=args.dir,
    )
    fire = Fire([region], args.world, 10, np.random.default_rng(seed), wind_model=model)
    start = fire._xy.copy()
    for _ in range(args.steps):
        fire.step()
    d = (fire._xy - start).mean(axis=1)
    th = math.radians(args.dir)
    along = d[0] * math.sin(th) + d[1] * math.cos(th)
    across = d[0] * math.cos(th) - d[1] * math.sin(th)
    return float(along), float(across), int(fire.n_burning)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=40)
    ap.add_argument("--steps", type=int, default=1800)
    ap.add_argument("--fronts", type=int, default=10)
    ap.add_argument("--fuel", type=float, default=10.0)
    ap.add_argument("--wind", type=float, default=5.0)
    ap.add_argument("--dir", type=float, default=45.0)
    ap.add_argument("--world", type=int, default=1200)
    args = ap.parse_args()
    print(
        f"{args.seeds} seeds x {args.steps} steps, {args.fronts} fronts, fuel {args.fuel:g}, "
        f"wind {args.wind:g} at {args.dir:g} deg, {args.world} px"
    )
    print(f"{'model':7} {'drift':>8} {'+-se':>6} {'spread':>7} {'across':>7} {'cells':>7}  s")
    spread = {}
    for model in ("fresh", "tables"):
        t0 = time.perf_counter()
        # the same seeds for both models: same ignition points and terrain
        r = np.array([episode(model, s, args) for s in range(args.seeds)])
        along, across, cells = r[:, 0], r[:, 1], r[:, 2]
        sd = along.std(ddof=1)
        spread[model] = sd
        print(
            f"{model:7} {along.mean():8.1f} {sd / math.sqrt(len(along)):6.1f} {sd:7.1f} "
            f"{across.std(ddof=1):7.1f} {cells.mean():7.0f}  {time.perf_counter() - t0:.0f}"
        )
    ratio = spread["tables"] / spread["fresh"]
    df = args.seeds - 1
    lo, hi = (math.sqrt(ratio**2 / stats.f.ppf(q, df, df)) for q in (0.975, 0.025))
    print(f"spread ratio tables / fresh: {ratio:.2f} (95 % interval {lo:.2f} .. {hi:.2f})")


if __name__ == "__main__":
    main()
