"""Benchmark the simulator core: fire model per tick, whole world with greedy, fire scaling.

Prints median microseconds per tick:

* fire alone on the shipped scenarios (practice, #1, #12, #24), 1,800 ticks each;
* the whole episode (world + belief + task graph + greedy replans + metrics) on the same
  scenarios, with the episode wall time;
* fire scaling with 10, 30, 100, 1,000 and 10,000 fronts on 1,200 px and 5,000 px maps, against a
  baseline measured in the same run: the same FARSITE rules written as a plain Python loop over
  fronts (the way the 2020 reference structures its loop, without its history-intensity cost);
* the per-tick path the environments need (issue 4): ``World.step`` + ``Belief.update`` in us per
  tick with an idle team and with the team following greedy plans (replanned every second; the
  scheduler's time is excluded), and a task graph build (one per-episode
  :class:`fcplan.taskgraph.TaskGraphBuilder`) in us per replan, on #1 and #24.

Old against new: run this script on two source trees, interleaved, with ``bench/ab.py``, e.g.
``python bench/ab.py ../fcplan-old . bench/bench_core.py --quick --rounds 5``.

Usage::

    python bench/bench_core.py            # full run (about a minute)
    python bench/bench_core.py --quick    # fewer ticks and repeats
    python bench/bench_core.py --only-tick   # only the per-tick path
"""

from __future__ import annotations

import argparse
import math
import platform
import statistics
import time

import numpy as np

import fcplan
from fcplan.fire import Fire, spread_rate_ratio
from fcplan.scenario import FireRegion


def median_us(fn, n: int) -> float:
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts) * 1e6


def fire_for(scenario, seed: int = 0) -> Fire:
    return Fire(
        scenario.regions,
        scenario.world_size,
        scenario.ticks_per_second,
        np.random.default_rng(seed),
    )


def bench_scenarios(names, ticks: int, repeats: int) -> None:
    print("## Fire model alone (median us per tick over the episode)")
    print(f"{'scenario':<10} {'fronts':>6} {'us/tick':>9} {'burning cells at end':>21}")
    for name in names:
        sc = fcplan.load_scenario(name)
        fire = fire_for(sc)
        us = median_us(fire.step, ticks)
        print(f"{sc.name:<10} {fire.n_fronts:>6} {us:>9.1f} {fire.n_burning:>21}")
    print()
    print("## Whole episode with greedy (world + belief + task graph + replans + metrics)")
    print(
        f"{'scenario':<10} {'episode s':>9} {'us/tick':>9} {'replans':>8} {'solve p50 ms':>13}"
        f" {'final (manual)':>15}"
    )
    for name in names:
        walls = []
        for _ in range(repeats):
            res = fcplan.run_episode(name, "greedy", seed=0)
            walls.append(res.wall_time_s)
        wall = statistics.median(walls)
        print(
            f"{res.scenario:<10} {wall:>9.3f} {wall / res.ticks * 1e6:>9.1f} "
            f"{len(res.solves):>8} {np.median(res.solve_times_s) * 1e3:>13.2f} "
            f"{res.metrics['manual'].final_score:>15.1f}"
        )
    print()


class NaiveFire:
    """The same FARSITE rules as fcplan.fire, one front at a time in Python (baseline only)."""

    def __init__(self, fire: Fire) -> None:
        self.w = fire.world_size
        self.x = fire.x.tolist()
        self.y = fire.y.tolist()
        self.fuel = fire._fuel.tolist()
        self.wind = fire._wind.tolist()
        self.theta = fire._theta.tolist()
        self.terrain = fire.terrain
        self.burning: set[int] = set()
        self.rng = np.random.default_rng(0)

    def step(self) -> None:
        w = self.w
        for i in range(len(self.x)):
            x, y = self.x[i], self.y[i]
            if not (0 <= x < w and 0 <= y < w):
                continue
            u = self.wind[i] + 2.0 * self.rng.standard_normal()
            th = self.theta[i] + 2.0 * self.rng.standard_normal()
            r = self.fuel[i] * float(self.terrain[round(x), round(y)])
            c = max(r, 1e-15) * float(spread_rate_ratio(u))
            x, y = x + c * math.sin(th), y + c * math.cos(th)
            self.x[i], self.y[i] = x, y
            if 0 <= x < w and 0 <= y < w:
                self.burning.add(int(x) * w + int(y))


