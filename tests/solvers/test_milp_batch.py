"""Tests for solvers.milp_model.batch and its kernels: the build across agents gives the
per-agent build's model bit for bit; each kernel equals its readable rule."""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.taskgraph import synthetic_task_graph
from solvers.milp_model import MilpParams, build_milp_model
from solvers.milp_model.batch import _smallest, _top
from solvers.milp_model.kernels import box_pairs, discounted_pairs
from solvers.milp_model.routes import top_candidates
from solvers.milp_model.sensing import discounted_share
from tests.solvers.graphs import episode_graphs

_FIELDS = ("c", "b_ub", "ub", "var_kind", "var_ref", "route_agent", "route_kind", "route_tasks",
           "route_arrival", "route_length", "route_value", "altitude")  # fmt: skip


def _assert_same_model(a, b) -> None:
    """Every array of two models equal byte for byte, dtypes included, and the same rows."""
    for name in _FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype, name
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), name
    assert np.array_equal(np.asarray(a.row_kind), np.asarray(b.row_kind))
    assert a.A_ub.shape == b.A_ub.shape and (a.A_ub != b.A_ub).nnz == 0
    assert a.A_ub.indices.dtype == b.A_ub.indices.dtype
    assert a.size == b.size


@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
def test_episode_models_equal_the_per_agent_build(name):
    """On real episodes' graphs (fires found and fought, agents on forced returns, hybrid
    agents in the open world) the build across agents equals the per-agent build."""
    for g in episode_graphs(name, (0, 200, 600, 1200)):
        _assert_same_model(build_milp_model(g), build_milp_model(g, batched=False))


@pytest.mark.parametrize(
    "params",
    [
        MilpParams(),
        MilpParams(slots=1, search_slots=1),
        MilpParams(slots=3, search_slots=2, fire_candidates=4, search_candidates=3),
        MilpParams(search_candidates=5, watch_candidates=2, growth_cells_s=0.0),
    ],
    ids=["defaults", "one-slot", "three-slots", "few-candidates"],
)
def test_synthetic_models_equal_the_per_agent_build(params):
    """On synthetic graphs of 2-30 agents and 6-300 tasks, under several model settings and
    with the scored ends thinned (``max_scored_ends=16``, so that the nearest-and-best
    selection runs), both builds give the same model, with and without pruning."""
    params = params.replace(max_scored_ends=16)
    for a, k, seed in ((2, 6, 0), (6, 30, 1), (12, 80, 2), (30, 300, 3)):
        g = synthetic_task_graph(a, k, np.random.default_rng(seed))
        for prune in (True, False):
            fast = build_milp_model(g, params, prune=prune)
            _assert_same_model(fast, build_milp_model(g, params, prune=prune, batched=False))


