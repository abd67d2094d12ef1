"""Tests for fcplan.fire: FARSITE statistics, the fire's clock, delays, pruning, map edges,
wind models, determinism."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.fire import BURNING, INTENSITY_COEFF, PRUNED, Fire, spread_rate_ratio
from fcplan.scenario import FireRegion


def region(**kw) -> FireRegion:
    base = dict(center=(600, 600), fronts=10, delay_s=0, fuel=10, wind_speed=5, wind_dir_deg=45)
    base.update(kw)
    return FireRegion(**base)


def first_step(fire: Fire) -> tuple[np.ndarray, np.ndarray]:
    x0, y0 = fire.x.copy(), fire.y.copy()
    fire.step()
    return fire.x - x0, fire.y - y0


def test_spread_ratio_matches_reference_table():
    """C/R is 0 at U=0, 0.428 at 2, 0.460 at 3, 0.487 at 5 and 0.499 at 10 (spec 1.4)."""
    got = spread_rate_ratio(np.array([0.0, 2.0, 3.0, 5.0, 10.0]))
    np.testing.assert_allclose(got, [0.0, 0.428, 0.460, 0.487, 0.499], atol=2e-3)


def test_mean_first_step_is_about_quarter_fuel_at_wind_5():
    """The mean front step on the first tick is about 0.24 x fuel px at wind speed 5."""
    for fuel in (3.0, 10.0):
        fire = Fire([region(fronts=40_000, fuel=fuel)], 1200, 10, np.random.default_rng(1))
        dx, dy = first_step(fire)
        mean = np.hypot(dx, dy).mean()
        assert 0.22 * fuel < mean < 0.26 * fuel, mean


@pytest.mark.parametrize("tps", [1, 3, 5, 7, 10, 20, 40])
def test_fire_takes_ten_steps_per_simulated_second_at_any_rate(tps):
    """After tick t at r ticks/s the fire has taken floor(10 t / r) steps, and (without pruning)
    its fronts, cells and visits are bit for bit those of the 10 Hz fire after as many steps."""
    regions = [region(fronts=30), region(center=(300, 900), fronts=5, delay_s=1.25)]
    ref = Fire(regions, 1200, 10, np.random.default_rng(2))
    fire = Fire(regions, 1200, tps, np.random.default_rng(2))
    for t in range(1, 6 * tps + 1):
        fire.step()
        assert fire.n_steps == 10 * t // tps
        while ref.n_steps < fire.n_steps:
            ref.step()
        np.testing.assert_array_equal(fire._xy, ref._xy)
        np.testing.assert_array_equal(fire.state, ref.state)
    np.testing.assert_array_equal(fire.visits, ref.visits)


@pytest.mark.parametrize(("tps", "wake_tick"), [(5, 8), (10, 15), (20, 30), (40, 60)])
def test_region_wakes_on_the_first_step_after_its_delay(tps, wake_tick):
    """A region delayed 1.45 s starts with step 15 (1.5 s): its ignition cells burn on the tick
    that runs step 15 and its fronts have not moved before that step."""
    fire = Fire([region(delay_s=1.45)], 1200, tps, np.random.default_rng(3))
    assert fire.start_step.tolist() == [15]
    start = fire._xy.copy()
    for t in range(1, wake_tick):
        assert fire.step().size == 0 and fire.n_burning == 0, t
    np.testing.assert_array_equal(fire._xy, start)
    assert fire.step().size > 0
    assert fire.n_steps >= 15 and fire.region_active.all()


def test_drift_follows_wind_azimuth():
    """Fronts drift along the wind azimuth (90 deg = +x) by about e^-2 of the step length."""
    fire = Fire([region(fronts=60_000, wind_dir_deg=90)], 1200, 10, np.random.default_rng(3))
    dx, dy = first_step(fire)
    step = np.hypot(dx, dy).mean()
    assert 0.08 * step < dx.mean() < 0.2 * step
    assert abs(dy.mean()) < 0.03 * step
    fire = Fire([region(fronts=60_000, wind_dir_deg=0)], 1200, 10, np.random.default_rng(3))
    dx, dy = first_step(fire)
    assert dy.mean() > 0.08 * step and abs(dx.mean()) < 0.03 * step


def test_delay_is_respected_and_ignition_cells_burn_on_activation():
    """A region with a 3 s delay burns nothing before tick 30 and its ignition cells at tick 30."""
    fire = Fire([region(delay_s=3.0)], 1200, 10, np.random.default_rng(4))
    ignition = set((fire.x.astype(int) * 1200 + fire.y.astype(int)).tolist())
    x_before = fire.x.copy()
    for _ in range(29):
        assert fire.step().size == 0
    assert fire.n_burning == 0
    np.testing.assert_array_equal(fire.x, x_before)
    new = fire.step()
    assert ignition <= set(new.tolist())
    assert fire.n_burning == int((fire.state == BURNING).sum())


def test_ignition_box_is_centre_plus_minus_half_width():
    """Initial fronts are integer pixels in [c - 50, c + 49] on each axis."""
    fire = Fire([region(fronts=5000, center=(350, 450))], 1200, 10, np.random.default_rng(5))
    assert np.all(fire.x == np.round(fire.x))
    assert fire.x.min() >= 300 and fire.x.max() <= 399
    assert fire.y.min() >= 400 and fire.y.max() <= 499


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), every=st.integers(1, 5), share=st.integers(1, 3))
def test_pruned_cells_never_burn_again_and_fronts_freeze(seed, every, share):
    """Pruned cells never re-ignite and frozen fronts never move, whatever gets pruned when."""
    fire = Fire([region(fronts=12, fuel=15)], 1200, 10, np.random.default_rng(seed))
    ever_pruned = np.zeros_like(fire.state, dtype=bool)
    for t in range(120):
        frozen = fire.frozen.copy()
        xy = np.stack([fire.x, fire.y])[:, frozen].copy()
        fire.step()
        np.testing.assert_array_equal(np.stack([fire.x, fire.y])[:, frozen], xy)
        assert not np.any((fire.state == BURNING) & ever_pruned)
        if t % every == 0:
            burning = np.flatnonzero(fire.state.reshape(-1) == BURNING)
            fire.prune(burning[::share])
            ever_pruned |= fire.state == PRUNED
    assert fire.n_burning == int((fire.state == BURNING).sum())
    assert fire.n_pruned == int((fire.state == PRUNED).sum())
    assert fire.n_burning + fire.n_pruned == fire.n_ignited


def test_frozen_front_keeps_its_position():
    """Once its cell is pruned a front stays exactly where it is for the rest of the episode."""
    fire = Fire([region(fronts=5)], 1200, 10, np.random.default_rng(6))
    for _ in range(5):
        fire.step()
    fire.prune(fire.cell[:2])
    assert fire.frozen[:2].all()
    xy = np.stack([fire.x[:2], fire.y[:2]]).copy()
    for _ in range(50):
        fire.step()
    np.testing.assert_array_equal(np.stack([fire.x[:2], fire.y[:2]]), xy)


def test_fronts_leaving_the_map_die_without_a_phantom_cell():
    """Fronts that leave the map die; no phantom burning cell appears at (0, 0)."""
    fire = Fire(
        [region(center=(50, 1150), fronts=200, fuel=20, wind_dir_deg=135)],
        1200,
        10,
        np.random.default_rng(7),
    )
    for _ in range(400):
        fire.step()
    assert (~fire.alive).any()
    assert fire.state[0, 0] != BURNING or 0 in (fire.cell[fire.alive])
    dead_cells = fire.cell[~fire.alive]
    assert np.all(
        (fire.x[~fire.alive] < 0)
        | (fire.x[~fire.alive] >= 1200)
        | (fire.y[~fire.alive] < 0)
        | (fire.y[~fire.alive] >= 1200)
    )
    assert dead_cells.size > 0


def test_same_seed_same_fire_and_random_stream_independent_of_pruning():
    """Same seed gives the same fire; pruning elsewhere does not change other fronts' draws."""
    a = Fire([region(), region(center=(200, 900))], 1200, 10, np.random.default_rng(8))
    b = Fire([region(), region(center=(200, 900))], 1200, 10, np.random.default_rng(8))
    for _ in range(100):
        a.step()
        b.step()
    np.testing.assert_array_equal(a.state, b.state)
    # prune region 0's cells in b only: region 1's fronts must move identically
    b.prune(np.flatnonzero(b.state.reshape(-1) == BURNING))
    for _ in range(100):
        a.step()
        b.step()
    r1 = a.region == 1
    unfrozen = ~b.frozen & r1
    np.testing.assert_array_equal(a.x[unfrozen], b.x[unfrozen])


