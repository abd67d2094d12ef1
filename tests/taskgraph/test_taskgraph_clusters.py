"""Tests for fcplan.taskgraph.clusters: connected-fire labels equal scipy's."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.taskgraph.clusters import EIGHT_CONNECTED, TileClusters, label_tiles


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    nx=st.integers(2, 30),
    ny=st.integers(2, 30),
    most=st.sampled_from([40, 200, 400]),
)
def test_fire_clusters_match_scipy_label_also_when_repeated(seed, nx, ny, most):
    """Up to a few dozen tiles (the closure path), up to 256 (the numpy labelling) and beyond
    (scipy), cluster labels equal scipy.ndimage.label (8-connected, numbered by first tile in
    raster order), and asking a TileClusters again for the same tiles (its memo) gives the same
    labels."""
    from scipy.ndimage import label

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, min(nx * ny, most) + 1))
    flat = np.sort(rng.choice(nx * ny, size=n, replace=False))
    tx, ty = np.divmod(flat, ny)
    grid = np.zeros((nx + 1, ny + 1), dtype=bool)
    grid[tx, ty] = True
    labels, _ = label(grid, structure=EIGHT_CONNECTED)
    want = labels[tx, ty].astype(np.int64) - 1
    assert np.array_equal(label_tiles(tx, ty, nx, ny), want)
    clusters = TileClusters()
    assert np.array_equal(clusters(tx, ty, nx, ny), want)
    assert np.array_equal(clusters(tx.copy(), ty.copy(), nx, ny), want)


def test_tile_clusters_keeps_its_last_answers():
    """A TileClusters keeps at most ``size`` answers, read-only, and drops the oldest first."""
    clusters = TileClusters(size=2)
    tiles = [(np.array([0, k + 2]), np.array([0, 0])) for k in range(3)]
    first = clusters(*tiles[0], 8, 8)
    assert not first.flags.writeable
    assert clusters(*tiles[0], 8, 8) is first
    clusters(*tiles[1], 8, 8)
    clusters(*tiles[2], 8, 8)
    assert clusters(*tiles[0], 8, 8) is not first  # dropped, labelled again
