"""Tests for fcplan.taskgraph.build_batch: the batched build is, world for world, the builder's
own graph (the specification)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.env.vector_task import VectorTaskEnv
from fcplan.scenario import load_scenario
from fcplan.taskgraph import TaskGraph, TaskGraphBuilder, TaskGraphParams
from fcplan.taskgraph.build_batch import _labels, build_graphs
from fcplan.taskgraph.clusters import label_tiles

_VIEWS = ("agent_task_distance", "task_home_distance", "can_do")


def _same_graph(a: TaskGraph, b: TaskGraph) -> None:
    """Every field and pre-filled view equal: values, dtypes, shapes, bits."""
    for f in dataclasses.fields(TaskGraph):
        u, v = getattr(a, f.name), getattr(b, f.name)
        if isinstance(v, np.ndarray):
            assert (u.dtype, u.shape, u.tobytes()) == (v.dtype, v.shape, v.tobytes()), f.name
        else:
            assert type(u) is type(v) and u == v, f.name
    assert {k for k in _VIEWS if k in a.__dict__} == {k for k in _VIEWS if k in b.__dict__}
    for k in _VIEWS:
        if k in b.__dict__:
            u, v = a.__dict__[k], b.__dict__[k]
            assert (u.dtype, u.shape, u.tobytes()) == (v.dtype, v.shape, v.tobytes()), k


@pytest.mark.parametrize(
    "name, params",
    [
        ("1", [None]),
        ("24", [None]),
        ("1", [TaskGraphParams(tile_px=(37.5, 41.0), search_block_px=60)]),
        ("24", [None, TaskGraphParams(tile_px=(30.0, 30.0)), None]),
    ],
)
def test_build_graphs_equal_per_world_builds(name, params):
    """Property: along episodes of the batched task env (worlds with and without known fire,
    whole-px and fractional tiles, other search blocks, builders of different parameters in
    one call), build_graphs gives each world the graph of its own builder: every field and
    distance table bit for bit, across replans (kept cluster labels and team constants)."""
    sc = load_scenario(name).replace(duration_s=90)
    n = 6
    env = VectorTaskEnv(sc, num_envs=n, k=5)
    obs, _ = env.reset(seed=11)
    pick = [params[i % len(params)] for i in range(n)]
    fast = [TaskGraphBuilder(sc, p) for p in pick]
    slow = [TaskGraphBuilder(sc, p) for p in pick]
    rng = np.random.default_rng(0)
    fires = 0
    for _ in range(9):
        m = obs["action_mask"]
        obs, *_ = env.step((rng.random(m.shape) * m).argmax(axis=2))
        beliefs = [env.belief.view(b, (p or TaskGraphParams()).search_block_px)
                   for b, p in enumerate(pick)]  # fmt: skip
        got = build_graphs(fast, env.teams, beliefs)
        for b in range(n):
            want = slow[b].build(env.teams[b], beliefs[b])
            _same_graph(got[b], want)
            fires += want.fire_tasks.size > 0
    assert fires > 0


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    worlds=st.integers(1, 5),
    nx=st.integers(1, 30),
    ny=st.integers(1, 30),
    most=st.integers(1, 400),
)
def test_stacked_labels_equal_label_tiles(seed, worlds, nx, ny, most):
    """Property: the stacked-grid labels of several worlds' tiles (raster order, 1 to a few
    hundred tiles each: every path of label_tiles, tiles on the grids' borders) equal
    label_tiles of each world's tiles."""
    rng = np.random.default_rng(seed)
    parts, want = [], []
    for _ in range(worlds):
        n = int(rng.integers(1, min(most, nx * ny) + 1))
        flat = np.sort(rng.choice(nx * ny, n, replace=False))
        tx, ty = np.divmod(flat, ny)
        parts.append((tx, ty))
        want.append(label_tiles(tx, ty, nx, ny))
    world = np.concatenate([np.full(len(p[0]), j) for j, p in enumerate(parts)])
    tx = np.concatenate([p[0] for p in parts])
    ty = np.concatenate([p[1] for p in parts])
    cuts = np.searchsorted(world, np.arange(worlds + 1))
    got = _labels(world, tx, ty, cuts, nx, ny)
    for j in range(worlds):
        np.testing.assert_array_equal(got[cuts[j] : cuts[j + 1]], want[j], strict=True)
