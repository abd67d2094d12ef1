"""Tests for solvers.milp_model.kernels: each fast kernel equals its readable rule bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.taskgraph import TaskKind
from solvers.milp_model import MilpParams, build, build_milp_model, objective
from solvers.milp_model.kernels import (
    _axis_range,
    discounted_coverage,
    dominated,
    dominated_sparse,
    near_cells,
)
from solvers.milp_model.prune import dominated as dominated_rule
from solvers.milp_model.sensing import discounted_share
from tests.solvers.graphs import episode_graphs


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_seg=st.integers(0, 40),
    n_blocks=st.integers(0, 60),
    block=st.floats(20.0, 200.0),
    z=st.floats(10.0, 120.0),
    spread=st.floats(0.0, 2000.0),
    still=st.floats(0.0, 1.0),
)
def test_discounted_coverage_equals_the_rule(seed, n_seg, n_blocks, block, z, spread, still):
    """discounted_coverage gives exactly (bit for bit, +0.0 outside the swath) what the
    readable discounted_share gives, on segments of any length and
    direction (points included), blocks near and far, at any altitude and block size."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 3000.0, (n_seg, 2))
    q = p + rng.normal(0.0, spread + 1e-3, (n_seg, 2))
    q = np.where(rng.random((n_seg, 1)) < still, p, q)  # some segments are points
    centres = rng.uniform(-200.0, 3200.0, (n_blocks, 2))
    t_start = rng.uniform(0.0, 80.0, n_seg)
    args = (p, q, centres, block, z, 10.0, 120.0, float(rng.uniform(5.0, 300.0)), t_start, 60.0)
    fast, rule = discounted_coverage(*args), discounted_share(*args)
    assert fast.shape == rule.shape == (n_seg, n_blocks)
    assert fast.tobytes() == rule.tobytes()


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(0, 40),
    groups=st.integers(1, 6),
    n_blocks=st.integers(1, 12),
    density=st.floats(0.0, 1.0),
    levels=st.integers(1, 4),
)
@pytest.mark.parametrize("kernel", [dominated, dominated_sparse])
def test_dominated_equals_the_rule(kernel, seed, n, groups, n_blocks, density, levels):
    """Both one-pass kernels (dense covers per pair, and the sparse difference of each pair's
    rows) drop exactly the routes the per-group rule drops, with ties in value and cover
    (coarse levels make them common) and groups without any cover."""
    rng = np.random.default_rng(seed)
    keys = rng.integers(0, groups, (n, 2))
    value = rng.integers(0, 4, n).astype(np.float64)
    dense = rng.integers(0, levels + 1, (n, n_blocks)) * (rng.random((n, n_blocks)) < density)
    cover = sp.csr_array(dense.astype(np.int64))
    assert kernel(keys, value, cover).tolist() == dominated_rule(keys, value, cover).tolist()


def test_models_built_with_the_rules_are_equal(monkeypatch):
    """A model built agent by agent with the readable rules in place of the kernels is the
    same model (rows, objective, routes) as the default build, on real episodes' graphs:
    scenario #1 and #24 over their first minute."""
    fast = [build_milp_model(g) for n in (1, 24) for g in episode_graphs(n, (0, 200, 600))]
    monkeypatch.setattr(build, "dominated", dominated_rule)
    monkeypatch.setattr(objective, "discounted_coverage", discounted_share)
    monkeypatch.setattr(
        objective,
        "near_cells_each",
        lambda c, snaps, r: np.array([objective.near_known_cells(c, [q], r) for q in snaps]),
    )
    slow = [
        build_milp_model(g, batched=False)
        for n in (1, 24)
        for g in episode_graphs(n, (0, 200, 600))
    ]
    for a, b in zip(fast, slow, strict=True):
        assert a.n_routes == b.n_routes
        for x, y in ((a.c, b.c), (a.b_ub, b.b_ub), (a.route_tasks, b.route_tasks)):
            assert np.array_equal(x, y)
        assert (a.A_ub != b.A_ub).nnz == 0


