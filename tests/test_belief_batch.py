"""Tests for fcplan.belief_batch: the batched belief is, world for world, the single belief."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fcplan import load_scenario
from fcplan.batch import BatchWorld
from fcplan.belief import Belief
from fcplan.belief_batch import BatchBelief, coverage_ages
from fcplan.world import StepInfo
from tests.batch.drive import random_commands


def _step_info(info, ticks, tps, b):
    """World ``b``'s slice of a batch tick as the single world's StepInfo."""

    def part(p):
        return p[1][p[0] == b]

    return StepInfo(
        int(ticks[b]), int(ticks[b]) / tps, part(info.ignited), part(info.sensed),
        part(info.newly_sensed), part(info.pruned), info.fov[b].tolist(),
        tuple(np.flatnonzero(info.dumped[b]).tolist()),
        tuple(np.flatnonzero(info.arrived[b]).tolist()),
    )  # fmt: skip


def _same(view_known, belief, batch_belief, b, blocks):
    """Every read of world ``b``: equal arrays, dtypes and order."""
    np.testing.assert_array_equal(view_known, belief.known, strict=True)
    assert int(batch_belief.tick[b]) == belief.tick
    assert int(batch_belief.n_pruned[b]) == belief.n_pruned
    np.testing.assert_array_equal(batch_belief.last_seen(b), belief.last_seen, strict=True)
    for blk in blocks:
        got = batch_belief.view(b, blk).coverage_age_s(blk)
        assert got.tobytes() == belief.coverage_age_s(blk).tobytes(), blk
    np.testing.assert_array_equal(batch_belief.coverage[b], belief.coverage, strict=True)


@pytest.mark.parametrize("name", ["1", "24"])
def test_batch_belief_equals_per_world_beliefs(name):
    """Property: fed the same ticks (some worlds held by the step mask, one reset mid-episode),
    world b's known cells (order included), last_seen, tick, pruned count, coverage and
    coverage ages (block sizes on every layout path) equal a Belief fed world b's ticks, at
    reads every few ticks."""
    sc = load_scenario(name).replace(duration_s=60)
    n = 4
    batch = BatchWorld(sc, n)
    batch.reset(seeds=list(range(10, 10 + n)))
    bb = BatchBelief(sc, n)
    ref = [Belief(sc) for _ in range(n)]
    rng = np.random.default_rng(0)
    ids = batch.team.one.ids
    tps = sc.ticks_per_second
    pruned = 0
    for t in range(sc.n_ticks):
        if t % 7 == 0:
            for b in range(n):
                batch.team.apply(b, random_commands(rng, sc, ids))
        mask = rng.random(n) < 0.9
        info = batch.step(mask=mask)
        bb.update(info, batch.tick)
        pruned += info.pruned[0].size
        for b in np.flatnonzero(info.ran).tolist():
            ref[b].update(_step_info(info, batch.tick, tps, b))
        if t == sc.n_ticks // 2:
            reset = np.zeros(n, dtype=bool)
            reset[2] = True
            batch.reset(seeds=[99], mask=reset)
            bb.reset(np.array([2]))
            ref[2] = Belief(sc)
        if t % 10 == 3:
            for b in range(n):
                _same(bb.known(b), ref[b], bb, b, (100,) if b else (100, 60, 45, 7))
    assert pruned > 0 and any(r.known.size for r in ref)


@pytest.mark.parametrize("block_px", [100, 60, 40, 45, 7, 1200])
def test_coverage_ages_equal_belief(block_px):
    """Property: coverage_ages of stacked random coverage grids and ticks equals each grid's
    Belief.coverage_age_s bit for bit (every block layout: square sub-blocks, equal blocks,
    bincount, blocks without a coarse centre)."""
    sc = load_scenario(1)
    rng = np.random.default_rng(block_px)
    beliefs = []
    for _ in range(5):
        bel = Belief(sc)
        tick = int(rng.integers(0, 3000))
        bel.tick = tick
        cov = rng.integers(-1, tick + 1, bel.coverage.shape).astype(np.int32)
        bel._coverage[...] = cov
        beliefs.append(bel)
    cov = np.stack([b.coverage for b in beliefs])
    ticks = np.array([b.tick for b in beliefs])
    got = coverage_ages(cov, ticks, sc.world_size, 20, sc.ticks_per_second, block_px)
    for b, bel in enumerate(beliefs):
        assert got[b].tobytes() == bel.coverage_age_s(block_px).tobytes()


def test_reset_clears_every_cell_it_wrote_and_only_its_worlds():
    """Property: after a reset of some worlds mid-episode, their stored maps (seen ticks and
    known mask) are all zero, as freshly created, though only the touched rows were cleared;
    the other worlds keep theirs; and last_seen_at of a view reads the dense last_seen map at
    any cells (never-sensed ones give -1)."""
    sc = load_scenario("1").replace(duration_s=30)
    n = 3
    batch = BatchWorld(sc, n)
    batch.reset(seeds=[0, 1, 2])
    bb = BatchBelief(sc, n)
    rng = np.random.default_rng(1)
    ids = batch.team.one.ids
    for t in range(sc.n_ticks):
        if t % 7 == 0:
            for b in range(n):
                batch.team.apply(b, random_commands(rng, sc, ids))
        bb.update(batch.step(), batch.tick)
    ww = sc.world_size**2
    written = [int(np.count_nonzero(bb._seen[b])) for b in range(n)]
    assert min(written) > 0
    before = bb._seen[1].copy()
    cells = rng.integers(0, ww, 500)
    cells = np.concatenate([cells, bb.known(1)])
    got = bb.view(1, 100).last_seen_at(cells)
    assert got.dtype == np.int32 and (got == -1).any()
    np.testing.assert_array_equal(got, bb.last_seen(1).reshape(-1)[cells])
    bb.reset(np.array([0, 2]))
    for b in (0, 2):
        assert not bb._seen[b].any() and not bb._mask[b * ww : (b + 1) * ww].any()
        assert (bb.last_seen(b) == -1).all() and bb.known(b).size == 0
    np.testing.assert_array_equal(bb._seen[1], before)
    assert not bb._touched[[0, 2]].any() and bb._touched[1].any()


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(0, 199), st.integers(1, 7)), max_size=6), st.integers(0, 99))
def test_random_resets_read_as_fresh_beliefs(resets, seed):
    """Property: whatever worlds are reset at whatever ticks (several at once, the same world
    twice, one before it has sensed anything), every world's dense last_seen, known cells
    (in order) and stored maps read as a single Belief fed only its ticks since its reset; a
    reset clears only rows that world wrote, so this checks nothing written survives one."""
    sc = load_scenario("practice").replace(duration_s=20)
    n = 3
    batch = BatchWorld(sc, n)
    batch.reset(seeds=[seed, seed + 1, seed + 2])
    sensed = 0
    bb = BatchBelief(sc, n)
    ref = [Belief(sc) for _ in range(n)]
    rng = np.random.default_rng(seed)
    ids = batch.team.one.ids
    tps = sc.ticks_per_second
    when = {}
    for t, which in resets:
        when.setdefault(t, 0)
        when[t] |= which
    for t in range(sc.n_ticks):
        if t % 5 == 0:
            for b in range(n):
                batch.team.apply(b, random_commands(rng, sc, ids))
        info = batch.step()
        bb.update(info, batch.tick)
        sensed += info.sensed[0].size
        for b in range(n):
            ref[b].update(_step_info(info, batch.tick, tps, b))
        rows = [b for b in range(n) if when.get(t, 0) >> b & 1]
        if rows:
            mask = np.isin(np.arange(n), rows)
            batch.reset(seeds=[seed + 10 + b for b in rows], mask=mask)
            bb.reset(np.array(rows))
            for b in rows:
                ref[b] = Belief(sc)
        if t % 25 == 24 or t == sc.n_ticks - 1:
            for b in range(n):
                np.testing.assert_array_equal(bb.known(b), ref[b].known, strict=True)
                np.testing.assert_array_equal(bb.last_seen(b), ref[b].last_seen, strict=True)
    assert sensed > 0
    ww = sc.world_size**2
    for b in range(n):  # the stored maps hold exactly what the world sensed since its reset
        assert np.count_nonzero(bb._seen[b]) == np.count_nonzero(ref[b].last_seen >= 0)
        assert np.count_nonzero(bb._mask[b * ww : (b + 1) * ww]) == ref[b].known.size