def test_one_visit_gives_reference_peak_intensity():
    """A single front visit radiates about 22.5 kW/m at its own cell (spec 1.5)."""
    fire = Fire([region(fronts=1)], 1200, 10, np.random.default_rng(9))
    fire.visits[600, 600] = 1
    peak = fire.intensity()[600, 600]
    assert 19.0 < peak < 25.0
    assert abs(INTENSITY_COEFF - 12.776) < 1e-3


def test_tabulated_spread_ratio_matches_formula():
    """The per-step lookup tables of C/R agree with the FARSITE formula (1e-4 for small batches;
    1.5e-4 for large ones away from the two kinks of sqrt|LB^2 - 1|, 0.0066 at them)."""
    from fcplan.farsite import _RATIO_TABLE, _U_GRID
    from fcplan.farsite import ratio_tabulated as _ratio

    u = np.linspace(-40, 60, 400_001)
    exact = spread_rate_ratio(u)
    np.testing.assert_allclose(np.interp(u, _U_GRID, _RATIO_TABLE), exact, atol=1e-4)
    big = _ratio(u)  # the large-batch path
    away = (np.abs(u) > 0.002) & (np.abs(u + 6.2189) > 0.002)
    np.testing.assert_allclose(big[away], exact[away], atol=1.5e-4)
    np.testing.assert_allclose(big, exact, atol=0.0066)


