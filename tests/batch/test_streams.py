"""Tests of fcplan.batch.streams: the terrain read by PCG64 jumps is the terrain the fire draws,
the generator skipped past it is in the state drawing it leaves, and uniforms drawn ahead in
blocks are the values of successive ``random(k)`` calls."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.batch.streams import TerrainJump, UniformBlocks, spawn_streams, world_seeds
from fcplan.fire import Fire
from fcplan.scenario import load_scenario
from tests._fast.bits import bits


@pytest.fixture(scope="module")
def jump():
    return TerrainJump(33)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**63), pre=st.integers(0, 5))
def test_terrain_jump_equals_the_draw(jump, seed, pre):
    """Every cell's value equals ``random((side, side), float32)``, with or without a buffered
    32-bit half before the draw (``pre`` 32-bit draws first), and the generator is left in the
    state the draw leaves (the same next values of every kind)."""
    a, b = np.random.default_rng(seed), np.random.default_rng(seed)
    a.integers(0, 7, size=pre)  # (32-bit draws: an odd count leaves a half buffered)
    b.integers(0, 7, size=pre)
    ref = a.random((33, 33), dtype=np.float32).reshape(-1).astype(np.float64)
    base = jump.skip(b)
    cells = np.arange(33 * 33)
    vals = jump.values(np.repeat(base[None], cells.size, axis=0), cells)
    assert bits(vals) == bits(ref)
    assert _state(a) == _state(b)
    assert bits(a.integers(0, 9, 5)) == bits(b.integers(0, 9, 5))


def _state(g: np.random.Generator) -> dict:
    """The generator's state, without the buffered half when none is buffered (numpy leaves a
    stale value there that no draw reads)."""
    st = dict(g.bit_generator.state)
    if not st["has_uint32"]:
        st["uinteger"] = 0
    return st


def test_terrain_of_a_fire():
    """The values read for a fire's stream are the fire's own terrain (a 1,201-px side)."""
    sc = load_scenario(1)
    fire_rng = spawn_streams(7)[0]
    fire = Fire(sc.regions, sc.world_size, sc.ticks_per_second, spawn_streams(7)[0])
    n = sum(r.fronts for r in sc.regions)
    fire_rng.integers(np.zeros((n, 2), np.int64), np.ones((n, 2), np.int64) * 5, size=(n, 2))
    jump = TerrainJump(sc.world_size + 1)
    base = jump.skip(fire_rng)
    cells = np.random.default_rng(0).integers(0, (sc.world_size + 1) ** 2, 5000)
    got = jump.values(np.repeat(base[None], cells.size, axis=0), cells)
    assert bits(got) == bits(fire.terrain.reshape(-1)[cells].astype(np.float64))


@settings(max_examples=20, deadline=None)
@given(
    counts=st.lists(st.lists(st.integers(0, 40), min_size=3, max_size=3), min_size=1, max_size=12)
)
def test_uniform_blocks_equal_successive_draws(counts):
    """World ``b``'s values are ``random(k)`` of its own generator, call after call, including a
    request longer than the block (the rows grow)."""
    seeds = [11, 12, 13]
    blocks = UniformBlocks(3, block=16)
    for b, s in enumerate(seeds):
        blocks.reset(b, np.random.default_rng(s))
    refs = [np.random.default_rng(s) for s in seeds]
    for row in counts:
        k = np.array(row, dtype=np.int64)
        worlds = np.flatnonzero(k)
        got = blocks.take(worlds, k[worlds])
        want = np.concatenate([refs[b].random(int(k[b])) for b in worlds.tolist()] or [np.zeros(0)])
        assert bits(got) == bits(want)


def test_seeds():
    """Gymnasium's seed rule: an int ``s`` gives world ``b`` the seed ``s + b`` whichever worlds
    are reset; a list holds one seed per world or one per world reset; streams need ints or
    SeedSequences."""
    assert world_seeds(3, [0, 1, 2], 5) == [5, 6, 7]
    assert world_seeds(4, [1, 3], 5) == [6, 8]
    assert world_seeds(2, [0, 1], None) == [None, None]
    assert world_seeds(3, [0, 2], [7, 8, 9]) == [7, 9]
    assert world_seeds(3, [0, 2], [7, 9]) == [7, 9]
    with pytest.raises(ValueError, match="need 3 seeds"):
        world_seeds(3, [0, 1, 2], [1, 2])
    with pytest.raises(ValueError, match="seed"):
        spawn_streams(np.random.default_rng(0))
    a = spawn_streams(3)
    assert [g.random() for g in a] == [g.random() for g in spawn_streams(np.random.SeedSequence(3))]


@pytest.mark.parametrize("bad", [-1, True, "x", [1, -2], [0, 1.5], [None, "3"]])
def test_bad_seeds_are_seed_errors_in_both_vector_envs(bad):
    """A bad seed, or a bad seed in the list, given to a batched reset is the world's one-line
    SeedError (the check of fcplan.world.check_seed), in world_seeds and at both vector levels;
    a string is not taken for a list of seeds."""
    from fcplan.env import vector_env
    from fcplan.errors import SeedError

    with pytest.raises(SeedError, match=r"^seed: must be an integer >= 0"):
        world_seeds(2, [0, 1], bad)
    for mode in ("motion", "task"):
        env = vector_env("practice", mode, 2)
        with pytest.raises(SeedError, match=r"^seed: must be an integer >= 0"):
            env.reset(seed=bad)
