"""The fire's statistics at 5, 10, 20 and 40 ticks per second (issue 15).

For each rate the fire alone (scenario #1's region moved to the map centre: 10 fronts, fuel 10,
wind 5 at 45 degrees, 1,200 px; no agents) runs ``--seconds`` simulated seconds on ``--seeds``
seeds, and the script prints the mean over episodes (and its standard error) of:

* ``cells``: burning cells at the end;
* ``drift``: the fronts' mean displacement along the wind (px);
* ``spread``: the standard deviation over fronts of that displacement (px);
* ``step/s``: the mean distance a front moves per simulated second (px).

``--alternatives`` also runs two per-tick rules on a plain re-implementation of the FARSITE step
(exact C/R, no pruning), to show why fcplan fixes the fire's step at 0.1 s instead:

* ``dt``: every tick is one step scaled by ``dt = 10 / r`` (fcplan's rule before issue 15);
* ``sqrt``: the mean step (given the fuel under the front) scaled by ``dt`` and the random part by
  ``sqrt(dt)``, the diffusion scaling that keeps drift velocity and variance per second fixed for
  a front on constant fuel.

``--team`` prints the seconds per leg of a perception agent patrolling a square at 200 px/s
(the team's one rate-dependent effect: an agent snaps onto a goal within one step of it and starts
the next leg on the next tick, so each leg takes ``ceil(leg / step)`` ticks).

Usage::

    python bench/bench_tick_rate.py                      # 30 seeds x 180 s
    python bench/bench_tick_rate.py --alternatives --seeds 12
    python bench/bench_tick_rate.py --team --seeds 0
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from fcplan.farsite import WIND_DIR_SD_RAD, WIND_SPEED_SD, spread_rate_ratio
from fcplan.fire import Fire
from fcplan.scenario import FireRegion, load_scenario
from fcplan.team import Command, Team

W, FRONTS, FUEL, WIND, DIR = 1200, 10, 10.0, 5.0, math.radians(45.0)
AZIMUTH = np.array([math.sin(DIR), math.cos(DIR)])


def statistics(xy_start: np.ndarray, xy_by_second: list[np.ndarray], cells: int) -> list[float]:
    """cells, drift, spread and step per second of one episode."""
    along = (xy_by_second[-1] - xy_start).T @ AZIMUTH
    path = [xy_start, *xy_by_second]
    step = np.mean([np.hypot(*(b - a)).mean() for a, b in zip(path, path[1:], strict=False)])
    return [float(cells), float(along.mean()), float(along.std()), float(step)]


def fcplan_episode(tps: int, seed: int, seconds: int) -> list[float]:
    region = FireRegion((W / 2, W / 2), FRONTS, delay_s=0, fuel=FUEL, wind_speed=5, wind_dir_deg=45)
    fire = Fire([region], W, tps, np.random.default_rng(seed))
    start, by_second = fire._xy.copy(), []
    for _ in range(seconds):
        for _ in range(tps):
            fire.step()
        by_second.append(fire._xy.copy())
    return statistics(start, by_second, fire.n_burning)


def _mean_ratio() -> float:
    """E[C/R] for U ~ N(WIND, 2) (Gauss-Hermite quadrature)."""
    x, w = np.polynomial.hermite_e.hermegauss(80)
    return float((spread_rate_ratio(WIND + WIND_SPEED_SD * x) * w).sum() / w.sum())


def alternative_episode(rule: str, tps: int, seed: int, seconds: int) -> list[float]:
    """One episode of the plain FARSITE step scaled per tick by ``rule`` ("dt" or "sqrt")."""
    rng = np.random.default_rng(seed)
    xy = rng.integers(W // 2 - 50, W // 2 + 50, size=(FRONTS, 2)).T.astype(np.float64)
    terrain = rng.random((W + 1, W + 1), dtype=np.float32)
    burning = np.zeros((W, W), dtype=bool)
    dt = 10.0 / tps
    mean_dir = _mean_ratio() * math.exp(-(WIND_DIR_SD_RAD**2) / 2) * AZIMUTH[:, None]
    alive = np.ones(FRONTS, dtype=bool)
    start, by_second = xy.copy(), []
    for _ in range(seconds):
        for _ in range(tps):
            z = rng.standard_normal((2, FRONTS))
            u, theta = z[0] * WIND_SPEED_SD + WIND, z[1] * WIND_DIR_SD_RAD + DIR
            r = FUEL * terrain[np.rint(xy[0]).astype(int), np.rint(xy[1]).astype(int)]
            step = r * spread_rate_ratio(u) * np.stack([np.sin(theta), np.cos(theta)])
            if rule == "dt":
                move = dt * step
            else:
                mean = r * mean_dir
                move = dt * mean + math.sqrt(dt) * (step - mean)
            xy = np.where(alive, xy + move, xy)
            alive &= ((xy >= 0) & (xy < W)).all(axis=0)
            cells = xy[:, alive].astype(int)
            burning[cells[0], cells[1]] = True
        by_second.append(xy.copy())
    return statistics(start, by_second, int(burning.sum()))


def table(title: str, run, seeds: int, seconds: int) -> None:
    print(f"\n{title}")
    print(f"{'Hz':>3} {'cells':>13} {'drift':>11} {'spread':>11} {'step/s':>11}    s")
    for tps in (5, 10, 20, 40):
        t0 = time.perf_counter()
        r = np.array([run(tps, seed, seconds) for seed in range(seeds)])
        m, se = r.mean(axis=0), r.std(axis=0, ddof=1) / math.sqrt(seeds)
        cols = " ".join(
            f"{a:{w}.1f} {b:{4}.1f}" for a, b, w in zip(m, se, (8, 6, 6, 6), strict=True)
        )
        print(f"{tps:3d} {cols}  {time.perf_counter() - t0:4.0f}")


def leg_seconds(tps: int, leg: float, legs: int = 16) -> float:
    """Seconds per leg of P1 patrolling a square of side ``leg`` px from one of its corners."""
    team = Team(load_scenario(1).replace(ticks_per_second=tps))
    p, (x, y) = team.index("P1"), (300.0, 400.0)
    team.pos[p] = (x, y)
    square = ((x + leg, y), (x + leg, y + leg), (x, y + leg), (x, y))
    team.apply({"P1": Command(route=square, patrol=True)})
    ticks = arrivals = 0
    while arrivals < legs:
        ticks += 1
        arrivals += p in team.move().tolist()
    return ticks / tps / legs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--seconds", type=int, default=180)
    ap.add_argument("--alternatives", action="store_true")
    ap.add_argument("--team", action="store_true")
    args = ap.parse_args()
    if args.team:
        print("seconds per leg, patrol at 200 px/s (ideal: leg / 200)")
        for leg in (37.0, 100.0, 150.0):
            row = "  ".join(f"{tps} Hz {leg_seconds(tps, leg):.3f}" for tps in (5, 10, 20, 40))
            print(f"leg {leg:5.0f} px (ideal {leg / 200:.3f}):  {row}")
    if args.seeds <= 0:
        return
    print(f"{args.seeds} seeds x {args.seconds} s; mean and standard error over episodes")
    table("fcplan (a fire step every 0.1 s)", fcplan_episode, args.seeds, args.seconds)
    if args.alternatives:
        for rule in ("dt", "sqrt"):
            table(
                f"per-tick rule {rule!r}",
                lambda tps, seed, s, rule=rule: alternative_episode(rule, tps, seed, s),
                args.seeds,
                args.seconds,
            )


if __name__ == "__main__":
    main()
