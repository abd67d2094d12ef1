"""Tests of fcplan.shared_views: a copied or unpickled object keeps its views of shared memory
views of the copied memory (flat views, slices, strided windows, views kept in lists, tuples
and dicts, views of one array kept by two objects of one copied tree), with their write flags;
a shallow copy views the original's memory; arrays that own their memory are copied as before."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.lib.stride_tricks import sliding_window_view

from fcplan.shared_views import KeepsViews, memory_owner


class _Maps(KeepsViews):
    """Views of every kind the simulator keeps."""

    def __init__(self) -> None:
        self.grid = np.arange(36, dtype=np.float32).reshape(6, 6)
        self.flat = self.grid.reshape(-1)
        self.inner = self.grid[1:-1, 1:-1]
        self.windows = sliding_window_view(self.grid, (3, 3))
        self.rows = [self.grid[0], self.grid[5]]
        self.pair = (self.grid[:, 0], 7)
        self.named = {"col": self.grid[:, 2], "own": np.ones(3)}
        self.orphan = np.zeros(10)[2:5]  # a view of an array nothing else keeps


class _Reader(KeepsViews):
    """Another object of the same tree viewing the first one's grid."""

    def __init__(self, maps: _Maps) -> None:
        self.maps = maps
        self.column = maps.grid[:, 3]


class _Slice(KeepsViews):
    """A grid and one strided slice of it."""

    def __init__(self, shape, start, step, transpose) -> None:
        self.grid = np.arange(shape[0] * shape[1] * 3, dtype=np.int64).reshape(shape[0], -1)
        v = self.grid[start[0] :: step[0], start[1] :: step[1]]
        self.view = v.T if transpose else v


def _deep(obj):
    return copy.deepcopy(obj)


def _pickled(obj):
    return pickle.loads(pickle.dumps(obj))


@pytest.mark.parametrize("clone", [_deep, _pickled], ids=["deepcopy", "pickle"])
def test_views_follow_the_copied_grid(clone):
    """A write through any view of the copy shows in the copy's grid and every other view of
    it, never in the original; values, shapes, dtypes and read-only flags are kept."""
    m = _Maps()
    c = clone(m)
    for name in ("flat", "inner", "windows", "orphan"):
        assert np.array_equal(getattr(c, name), getattr(m, name)), name
        assert getattr(c, name).dtype == getattr(m, name).dtype
    assert not c.windows.flags.writeable and c.flat.flags.writeable
    c.flat[7] = -1.0
    assert c.grid[1, 1] == -1.0 and c.inner[0, 0] == -1.0 and c.windows[0, 0, 1, 1] == -1.0
    c.rows[1][:] = -2.0
    assert (c.grid[5] == -2.0).all() and c.pair[0][5] == -2.0 and c.named["col"][5] == -2.0
    assert c.pair[1] == 7 and np.array_equal(c.named["own"], np.ones(3))
    assert m.grid[1, 1] == 7.0 and (m.grid[5] != -2.0).all()
    assert not np.shares_memory(c.grid, m.grid)


@pytest.mark.parametrize("clone", [_deep, _pickled], ids=["deepcopy", "pickle"])
def test_two_objects_share_one_copied_grid(clone):
    """Views of one array kept by two objects of a copied tree stay on one block of memory."""
    r = clone(_Reader(_Maps()))
    r.column[2] = 99.0
    assert r.maps.grid[2, 3] == 99.0 and r.maps.flat[15] == 99.0


def test_a_shallow_copy_views_the_original():
    """``copy.copy`` gives views of the same memory (a shallow copy's meaning)."""
    m = _Maps()
    c = copy.copy(m)
    c.flat[0] = 5.0
    assert m.grid[0, 0] == 5.0 and isinstance(c.flat, np.ndarray)


@given(
    shape=st.tuples(st.integers(1, 6), st.integers(1, 6)),
    start=st.tuples(st.integers(0, 5), st.integers(0, 5)),
    step=st.tuples(st.integers(-3, 3).filter(bool), st.integers(-3, 3).filter(bool)),
    transpose=st.booleans(),
)
def test_any_slice_is_rebuilt(shape, start, step, transpose):
    """Any strided slice (negative steps and transposes included) of a grid comes back as the
    same slice of the copied grid."""
    one = _Slice(shape, start, step, transpose)
    c = _pickled(one)
    assert np.array_equal(c.view, one.view)
    if c.view.size:
        c.view[...] = -1
        expect = one.grid.copy()
        sub = expect[start[0] :: step[0], start[1] :: step[1]]
        sub[...] = -1
        assert np.array_equal(c.grid, expect)


def test_memory_owner_follows_strided_windows():
    """The owner of a sliding window view is the array it slides over."""
    g = np.zeros((5, 5))
    assert memory_owner(sliding_window_view(g, (2, 2))) is g
    assert memory_owner(g.reshape(-1)[3:]) is g