def scaling(ticks: int) -> None:
    print("## Fire scaling (median us per tick; ticks 50..50+N, fuel 10, wind 5)")
    print(f"{'map px':>7} {'fronts':>7} {'fcplan us':>10} {'python-loop us':>15} {'speed-up':>9}")
    for w in (1200, 5000):
        for n in (10, 30, 100, 1000, 10_000):
            k = max(1, min(25, n // 10))  # regions
            rng = np.random.default_rng(1)
            centres = rng.uniform(100, w - 100, size=(k, 2))
            regions = [
                FireRegion(
                    center=(float(cx), float(cy)),
                    fronts=n // k,
                    delay_s=0,
                    fuel=10,
                    wind_speed=5,
                    wind_dir_deg=45,
                )
                for cx, cy in centres
            ]
            fire = Fire(regions, w, 10, np.random.default_rng(0))
            for _ in range(50):
                fire.step()
            us = median_us(fire.step, ticks)
            if n <= 1000:
                naive = NaiveFire(fire)
                base = median_us(naive.step, max(5, ticks // 10))
                print(f"{w:>7} {n:>7} {us:>10.1f} {base:>15.1f} {base / us:>8.1f}x")
            else:
                print(f"{w:>7} {n:>7} {us:>10.1f} {'-':>15} {'-':>9}")
    print()


def tick_loop(impl, scenario, greedy: bool, seed: int = 0) -> tuple[float, float]:
    """One episode; return (us per World.step + Belief.update, us per build_task_graph).

    Greedy plans are made every 10 ticks (1 s) from the graph; their solve time is not counted.
    """
    from fcplan.plan import plan_commands
    from fcplan.scheduling import make_scheduler, solve

    world_cls, belief_cls, builder_cls = impl
    world = world_cls().reset(scenario, seed)
    belief = belief_cls(scenario)
    build = builder_cls(scenario).build
    scheduler = make_scheduler("greedy")
    commands = None
    t_step = t_graph = 0.0
    n = graphs = 0
    clock = time.perf_counter
    while not world.done:
        t0 = clock()
        info = world.step(commands)
        belief.update(info)
        t_step += clock() - t0
        commands = None
        n += 1
        if n % 10 == 0:
            t0 = clock()
            graph = build(world.team, belief)
            t_graph += clock() - t0
            graphs += 1
            if greedy:
                plan = solve(scheduler, graph, time_limit=None, rng=world.controller_rng)
                commands = plan_commands(plan, graph)
    return t_step / n * 1e6, t_graph / max(graphs, 1) * 1e6


def bench_tick(repeats: int) -> None:
    """Per-tick path of the environments."""
    import scipy.ndimage  # noqa: F401  (imported lazily on the first fire cluster: not per call)

    from fcplan.belief import Belief
    from fcplan.taskgraph import TaskGraphBuilder
    from fcplan.world import World

    impls = {"current": (World, Belief, TaskGraphBuilder)}
    print("## Per-tick path (issue 4): World.step + Belief.update, build_task_graph")
    print(f"(best of {repeats} episodes of 1,800 ticks, implementations interleaved)")
    head = f"{'scenario':<9} {'team':<7} {'impl':<10} {'us/tick':>8} {'graph us':>9}"
    print(head)
    for name in ("1", "24"):
        sc = fcplan.load_scenario(name)
        for greedy in (False, True):
            runs = {k: [] for k in impls}
            for impl in impls.values():  # warm-up (imports, caches)
                tick_loop(impl, sc.replace(duration_s=5), greedy)
            for _ in range(repeats):
                for key, impl in impls.items():
                    runs[key].append(tick_loop(impl, sc, greedy))
            med = {k: (min(r[0] for r in v), min(r[1] for r in v)) for k, v in runs.items()}
            team = "greedy" if greedy else "idle"
            for key, (us, gus) in med.items():
                print(f"{sc.name:<9} {team:<7} {key:<10} {us:>8.1f} {gus:>9.1f}")
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--only-tick", action="store_true", help="only the per-tick path section")
    args = ap.parse_args()
    ticks = 300 if args.quick else 1800
    print(
        f"fcplan {fcplan.__version__}, numpy {np.__version__}, Python "
        f"{platform.python_version()}, {platform.machine()}\n"
    )
    if not args.only_tick:
        bench_scenarios(["practice", "1", "12", "24"], ticks, 1 if args.quick else 3)
        scaling(100 if args.quick else 300)
    bench_tick(1 if args.quick else 5)


if __name__ == "__main__":
    main()
