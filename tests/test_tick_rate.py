"""The physics per simulated second does not depend on ``ticks_per_second`` (issue 15).

Fire: the statistics of the fire alone (burning cells, drift along the wind, spread of the fronts
along the wind, distance a front moves per second) at 5, 20 and 40 Hz are compared with 10 Hz on
*different* seeds per rate, so the comparison is statistical: for each statistic the episode means
of two rates may differ by at most ``K`` standard errors of the difference,
``K * sqrt(se_a^2 + se_b^2)`` with ``se = sd / sqrt(seeds)``. ``K = 4``: under the hypothesis of
equal means a difference beyond 4 standard errors has probability 6e-5 per comparison (1e-3 for
the 12 comparisons of a test), while the fire before issue 15 differed by 6 standard errors or more
between 10 and 40 Hz in cells and drift. Seeds are fixed, so each test is deterministic. The quick
test (10 seeds x 60 s) runs in the default suite; the full one (30 seeds x 180 s) is marked slow.
Beyond statistics, the fire at any rate is bit for bit the 10 Hz fire at the ticks' times
(tests/test_fire.py), which is checked here through the World too.

Team: distance flown, battery drain (flying and hovering), climb, dumps and the probability to
sense a cell in view, per simulated second, at 5, 10, 20 and 40 Hz.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fcplan.fire import Fire
from fcplan.scenario import FireRegion
from fcplan.team import Command, Team, per_tick_probability
from fcplan.world import World
from tests.conftest import scenario_with

RATES = (5, 10, 20, 40)
K = 4.0  # standard errors of the difference allowed between two rates' means (module docstring)
STATS = ("cells", "drift", "spread", "step_per_s")


def fire_statistics(tps: int, seed: int, seconds: int) -> dict[str, float]:
    """One episode of the fire alone (scenario #1's region at the map centre) at ``tps``:
    burning cells, mean and standard deviation over fronts of the displacement along the wind
    (px), and the mean distance a front moves per simulated second (px)."""
    region = FireRegion((600, 600), fronts=10, delay_s=0, fuel=10, wind_speed=5, wind_dir_deg=45)
    fire = Fire([region], 1200, tps, np.random.default_rng(seed))
    start = fire._xy.copy()
    prev, moved = start.copy(), 0.0
    for _ in range(seconds):
        for _ in range(tps):
            fire.step()
        moved += float(np.hypot(*(fire._xy - prev)).mean())
        prev = fire._xy.copy()
    along = (fire._xy - start).T @ np.array([math.sin(math.pi / 4), math.cos(math.pi / 4)])
    return {
        "cells": float(fire.n_burning),
        "drift": float(along.mean()),
        "spread": float(along.std()),
        "step_per_s": moved / seconds,
    }


def compare_rates(seeds: int, seconds: int) -> None:
    """Assert every statistic's mean at 5, 20 and 40 Hz is within K standard errors of 10 Hz."""
    runs = {
        tps: [fire_statistics(tps, 1000 * tps + i, seconds) for i in range(seeds)] for tps in RATES
    }
    summary = {}
    for tps, episodes in runs.items():
        for name in STATS:
            v = np.array([e[name] for e in episodes])
            summary[tps, name] = (v.mean(), v.std(ddof=1) / math.sqrt(seeds))
    for tps in (5, 20, 40):
        for name in STATS:
            (m, se), (m10, se10) = summary[tps, name], summary[10, name]
            assert abs(m - m10) <= K * math.hypot(se, se10), (tps, name, m, m10, se, se10)


def test_fire_statistics_agree_across_tick_rates_quick():
    """Burning cells, drift and spread along the wind and distance per second after 60 s: the
    means over 10 seeds at 5, 20 and 40 Hz are within 4 standard errors of 10 Hz."""
    compare_rates(seeds=10, seconds=60)


@pytest.mark.slow
def test_fire_statistics_agree_across_tick_rates():
    """The same after 180 s over 30 seeds per rate (the issue's setting)."""
    compare_rates(seeds=30, seconds=180)


@pytest.mark.parametrize("tps", [5, 20, 40])
def test_world_fire_is_the_10hz_fire_at_the_same_times(tps):
    """With an idle team (nothing pruned) the world's fire after s simulated seconds is, bit for
    bit, the 10 Hz world's fire after s seconds, for the same seed."""
    worlds = {r: World().reset(scenario_with(12, ticks_per_second=r), seed=3) for r in (10, tps)}
    for _ in range(65):  # past region 2's 60 s delay
        for r, world in worlds.items():
            for _ in range(r):
                world.step()
        a, b = worlds[10].fire, worlds[tps].fire
        assert a.n_steps == b.n_steps
        np.testing.assert_array_equal(a._xy, b._xy)
        np.testing.assert_array_equal(a.state, b.state)


@pytest.mark.parametrize("tps", RATES)
def test_distance_battery_and_climb_per_second_do_not_depend_on_rate(tps):
    """Flying for 2 s covers 400 px and drains 40 battery units, hovering for 2 s drains 1 unit,
    and a perception agent climbs 50 m per second, at any tick rate."""
    team = Team(scenario_with(1, ticks_per_second=tps))
    p, a = team.index("P1"), team.index("A1")
    start = team.pos.copy()
    team.apply({"P1": Command(route=((1000.0, 420.0),), altitude=100.0), "A1": Command(route=())})
    team.pos[a] = (300.0, 300.0)  # hovering away from home (ACTIVE, no goal)
    team.mode[a] = 1
    for _ in range(2 * tps):
        team.move()
    assert team.pos[p, 0] - start[p, 0] == pytest.approx(400.0)
    assert team.distance[p] == pytest.approx(400.0)
    assert team.battery_capacity[p] - team.battery[p] == pytest.approx(40.0)
    assert team.battery_capacity[a] - team.battery[a] == pytest.approx(1.0)
    assert team.z[p] == 100.0 and team.z_start[p] == 20.0
    team = Team(scenario_with(1, ticks_per_second=tps))
    team.apply({"P1": Command(altitude=100.0)})
    for _ in range(tps):
        team.move()
    assert team.z[team.index("P1")] == pytest.approx(70.0)


@pytest.mark.parametrize("tps", RATES)
def test_dumps_and_pruning_per_second_do_not_depend_on_rate(tps):
    """An action agent patrolling two burning spots 200 px apart (1 s per leg at 200 px/s)
    arrives, dumps and prunes at the same simulated times at any rate: one dump per arrival."""
    scenario = scenario_with(1, ticks_per_second=tps, **{"fire.action_gate": "reference"})
    world = World().reset(scenario, seed=5)
    spots = ((700.0, 800.0), (900.0, 800.0))
    for x, y in spots:
        xs, ys = np.meshgrid(np.arange(x - 20, x + 20), np.arange(y - 10, y + 10), indexing="ij")
        world.ignite(np.stack([xs.ravel(), ys.ravel()], axis=1))
    world.team.pos[world.team.index("A1")] = spots[1]
    world.step({"A1": Command(route=spots, patrol=True)})
    dump_times = []
    for _ in range(6 * tps):
        info = world.step()
        if info.dumped:
            dump_times.append(round(info.time_s, 9))
    assert dump_times == [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]


@pytest.mark.parametrize("tps", RATES)
def test_sensing_probability_per_second_does_not_depend_on_rate(tps):
    """The per-tick sensing probability at r Hz gives, over one simulated second in view, the
    probability of ten 10 Hz ticks: 1 - (1 - p_tick)^r = 1 - (1 - c)^10, for every altitude."""
    team = Team(scenario_with(1, ticks_per_second=tps))
    for z in (20.0, 55.0, 100.0):
        team.z[:] = z
        c, p = team.sensing_confidence(), team.sensing_probability()
        np.testing.assert_allclose(1 - (1 - p) ** tps, 1 - (1 - c) ** 10, rtol=1e-12)
        assert np.all((p >= 0) & (p <= 1))
    if tps == 10:
        assert per_tick_probability(c, 10) is c  # 10 Hz: the manual's confidence itself


@pytest.mark.parametrize("tps", [5, 10, 20, 40])
def test_world_senses_the_same_share_of_cells_per_second_at_any_rate(tps):
    """A perception agent hovering at its highest altitude (c = 0.4) over 2,400 burning cells has
    sensed 1 - 0.6^2 = 64 % of them after 0.2 s at any rate (within 4 percentage points)."""
    world = World().reset(scenario_with(1, ticks_per_second=tps), seed=6)
    xs, ys = np.meshgrid(np.arange(770, 830), np.arange(780, 820), indexing="ij")
    cells = np.stack([xs.ravel(), ys.ravel()], axis=1)
    world.ignite(cells)
    team, p = world.team, world.team.index("P1")
    team.pos[p] = (800.0, 800.0)
    team.z[p] = team.z_target[p] = 100.0
    for _ in range(tps // 5):
        world.step()
    share = world.sensed[cells[:, 0], cells[:, 1]].mean()
    assert abs(share - (1 - 0.6**2)) < 0.04, share
