"""Tests for the speed paths of fcplan.team, fcplan.fire and fcplan.world: the small-team Python
path of ``Team.move`` gives bit-identical states to the numpy path, the fire's ``burn_box`` always
holds every burning cell, queued front visits add up to the same grid, the world's field-of-view
scan box is the one of the plain two-step computation, its box cells (from a grid of offsets)
are the flat indices of the mask's ``nonzero``, and ``World.step``'s StepInfo builder gives the
dataclass's own instance."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.fire import BLOCK, BURNING
from fcplan.scenario import load_scenario
from fcplan.team import SMALL_TEAM, Command, Team
from fcplan.world import StepInfo, World, _scan_box, _step_info

_STATE = ("pos", "z", "z_target", "battery", "tank", "mode", "goal", "has_goal", "armed",
          "hover_s", "distance", "dumps", "sorties", "goal_index", "patrol")  # fmt: skip


def _bits(a) -> bytes:
    """Exact bytes of an array (so -0.0 and 0.0 differ)."""
    a = np.asarray(a)
    return a.dtype.str.encode() + str(a.shape).encode() + np.ascontiguousarray(a).tobytes()


_coord = st.one_of(
    st.sampled_from([0.0, 1.0, 60.0, 599.5, 1199.0]),
    st.floats(-50.0, 1250.0, allow_nan=False, allow_infinity=False),
)
_command = st.one_of(
    st.builds(
        Command,
        route=st.lists(st.tuples(_coord, _coord), min_size=0, max_size=3).map(tuple),
        patrol=st.booleans(),
        altitude=st.one_of(st.none(), st.floats(0.0, 150.0)),
    ),
    st.builds(Command, home=st.just(True)),
    st.builds(Command, altitude=st.floats(0.0, 150.0)),
)
# per tick: maybe a command for one agent row, maybe a dump by one row, maybe a battery cut
_tick = st.tuples(
    st.one_of(st.none(), st.tuples(st.integers(0, 15), _command)),
    st.one_of(st.none(), st.integers(0, 15)),
    st.one_of(st.none(), st.tuples(st.integers(0, 15), st.floats(0.0, 1.0))),
)


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(1)


@settings(max_examples=200, deadline=None)
@given(ticks=st.lists(_tick, min_size=1, max_size=60), moves=st.integers(0, 40))
def test_small_team_path_is_bit_identical_to_the_vector_path(scenario, ticks, moves):
    """Team.move on Python floats (teams <= SMALL_TEAM) and on numpy leave every state array
    bit for bit equal, through routes (diagonal, axis-aligned, on the map edge), patrols, altitude
    changes, going home, dumps, docking and forced returns on a low battery."""
    small, vector = Team(scenario), Team(scenario)
    assert small._small and small.n <= SMALL_TEAM
    vector._small = False
    for cmd, dump, cut in ticks:
        for team in (small, vector):
            if cmd is not None:
                i = cmd[0] % team.n
                team.apply({i: cmd[1]})
            if dump is not None and team.tank[dump % team.n] > 0:
                team.record_dump(dump % team.n)
            if cut is not None:
                i = cut[0] % team.n
                team.battery[i] = team.battery_capacity[i] * cut[1]
        for _ in range(1 + moves // 10):
            a, b = small.move(), vector.move()
            assert a.tolist() == b.tolist()
            for name in _STATE:
                assert _bits(getattr(small, name)) == _bits(getattr(vector, name)), name
            assert small.routes[0].tolist() == vector.routes[0].tolist()
            rects = small.fov_rects_list()
            assert _bits(np.array(rects, dtype=np.float64)) == _bits(vector.fov_rects())
            assert rects == vector.fov_rects_list()


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


@pytest.mark.parametrize("zero", [0.0, -0.0])
@pytest.mark.parametrize("goal", [(-3.0, 5.0), (0.0, -0.0), (7.0, -2.0)])
@pytest.mark.parametrize("mode", ["idle", "hover", "fly"])
def test_small_team_path_keeps_the_vector_paths_signed_zeros(scenario, zero, goal, mode):
    """Agents that do not fly are skipped by the small path except for zero coordinates: a
    ``-0.0`` or ``+0.0`` coordinate of an idle, hovering or flying agent (goal signs either way)
    ends the tick with the vector path's exact bits, positions, batteries, distances and clocks."""
    small, vector = Team(scenario), Team(scenario)
    vector._small = False
    for team in (small, vector):
        team.pos[0] = (zero, 40.0)
        team.pos[1] = (40.0, zero)
        team.goal[0] = team.goal[1] = goal
        if mode != "idle":
            team.mode[:2] = 1  # ACTIVE
            team.has_goal[:2] = mode == "fly"
    for _ in range(3):
        a, b = small.move(), vector.move()
        assert a.tolist() == b.tolist()
        for name in _STATE:
            assert _bits(getattr(small, name)) == _bits(getattr(vector, name)), name


@pytest.mark.parametrize("z", [0.0, -0.0, 30.0])
@pytest.mark.parametrize("target", [0.0, -0.0, 30.0, math.nan])
def test_small_team_path_steps_altitudes_as_the_vector_path(scenario, z, target):
    """The small path steps only the altitudes off their target (and zero ones): while one agent
    climbs, any altitude of the others (zeros of either sign) and target (equal, zero, NaN) ends
    the tick with the vector path's exact bits, for agents that can sense and those that cannot."""
    small, vector = Team(scenario), Team(scenario)
    vector._small = False
    for team in (small, vector):
        team.z[:] = z
        team.z_target[:] = target
        team.z_target[0] = 50.0  # (one agent climbs, so the others take the altitude step too)
    for _ in range(2):
        small.move(), vector.move()
        assert _bits(small.z) == _bits(vector.z)
