"""Tests of fcplan.batch.cells: the block layout maps every cell to its own byte, and
``scan_boxes`` finds exactly the cells a dense scan of each box finds, in ``[x, y]`` order."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.batch.cells import STATE_BITS, CellGrid, scan_boxes


def test_layout_is_a_bijection():
    """``index`` sends the W x W cells of every world to distinct bytes, and ``world_array``
    reads them back in the ``[x, y]`` layout."""
    grid = CellGrid(2, 37)
    x, y = np.meshgrid(np.arange(37), np.arange(37), indexing="ij")
    for b in range(2):
        g = grid.index(np.full(x.size, b), x.reshape(-1), y.reshape(-1))
        assert np.unique(g).size == 37 * 37
        grid.flat_state[g] = (np.arange(x.size) % 200).astype(np.uint8)
        assert np.array_equal(grid.world_array(b).reshape(-1), np.arange(x.size) % 200)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), density=st.floats(0.0, 0.3))
def test_scan_equals_a_dense_scan(seed, density):
    """Random grids and boxes: the burning cells found per box are those of the dense array,
    box by box in row-major order."""
    rng = np.random.default_rng(seed)
    w, num = 150, 3
    grid = CellGrid(num, w)
    dense = (rng.random((num, w, w)) < density).astype(np.uint8)
    for b in range(num):
        x, y = np.nonzero(dense[b])
        wb = np.full(x.size, b)
        grid.flat_state[grid.index(wb, x, y)] = 1
        grid.count(wb, x, y, +1)
    p = 6
    world = rng.integers(0, num, p)
    a, c = np.sort(rng.integers(0, w, (2, p)), axis=0), np.sort(rng.integers(0, w, (2, p)), axis=0)
    pair, px, py = scan_boxes(grid, world, a[0], a[1], c[0], c[1], lambda v: (v & STATE_BITS) == 1)
    for j in range(p):
        sub = dense[world[j], a[0, j] : a[1, j] + 1, c[0, j] : c[1, j] + 1]
        ex, ey = np.nonzero(sub)
        assert np.array_equal(px[pair == j], ex + a[0, j])
        assert np.array_equal(py[pair == j], ey + c[0, j])