def test_a_passed_deadline_stops_the_build():
    """With a deadline already past, the build across agents raises TimeoutError."""
    g = synthetic_task_graph(6, 30, np.random.default_rng(0))
    with pytest.raises(TimeoutError, match="wall-clock limit"):
        build_milp_model(g, deadline=time.perf_counter() - 1.0)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_seg=st.integers(0, 30),
    n_blocks=st.integers(0, 60),
    block=st.floats(20.0, 200.0),
    spread=st.floats(0.0, 2000.0),
    still=st.floats(0.0, 1.0),
    grid=st.booleans(),
)
def test_discounted_pairs_equal_the_rule(seed, n_seg, n_blocks, block, spread, still, grid):
    """Each segment's pairs carry exactly (bit for bit) the value the readable
    discounted_share gives that segment with its own altitude, bounds and speed; every block
    left out is one the rule values +0.0 or one outside the segment's radius; blocks on a grid
    or anywhere."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 3000.0, (n_seg, 2))
    q = p + rng.normal(0.0, spread + 1e-3, (n_seg, 2))
    q = np.where(rng.random((n_seg, 1)) < still, p, q)
    if grid:
        side = int(np.ceil(np.sqrt(max(n_blocks, 1))))
        cells = np.argwhere(np.ones((side, side)))[:n_blocks]
        centres = (cells + 0.5) * block * rng.uniform(0.9, 1.1)
    else:
        centres = rng.uniform(-200.0, 3200.0, (n_blocks, 2))
    z = rng.uniform(10.0, 120.0, n_seg)
    lo = rng.uniform(5.0, 60.0, n_seg)
    hi = np.where(rng.random(n_seg) < 0.2, lo, lo + rng.uniform(0.0, 80.0, n_seg))
    speed = rng.uniform(5.0, 300.0, n_seg)
    t_start = rng.uniform(0.0, 80.0, n_seg)
    origin = p + rng.normal(0.0, 300.0, (n_seg, 2))
    radius = rng.uniform(0.0, 4000.0, n_seg)
    si, bi, val = discounted_pairs(
        p, q, z, lo, hi, speed, t_start, centres, block, 60.0, origin, radius
    )
    got = np.zeros((n_seg, n_blocks))
    got[si, bi] = val
    assert len(set(zip(si.tolist(), bi.tolist(), strict=True))) == si.size  # each pair once
    for s in range(n_seg):
        rule = discounted_share(
            p[s : s + 1], q[s : s + 1], centres, block, float(z[s]), float(lo[s]), float(hi[s]),
            float(speed[s]), t_start[s : s + 1], 60.0,
        )[0]  # fmt: skip
        near = np.hypot(*(centres - origin[s]).T) <= radius[s]
        rule = np.where(near, rule, 0.0)
        assert got[s].tobytes() == rule.tobytes()


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_box=st.integers(0, 20),
    n_c=st.integers(0, 80),
    cell=st.floats(1.0, 300.0),
)
def test_box_pairs_finds_every_centre_in_each_box(seed, n_box, n_c, cell):
    """Every centre inside a closed box (edges included) is paired with it, once."""
    rng = np.random.default_rng(seed)
    centres = np.round(rng.uniform(-500.0, 2500.0, (n_c, 2)), 1)
    lo = rng.uniform(-800.0, 2500.0, (n_box, 2))
    hi = lo + rng.uniform(-50.0, 1200.0, (n_box, 2))
    if n_c and n_box:
        lo[0] = centres[0]  # a centre exactly on a box's corner
    si, bi = box_pairs(lo, hi, centres, cell)
    got = set(zip(si.tolist(), bi.tolist(), strict=True))
    assert len(got) == si.size
    inside = (centres[None] >= lo[:, None]) & (centres[None] <= hi[:, None])
    want = set(zip(*np.nonzero(inside.all(axis=2)), strict=True))
    assert {(int(s), int(b)) for s, b in want} <= got


def test_chunked_coverage_with_a_deadline_gives_the_same_model(monkeypatch):
    """With a far deadline the coverage kernel runs in chunks of segments (the clock read
    between them), and the model is the one built in one call."""
    from solvers.milp_model import batch

    g = synthetic_task_graph(12, 80, np.random.default_rng(2))
    whole = build_milp_model(g)
    monkeypatch.setattr(batch, "CHUNK_SEGMENTS", 7)
    _assert_same_model(build_milp_model(g, deadline=time.perf_counter() + 3600.0), whole)


@settings(max_examples=150, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    rows=st.integers(0, 6),
    cols=st.integers(0, 40),
    k=st.integers(0, 45),
    levels=st.integers(1, 6),
)
def test_smallest_and_top_equal_a_stable_sort(seed, rows, cols, k, levels):
    """The partition kernels pick, per row, the same set as the first ``k`` of a stable sort
    (ties, infinities and negative zeros included), and ``_top`` the same candidates in the same
    order as the readable rule ``top_candidates`` of each row."""
    rng = np.random.default_rng(seed)
    key = rng.integers(-levels, levels + 1, (rows, cols)).astype(np.float64)
    key[rng.random((rows, cols)) < 0.2] = np.inf
    key[key == 0] = rng.choice([0.0, -0.0], size=int((key == 0).sum()))
    want = np.zeros(key.shape, dtype=bool)
    want[np.arange(rows)[:, None], np.argsort(key, axis=1, kind="stable")[:, :k]] = True
    assert np.array_equal(_smallest(key, k), want)
    score = np.where(np.isfinite(key), -key, 0.0)
    allowed = rng.random((rows, cols)) < 0.8
    got = _top(score, allowed, k)
    assert len(got) == rows
    for r in range(rows):
        assert got[r].tolist() == top_candidates(score[r], allowed[r], k).tolist()
