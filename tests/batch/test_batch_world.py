"""Tests of fcplan.batch.world: world ``i`` of a batch is bit for bit a single world reset with the
same seed (fire, sensing, dumps, team, facility counts, trace, metrics), whatever ``B``, whatever
the other worlds do and whenever each world is reset."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.batch import BatchWorld
from fcplan.metrics import compute_all
from fcplan.mission import Mission
from fcplan.scenario import GeneratorConfig, load_scenario
from tests.batch.drive import run_pair
from tests.conftest import scenario_with

SCENARIOS = ["practice", 1, 24, "open_world_example"]


@pytest.mark.parametrize("name", SCENARIOS)
@pytest.mark.parametrize("num", [1, 7])
def test_worlds_equal_single_worlds(name, num):
    """B worlds stepped together under random commands (flights to the fire that arm dumps,
    patrols, calls home) equal B single worlds of the same seeds, tick for tick."""
    sc = load_scenario(name).replace(duration_s=25)
    run_pair(sc, [3 * b + 11 for b in range(num)], sc.n_ticks)


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENARIOS)
def test_64_worlds_whole_episodes(name):
    """64 worlds over whole episodes equal their single worlds."""
    sc = load_scenario(name)
    run_pair(sc, list(range(64)), sc.n_ticks, record_agents=False)


@pytest.mark.parametrize("name", ["practice", 24, "open_world_example"])
def test_resets_at_different_ticks(name):
    """Worlds reset at different ticks (one before another's end, one after its own end, held
    in between) keep equal to single worlds started at those ticks."""
    sc = load_scenario(name).replace(duration_s=12)
    resets = {40: [(1, 901)], 95: [(0, 902), (2, 903)], 150: [(1, 904)]}
    run_pair(sc, [5, 6, 7], 260, resets=resets)


def test_wind_models_and_tick_rates():
    """Both wind models, and 5 and 20 ticks per second (two and one-half fire steps per tick),
    stay bit-identical."""
    for model in ("fresh", "tables"):
        for tps in (5, 20):
            sc = scenario_with(24, **{"fire.wind_model": model, "ticks_per_second": tps})
            sc = sc.replace(duration_s=12)
            run_pair(sc, [1, 2, 3], sc.n_ticks)


def test_large_fires_and_reference_gate():
    """More than 256 fronts in the fresh wind model (C/R picked per world by how many move) and
    the 2020 code's dump gate."""
    cfg = GeneratorConfig(n_regions=(3, 3), fronts=(120, 120), duration_s=15)
    sc = cfg(seed=4).replace(wind_model="fresh")
    assert sum(r.fronts for r in sc.regions) > 256
    run_pair(sc, [8, 9], sc.n_ticks)
    ref = load_scenario(1).replace(duration_s=20, action_gate="reference")
    run_pair(ref, [1, 2, 3], ref.n_ticks)


def test_metrics_equal_the_single_episode():
    """``metrics(b)`` (counts only, no agent rows kept) equals the single world's metrics."""
    sc = load_scenario(1).replace(duration_s=15)
    batch = run_pair(sc, [21, 22], sc.n_ticks, record_agents=False)
    for b, seed in enumerate([21, 22]):
        m = Mission(sc, seed, event_replans=False, belief=False)
        ref = compute_all(_replay(batch, b, m))
        assert {k: v.as_dict() for k, v in batch.metrics(b).items()} == {
            k: v.as_dict() for k, v in ref.items()
        }


def _replay(batch, b, mission):
    from tests.batch.drive import random_commands

    rng = np.random.default_rng([0, b])
    while not mission.world.done:
        mission.world.team.apply(random_commands(rng, batch.scenario, mission.world.team.ids))
        mission.step()
    return mission.world.trace()


def test_held_and_autoreset_worlds():
    """A finished world is held (not stepped) until reset; ``step(autoreset=True)`` resets it
    from its reseed generator, as the motion env's ``reset()`` without a seed does."""
    sc = load_scenario("practice").replace(duration_s=1)
    batch = BatchWorld(sc, 2)
    batch.reset(seeds=[5, 6])
    for _ in range(sc.n_ticks):
        batch.step()
    assert batch.done.all()
    before = batch.fire.x.copy()
    info = batch.step()
    assert not info.ran.any() and np.array_equal(batch.fire.x, before)
    info = batch.step(autoreset=True)
    assert info.reset.all() and (batch.tick == 0).all()
    nxt = [int(np.random.default_rng(s).integers(2**63)) for s in (5, 6)]
    assert batch.seeds == nxt


def test_masked_reset_seeds_follow_gymnasium():
    """``reset(seeds=s, mask=m)`` seeds world ``b`` with ``s + b`` whichever worlds are reset
    (as the vector envs and ``SyncVectorEnv`` do); a list may hold one seed per world or one
    per reset world; the other worlds keep their episodes."""
    sc = load_scenario("practice").replace(duration_s=2)
    batch = BatchWorld(sc, 4)
    batch.reset(seeds=[0, 1, 2, 3])
    batch.step()
    mask = np.array([False, True, False, True])
    batch.reset(seeds=10, mask=mask)
    assert batch.seeds == [0, 11, 2, 13]
    assert batch.tick.tolist() == [1, 0, 1, 0]
    batch.reset(seeds=[20, 21, 22, 23], mask=mask)
    assert batch.seeds == [0, 21, 2, 23]
    batch.reset(seeds=[31, 33], mask=mask)
    assert batch.seeds == [0, 31, 2, 33]


def test_bad_input():
    """A batch needs at least one world and PCG64-seeded streams; it must be reset first."""
    sc = load_scenario("practice")
    with pytest.raises(ValueError, match="num"):
        BatchWorld(sc, 0)
    batch = BatchWorld(sc, 2)
    with pytest.raises(ValueError, match="reset"):
        batch.step()
    with pytest.raises(ValueError, match="seed"):
        batch.reset(seeds=[np.random.default_rng(0), 1])
    with pytest.raises(ValueError, match="2 seeds"):
        batch.reset(seeds=[1, 2, 3])