@settings(max_examples=120, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_blocks=st.integers(0, 50),
    n_snap=st.integers(0, 4),
    n_fire=st.integers(0, 30),
    reach=st.floats(10.0, 400.0),
    whole=st.booleans(),
    on_grid=st.booleans(),
)
def test_near_cells_equals_the_rule(seed, n_blocks, n_snap, n_fire, reach, whole, on_grid):
    """The kernel gives exactly (bit for bit) the readable rule's most known cells near each
    block over the snapshots, with block centres on a grid (the difference-array path) or
    scattered (the bucketed pairs), fires exactly at the reach on either side included, with
    whole cell counts; it refuses fractional ones (their sums would depend on the order)."""
    rng = np.random.default_rng(seed)
    if on_grid:
        centres = (rng.integers(0, 30, (n_blocks, 2)) + 0.5) * 100.0
    else:
        centres = rng.uniform(0.0, 3000.0, (n_blocks, 2))
    snaps = []
    for _ in range(n_snap):
        pos = rng.uniform(-100.0, 3100.0, (n_fire, 2))
        if n_blocks and n_fire:
            pos[0] = centres[0] + reach  # exactly at the reach
            pos[-1] = centres[-1] - np.array([reach, -reach])
        cells = rng.integers(0, 40, n_fire).astype(np.float64)
        snaps.append((pos, cells if whole else cells + 0.25))
    rule = objective.near_known_cells(centres, snaps, reach)
    if whole or not any(len(c) for _, c in snaps):
        assert near_cells(centres, snaps, reach).tobytes() == rule.tobytes()
    else:
        with pytest.raises(ValueError, match="whole cell counts"):
            near_cells(centres, snaps, reach)


@settings(max_examples=100, deadline=None)
@given(
    f=st.floats(-1e4, 1e4),
    reach=st.floats(0.0, 500.0),
    steps=st.lists(st.integers(-3, 3), min_size=1, max_size=12),
)
def test_axis_range_is_the_run_the_rule_accepts(f, reach, steps):
    """The run of grid values within reach of a fire is exactly the values the rule's test
    ``|g - f| <= reach`` accepts, also when grid values lie a few ulps either side of
    ``f - reach`` and ``f + reach`` (searchsorted's guess is off there)."""
    near = [v + k * np.spacing(v) for v in (f - reach, f + reach) for k in steps]
    grid = np.unique(np.array([*near, f - 2 * reach - 1.0, f, f + 2 * reach + 1.0]))
    lo, hi = _axis_range(grid, np.array([f]), reach)
    inside = np.flatnonzero(np.abs(grid - f) <= reach)
    assert list(range(int(lo[0]), int(hi[0]))) == inside.tolist()


def test_kept_snapshots_count_as_the_rule():
    """Block values from FireSnapshots that a scheduler keeps (counted once, for the blocks of
    graph, then for every other block of another, then the first again) equal, bit for bit,
    those from plain (positions, cells) snapshots and the readable rule's count over them all."""
    graphs = episode_graphs(24, (0, 200, 400, 600))
    snaps = [(g.task_pos[g.fire_tasks], g.task_cells[g.fire_tasks]) for g in graphs[:-1]]
    kept = [objective.FireSnapshot(*s) for s in snaps]
    p = MilpParams()
    for g, step in ((graphs[-1], 1), (graphs[1], 2), (graphs[-1], 1)):
        blocks = np.flatnonzero(g.task_kind == TaskKind.SEARCH)[::step]
        plain = objective.hidden_cells(g, p, blocks, snaps)
        assert objective.hidden_cells(g, p, blocks, kept).tobytes() == plain.tobytes()
        current = (g.task_pos[g.fire_tasks], g.task_cells[g.fire_tasks])
        near = objective.near_known_cells(g.task_pos[blocks], [current, *snaps], 150.0)
        age = np.minimum(g.task_staleness[blocks], p.search_age_cap_s)
        scale = objective.AGE_UNIT_S * (age / objective.AGE_UNIT_S) ** p.search_age_exponent
        rule = p.search_weight * scale * (1.0 + np.minimum(near, 50.0) / 10.0)
        assert plain.tobytes() == rule.tobytes()
