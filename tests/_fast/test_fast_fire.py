"""Equivalence tests of fcplan._fast.fire: the wind drawn ahead is the per-tick rule
(:func:`fcplan.fire.wind_draws`), the whole-array front step is the rule on the moving fronts
(``Fire._advance_moving``), ignition on Python ints is the numpy rule (``Fire._ignite``), the
cheaper unique is ``np.unique``; and the fire's shortcuts (draws ahead, the edge-margin check,
the queued visits) leave its trajectory bit for bit unchanged."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fcplan.fire as fire_mod
from fcplan._fast.fire import advance_whole, draw_ahead, draw_ahead_tables, ignite_cells, unique
from fcplan.farsite import interp_ratio, ratio_tabulated, wind_from_tables
from fcplan.fire import BURNING, WIND_DIR_SD_RAD, WIND_SPEED_SD, Fire, spread_rate_ratio, wind_draws
from fcplan.scenario import load_scenario
from fcplan.world import World
from tests._fast.bits import bits
from tests.test_fire import region


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(1)


@settings(max_examples=4, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), prune_every=st.integers(3, 40))
def test_burn_box_holds_every_burning_cell_and_visits_add_up(scenario, seed, prune_every):
    """The fire's burn_box contains every burning cell after every tick (with pruning), and the
    queued visit rows give the same grid as adding every tick's visits at once (reading
    ``visits`` every tick flushes the queue every tick)."""
    worlds = [World().reset(scenario, seed=seed) for _ in range(2)]
    rng = np.random.default_rng(seed)
    for t in range(500):
        picks = None
        for k, world in enumerate(worlds):
            fire = world.fire
            world.step()
            if k == 0:
                fire.visits  # noqa: B018 - flushes the queue
            if t % prune_every == 0 and fire.n_burning:
                if picks is None:
                    cells = np.flatnonzero(fire.state.reshape(-1) == BURNING)
                    picks = rng.choice(cells, size=min(3, cells.size), replace=False)
                fire.prune(picks)
            xs, ys = np.nonzero(fire.state == BURNING)
            if xs.size:
                x0, x1, y0, y1 = fire.burn_box
                assert x0 <= xs.min() and xs.max() <= x1 and y0 <= ys.min() and ys.max() <= y1
    a, b = (w.fire for w in worlds)
    assert a.visits.sum() > 0
    np.testing.assert_array_equal(a.visits, b.visits)
    np.testing.assert_array_equal(a.state, b.state)


def _run_pair(a: Fire, b: Fire, ticks: int, prune_every: int, small_b: int | None = None) -> None:
    """Step two fires side by side, pruning the same cells, asserting bit-identical states
    (``small_b``: the value of ``fcplan.fire._SMALL`` while ``b`` steps and prunes)."""
    saved = fire_mod._SMALL
    for t in range(ticks):
        new_a = a.step()
        fire_mod._SMALL = saved if small_b is None else small_b
        try:
            new_b = b.step()
        finally:
            fire_mod._SMALL = saved
        assert bits(new_a) == bits(new_b)
        assert bits(a._xy) == bits(b._xy)
        assert bits(a.alive) == bits(b.alive)
        assert bits(a.frozen) == bits(b.frozen)
        assert bits(a.cell) == bits(b.cell)
        assert a.burn_box == b.burn_box
        if prune_every and t % prune_every == 0:
            cells = np.flatnonzero(a.state.reshape(-1) == BURNING)[::3]
            assert bits(a.prune(cells)) == bits(b.prune(cells))
    assert bits(a.state) == bits(b.state)
    assert bits(a.block_burning) == bits(b.block_burning)
    assert bits(a.visits) == bits(b.visits)


_SEED, _COORD = st.integers(0, 2**31 - 1), st.integers(0, 1199)
_FRONTS = st.integers(1, 300)  # (over 256: C/R is not drawn ahead)
# one region anywhere on the x axis (some fronts leave the map), pruned every few ticks
_WIND = st.sampled_from(["fresh", "tables"])
_ONE_REGION_RUN = {
    "seed": _SEED,
    "fronts": _FRONTS,
    "cx": _COORD,
    "prune_every": st.integers(0, 7),
    "wind": _WIND,
}


@settings(max_examples=25, deadline=None)
@given(**_ONE_REGION_RUN)
def test_draws_ahead_move_fronts_exactly_as_tick_by_tick_draws(seed, fronts, cx, prune_every, wind):
    """Drawing and precomputing 64 steps ahead gives bit-identical fronts, cells and visits to
    drawing every step (also with more than 256 fronts, pruning, fronts leaving the map, and in
    both wind models)."""
    regions = [region(center=(cx, 600), fronts=fronts, fuel=20, delay_s=0.5)]
    ahead = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    saved = fire_mod._PRE_TICKS
    fire_mod._PRE_TICKS = 1
    try:
        per_tick = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    finally:
        fire_mod._PRE_TICKS = saved
    assert per_tick._pre_len == 1 and ahead._pre_len > 1
    _run_pair(ahead, per_tick, 150, prune_every)


@settings(max_examples=25, deadline=None)
@given(
    seed=_SEED,
    cx=_COORD,
    cy=_COORD,
    fuel=st.integers(1, 30),
    prune_every=st.integers(0, 7),
    wind=_WIND,
)
def test_edge_margin_shortcut_agrees_with_the_full_map_check(seed, cx, cy, fuel, prune_every, wind):
    """Skipping the per-front map check while the burn box keeps ``_edge_margin`` from the edges
    changes nothing: fronts die at exactly the same ticks as with the check on every tick (also
    once fronts freeze and the whole-array step moves idle fronts by a zero spread)."""
    regions = [region(center=(cx, cy), fronts=15, fuel=fuel)]
    fast = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    full = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    full._edge_margin = float("inf")  # never trust the box: check every front every tick
    _run_pair(fast, full, 200, prune_every)


@settings(max_examples=25, deadline=None)
@given(**_ONE_REGION_RUN)
def test_small_fire_kernels_move_fronts_exactly_as_the_vector_rule(
    seed, fronts, cx, prune_every, wind
):
    """With a few fresh cells per tick the fire ignites on Python ints (ignite_cells) and checks
    landings on lists; with ``_SMALL = 0`` every tick takes the numpy rule (``Fire._ignite``):
    fronts, cells, blocks, burn box and visits stay bit-identical (with pruning, freezing and
    fronts leaving the map)."""
    regions = [region(center=(cx, 600), fronts=fronts, fuel=20, delay_s=0.3)]
    kernel = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    rule = Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind)
    _run_pair(kernel, rule, 120, prune_every, small_b=0)


def _assert_rows_are_the_per_step_rule(seed, fill, per_step_wind, ratio_of, ticks, n):
    """Rows of the (T, 2, n) and (T, n) buffers that ``fill(rng, z, sc, ratio)`` fills are bit
    for bit ``T`` successive ``per_step_wind(rng)`` (and ``ratio_of`` their U), and the two
    streams stay in step."""
    z, sc = np.empty((ticks, 2, n)), np.empty((ticks, 2, n))
    ratio = np.empty((ticks, n))
    rng = np.random.default_rng(seed)
    fill(rng, z, sc, ratio)
    per_step = np.random.default_rng(seed)
    for t in range(ticks):
        u, sin_t, cos_t = per_step_wind(per_step)
        assert bits(z[t, 0]) == bits(u)
        assert bits(sc[t, 0]) == bits(sin_t)
        assert bits(sc[t, 1]) == bits(cos_t)
        assert bits(ratio[t]) == bits(ratio_of(u))
    assert bits(rng.random(3)) == bits(per_step.random(3))


@settings(max_examples=100, deadline=None)
@given(seed=_SEED, n=_FRONTS, ticks=st.integers(1, 70))
def test_wind_drawn_ahead_is_the_per_tick_rule(seed, n, ticks):
    """draw_ahead fills T ticks of U, sin(Theta), cos(Theta) and C/R that are, row by row, bit
    for bit what T successive calls of wind_draws (and the tabulated C/R of their U) give."""
    g = np.random.default_rng(seed + 1)
    wind, theta = g.uniform(0.0, 15.0, n), g.uniform(0.0, 2.0 * np.pi, n)
    sd = (WIND_SPEED_SD, WIND_DIR_SD_RAD)

    def fill(rng, z, sc, ratio):
        draw_ahead(rng, z, sc, ratio, wind, theta, *sd, interp_ratio)

    _assert_rows_are_the_per_step_rule(
        seed, fill, lambda rng: wind_draws(rng, wind, theta), interp_ratio, ticks, n
    )


@settings(max_examples=100, deadline=None)
@given(seed=_SEED, n=_FRONTS, ticks=st.integers(1, 70), regions=st.integers(1, 4))
def test_wind_drawn_ahead_from_tables_is_the_per_step_rule(seed, n, ticks, regions):
    """draw_ahead_tables fills T steps of U, sin(Theta), cos(Theta) and C/R that are, row by
    row, bit for bit what T successive calls of wind_from_tables (and the exact C/R of each
    table entry) give."""
    g = np.random.default_rng(seed + 1)
    length = int(g.integers(1, 1300))
    fire_regions = [region(wind_speed=float(g.uniform(0, 15))) for _ in range(regions)]
    fire = Fire(fire_regions, length, 10, np.random.default_rng(seed), wind_model="tables")
    tables = fire.wind_tables
    region_of = g.integers(0, regions, size=n)
    base = region_of.astype(np.int64) * length
    tab_u = np.ascontiguousarray(tables[:, 0]).reshape(-1)
    theta = np.ascontiguousarray(tables[:, 1]).reshape(-1)
    tab = (tab_u, np.sin(theta), np.cos(theta), spread_rate_ratio(tab_u))

    def fill(rng, z, sc, ratio):
        draw_ahead_tables(rng, z, sc, ratio, base, length, *tab)

    _assert_rows_are_the_per_step_rule(
        seed,
        fill,
        lambda rng: wind_from_tables(rng, tables, region_of),
        spread_rate_ratio,
        ticks,
        n,
    )


@settings(max_examples=50, deadline=None)
@given(
    seed=_SEED,
    fronts=_FRONTS,
    cx=_COORD,
    ticks=st.integers(1, 80),
    freeze_every=st.integers(0, 4),
    delayed=st.booleans(),
    wind=_WIND,
)
def test_whole_array_step_is_the_rule_on_the_moving_fronts(
    seed, fronts, cx, ticks, freeze_every, delayed, wind
):
    """Where Fire.step takes it (every front moves, or C/R of every front was drawn ahead),
    advance_whole moves the moving fronts to the positions of ``Fire._advance_moving`` bit for
    bit and leaves the other fronts (frozen, dead, region not yet active) exactly in place."""
    regions = [region(center=(cx, 600), fronts=fronts, fuel=20)]
    if delayed:  # fronts that do not move yet
        regions.append(region(center=(600, 300), fronts=3, fuel=5, delay_s=60))
    fires = [
        Fire(regions, 1200, 10, np.random.default_rng(seed), wind_model=wind) for _ in range(2)
    ]
    for fire in fires:
        for _ in range(ticks):
            fire.step()
        if freeze_every:  # prune where some fronts stand: they freeze
            fire.prune(fire.cell[fire.alive][::freeze_every])
    kernel, rule = fires
    idx = kernel._refresh_moving()
    rule._refresh_moving()
    pre_ratio, t = kernel._pre_ratio, kernel._pre_t % kernel._pre_len
    if idx.size == 0 or not (kernel._all_moving or pre_ratio is not None):
        return
    before = kernel._xy.copy()
    ratio = ratio_tabulated(kernel._pre_u[t]) if pre_ratio is None else pre_ratio[t]
    xy = advance_whole(kernel, t, ratio, kernel._all_moving)
    moved = rule._advance_moving(idx, t)
    assert xy is kernel._xy
    assert bits(xy[:, idx]) == bits(moved)
    assert bits(kernel._xy) == bits(rule._xy)
    idle = np.ones(kernel.n_fronts, dtype=bool)
    idle[idx] = False
    assert bits(kernel._xy[:, idle]) == bits(before[:, idle])


@settings(max_examples=200, deadline=None)
@given(
    cells=st.lists(st.integers(0, 99 * 100 + 99), min_size=0, max_size=40),
    burning=st.lists(st.integers(0, 99 * 100 + 99), max_size=20),
)
def test_ignition_kernel_is_the_vector_rule(cells, burning):
    """ignite_cells(fire, unburnt cells) returns the cells of ``Fire._ignite`` (sorted, unique,
    int64) and leaves the same states, block counts, burn box and counters, whatever the repeats
    and order of the cells."""
    fires = [Fire([region(center=(50, 50))], 100, 10, np.random.default_rng(0)) for _ in range(2)]
    for fire in fires:
        fire._ignite(np.array(burning, dtype=np.int64))
    kernel, rule = fires
    unburnt = [c for c in cells if kernel._state_flat[c] == fire_mod.UNBURNT]
    saved = fire_mod._SMALL
    fire_mod._SMALL = -1  # the numpy rule for any number of cells
    try:
        expected = rule._ignite(np.array(cells, dtype=np.int64))
    finally:
        fire_mod._SMALL = saved
    got = ignite_cells(kernel, unburnt)
    assert bits(got) == bits(expected)
    assert bits(kernel.state) == bits(rule.state)
    assert bits(kernel.block_burning) == bits(rule.block_burning)
    assert kernel.burn_box == rule.burn_box
    assert (kernel.n_burning, kernel.n_ignited) == (rule.n_burning, rule.n_ignited)


@settings(max_examples=200, deadline=None)
@given(values=st.lists(st.integers(-(2**62), 2**62), max_size=60))
def test_unique_is_numpy_unique(values):
    """unique(a) is np.unique(a): same values, order and dtype, for any 1-D int64 array."""
    a = np.array(values, dtype=np.int64)
    assert bits(unique(a)) == bits(np.unique(a))
