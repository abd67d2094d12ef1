"""Equivalence tests of fcplan._fast.world and the world's tuned scans: the StepInfo builder gives
the dataclass's own instance, the field-of-view scan box is the one of the plain two-step
computation, and the world's box cells (from a grid of offsets) are the flat indices of the mask's
``nonzero``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan._fast.world import step_info_builder
from fcplan.fire import BLOCK
from fcplan.scenario import load_scenario
from fcplan.world import StepInfo, World, _scan_box, _step_info


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(1)


def _cell_range_ref(rect, w):
    """Reference (the code _scan_box replaced): cell range covered by ``rect``, or None."""
    x0 = max(math.ceil(rect[0]), 0)
    x1 = min(math.floor(rect[1]), w - 1)
    y0 = max(math.ceil(rect[2]), 0)
    y1 = min(math.floor(rect[3]), w - 1)
    if x1 < x0 or y1 < y0:
        return None
    return x0, x1 + 1, y0, y1 + 1


def _burning_box_ref(blocks, x0, x1, y0, y1):
    """Reference: the part of the range ``[x0, x1) x [y0, y1)`` holding burning blocks."""
    i0, j0 = x0 // BLOCK, y0 // BLOCK
    b = blocks[i0 : (x1 - 1) // BLOCK + 1, j0 : (y1 - 1) // BLOCK + 1]
    if not np.count_nonzero(b):
        return None
    bi, bj = np.nonzero(b)
    return (
        max(x0, (i0 + int(bi[0])) * BLOCK),
        min(x1, (i0 + int(bi[-1]) + 1) * BLOCK),
        max(y0, (j0 + int(bj.min())) * BLOCK),
        min(y1, (j0 + int(bj.max()) + 1) * BLOCK),
    )


_edge = st.one_of(
    st.sampled_from([-1.0, -0.0, 0.0, 0.5, 15.0, 15.5, 16.0, 16.5, 31.0, 32.0, 99.0, 100.0]),
    st.floats(-30.0, 130.0, allow_nan=False, allow_infinity=False),
)


@settings(max_examples=500, deadline=None)
@given(
    rect=st.lists(_edge, min_size=4, max_size=4),
    w=st.sampled_from([1, 16, 17, 40, 100]),
    seed=st.integers(0, 2**32 - 1),
    density=st.sampled_from([0.0, 0.05, 0.3, 1.0]),
)
def test_scan_box_is_the_burning_box_of_the_cell_range(rect, w, seed, density):
    """_scan_box(rect, blocks, w) equals _burning_box(blocks, *_cell_range(rect, w)) (None when
    either is None) for any rectangle (inverted, outside the map, on block edges) and any
    pattern of burning blocks."""
    nblk = -(-w // BLOCK)
    blocks = (np.random.default_rng(seed).random((nblk, nblk)) < density).astype(np.int32)
    sl = _cell_range_ref(rect, w)
    expected = None if sl is None else _burning_box_ref(blocks, *sl)
    assert _scan_box(rect, blocks, w) == expected


def test_step_info_builder_gives_the_dataclass_instance(scenario):
    """The StepInfo that World.step builds through its descriptor fast path has exactly the
    fields (same objects) of StepInfo(...) built by the dataclass's __init__, and stays frozen."""
    world = World().reset(scenario, seed=1)
    for _ in range(30):
        world.step()
    values = (7, 0.7, np.arange(3), np.arange(2), np.arange(1), np.arange(0), [[0.0] * 4], (1,), ())
    fast, slow = _step_info(*values), StepInfo(*values)
    assert type(fast) is StepInfo
    names = [f.name for f in dataclasses.fields(StepInfo)]
    assert len(names) == len(values)
    for name, v in zip(names, values, strict=True):
        assert getattr(fast, name) is v and getattr(slow, name) is v
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.tick = 8  # type: ignore[misc]
    info = world.step()
    assert isinstance(info, StepInfo) and info.tick == 31 and info.fov.shape == (4, 4)


@settings(max_examples=200, deadline=None)
@given(
    shapes=st.lists(st.tuples(st.integers(1, 40), st.integers(1, 40)), min_size=1, max_size=6),
    seed=st.integers(0, 2**32 - 1),
    density=st.sampled_from([0.0, 0.02, 0.3, 1.0]),
)
def test_box_cells_are_the_flat_indices_of_the_masks_nonzero(scenario, shapes, seed, density):
    """World._cells(mask, x0, y0) is ``(x0 + i) W + (y0 + j)`` over ``mask.nonzero()`` (same
    values, same order, int64) for boxes of any shape in any order (the offset grid grows and is
    then sliced), and the cached offsets are never changed by a call."""
    world = World().reset(scenario, seed=0)
    w = world.world_size
    rng = np.random.default_rng(seed)
    for h, bw in shapes:
        mask = rng.random((h, bw)) < density
        x0, y0 = int(rng.integers(0, w - h + 1)), int(rng.integers(0, w - bw + 1))
        before = world._box_offsets.copy()
        got = world._cells(mask, x0, y0)
        i, j = mask.nonzero()
        assert got.dtype == np.int64
        np.testing.assert_array_equal(got, (x0 + i) * w + (y0 + j))
        off = world._box_offsets
        np.testing.assert_array_equal(off[: before.shape[0], : before.shape[1]], before)
        np.testing.assert_array_equal(
            off, np.add.outer(np.arange(off.shape[0]) * w, np.arange(off.shape[1]))
        )


def test_step_info_builder_refuses_other_dataclasses():
    """step_info_builder checks its class has StepInfo's nine fields and no __post_init__."""

    @dataclasses.dataclass(frozen=True, slots=True)
    class Two:
        a: int
        b: int

    with pytest.raises(TypeError, match="StepInfo-like"):
        step_info_builder(Two)