def test_block_counts_track_burning_cells():
    """The coarse burning-cell counts used to skip empty views equal the grid's cells per block."""
    from fcplan.fire import BLOCK

    fire = Fire([region(fronts=30, fuel=15)], 1200, 10, np.random.default_rng(11))
    for t in range(200):
        fire.step()
        if t % 20 == 0:
            fire.prune(np.flatnonzero(fire.state.reshape(-1) == BURNING)[::3])
    b = (fire.state == BURNING).reshape(1200 // BLOCK, BLOCK, 1200 // BLOCK, BLOCK).sum(axis=(1, 3))
    np.testing.assert_array_equal(fire.block_burning, b)


def test_front_stepping_into_a_pruned_cell_freezes_there_unburnt():
    """A moving front that steps into an already-pruned cell freezes there and does not burn it."""
    fire = Fire([region(fronts=200, fuel=20)], 1200, 10, np.random.default_rng(12))
    fire.step()
    # prune a wide ring of cells around the ignition box without touching any front's cell
    xs, ys = np.meshgrid(np.arange(520, 680), np.arange(520, 680), indexing="ij")
    flat = (xs * 1200 + ys).ravel()
    flat = flat[~np.isin(flat, fire.cell)]
    fire._state_flat[flat] = PRUNED  # pruned without ever burning (e.g. a firebreak)
    assert fire._moving is not None and fire._all_moving
    for _ in range(20):
        fire.step()
    assert fire.frozen.any()
    assert (fire._state_flat[fire.cell[fire.frozen]] == PRUNED).all()


def test_tables_model_draws_every_front_wind_from_its_region_tables():
    """In the tables model each region has W speeds ~ N(U, 2) and W directions ~ N(theta, 2):
    every front's wind of every step is one entry of its own region's tables."""
    regions = [region(wind_speed=5), region(center=(300, 300), wind_speed=12, wind_dir_deg=90)]
    fire = Fire(regions, 1000, 10, np.random.default_rng(13), wind_model="tables")
    tables = fire.wind_tables
    assert tables.shape == (2, 2, 1000)
    assert abs(tables[1, 0].mean() - 12) < 0.3 and abs(tables[1, 0].std() - 2) < 0.2
    assert abs(tables[1, 1].mean() - np.pi / 2) < 0.3 and abs(tables[1, 1].std() - 2) < 0.2
    fire.step()
    u, sin_t = fire._pre_u[:, :], fire._pre_sc[:, 0]
    for r in (0, 1):
        rows = fire.region == r
        assert np.isin(u[:, rows], tables[r, 0]).all()
        assert np.isin(sin_t[:, rows], np.sin(tables[r, 1])).all()
    np.testing.assert_array_equal(fire._pre_ratio, spread_rate_ratio(u))


def test_unknown_wind_model_is_refused():
    """A wind model other than fresh or tables is a ValueError naming the allowed values."""
    with pytest.raises(ValueError, match="fresh"):
        Fire([region()], 1200, 10, np.random.default_rng(0), wind_model="gusty")
