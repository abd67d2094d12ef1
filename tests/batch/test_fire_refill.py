"""Tests of fcplan.batch.fire's batched wind refill: drawing the next steps' wind of several
worlds at once gives, world by world, the values and generator states of the single fire's
per-world refill (:func:`fcplan._fast.fire.draw_ahead_tables`)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.batch.cells import CellGrid
from fcplan.batch.fire import BatchFire
from fcplan.scenario import load_scenario


def _fires(name: str, seeds: list[int]) -> tuple[BatchFire, BatchFire]:
    sc = load_scenario(name)
    out = []
    for _ in range(2):
        fire = BatchFire(sc, len(seeds), CellGrid(len(seeds), sc.world_size))
        for b, s in enumerate(seeds):
            fire.reset_world(b, np.random.default_rng(s))
        out.append(fire)
    return out[0], out[1]


@settings(max_examples=12, deadline=None)
@given(
    name=st.sampled_from(["practice", 24]),
    seeds=st.lists(st.integers(0, 2**32 - 1), min_size=2, max_size=6),
    pick=st.integers(1, 63),
)
def test_refill_of_many_worlds_equals_the_rule_per_world(name, seeds, pick):
    """The worlds chosen by ``pick`` (a bit mask) refilled together hold the wind rows and
    generator states that refilling them one by one with the rule's kernel gives."""
    batched, rule = _fires(name, seeds)
    worlds = np.array([b for b in range(len(seeds)) if pick >> b & 1] or [0])
    for _ in range(2):  # (twice: the second block continues each world's stream)
        batched._refill_worlds(worlds)
        for b in worlds.tolist():
            rule._refill(b)
    assert np.array_equal(batched.pre_z[:, :, 0], rule.pre_z[:, :, 0])
    assert np.array_equal(batched.pre_sc, rule.pre_sc)
    assert np.array_equal(batched.pre_ratio, rule.pre_ratio)
    for a, b in zip(batched.rngs, rule.rngs, strict=True):
        assert a.bit_generator.state == b.bit_generator.state
