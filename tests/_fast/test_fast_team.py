"""Equivalence tests of fcplan._fast.team: the small-team kernels on Python numbers leave every
state array of :class:`fcplan.team.Team` bit for bit as the numpy rules do (``Team._move_vector``,
``Team._rules``, ``Team.fov_rects``, ``Team.sensing_confidence``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan._fast.team import fov_rects_small, rules_small, sensing_confidence_of
from fcplan.scenario import load_scenario
from fcplan.team import DRAIN_PER_PX, FOV_TAN_X, FOV_TAN_Y, SMALL_TEAM, Command, Mode, Team
from tests._fast.bits import bits as _bits

_STATE = ("pos", "z", "z_target", "battery", "tank", "mode", "goal", "has_goal", "armed",
          "hover_s", "distance", "dumps", "sorties", "goal_index", "patrol")  # fmt: skip


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


_float = st.floats(-50.0, 1250.0, allow_nan=False, allow_infinity=False)
_signed = st.one_of(st.sampled_from([0.0, -0.0, 1.0, -1.0]), _float)


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_rules_kernel_is_the_vector_rule_on_random_team_states(scenario, data):
    """rules_small (via Team._rules on a small team) sends home and idles exactly the agents the
    numpy rule does, for random modes, positions, hover clocks around the 3-second limit and
    batteries around, at and far from the reserve ``0.1 |home - p| + 0.2 v + 0.1``."""
    small, vector = Team(scenario), Team(scenario)
    vector._small = False
    n = small.n
    mode = data.draw(st.lists(st.sampled_from(list(Mode)), min_size=n, max_size=n))
    pos = data.draw(st.lists(st.tuples(_float, _float), min_size=n, max_size=n))
    hover = data.draw(
        st.lists(
            st.one_of(st.sampled_from([0.0, 3.0 - 1e-9, 3.0, 2.9999999]), st.floats(0.0, 10.0)),
            min_size=n,
            max_size=n,
        )
    )
    scale = data.draw(
        st.lists(
            st.one_of(st.just(1.0), st.floats(0.5, 1.5), st.sampled_from([0.0, 1.0 + 1e-12])),
            min_size=n,
            max_size=n,
        )
    )
    for team in (small, vector):
        team.mode[:] = mode
        team.pos[:] = pos
        team.hover_s[:] = hover
        team.has_goal[:] = True
        team.battery[:] = (team.return_cost() + team._speed_margin + team._hover_margin) * scale
    small._rules(), vector._rules()
    assert _bits(small.mode) == _bits(vector.mode)
    assert _bits(small.has_goal) == _bits(vector.has_goal)


@settings(max_examples=200, deadline=None)
@given(data=st.data())
def test_rules_kernel_reads_given_lists_as_the_team_arrays(scenario, data):
    """rules_small called with the lists Team._rules would pass (or without batteries or hover
    clocks, None) gives the modes of the numpy rule."""
    small, vector = Team(scenario), Team(scenario)
    vector._small = False
    n = small.n
    batteries = data.draw(st.lists(st.floats(0.0, 600.0), min_size=n, max_size=n))
    pos = data.draw(st.lists(st.tuples(_float, _float), min_size=n, max_size=n))
    for team in (small, vector):
        team.mode[:] = Mode.ACTIVE
        team.pos[:] = pos
        team.battery[:] = batteries
    rows = list(range(n))
    rules_small(small, rows, small.mode.tolist(), small.pos.ravel().tolist(), None, None)
    vector._rules()
    assert _bits(small.mode) == _bits(vector.mode)


@settings(max_examples=200, deadline=None)
@given(
    pos=st.lists(st.tuples(_signed, _signed), min_size=4, max_size=4),
    z=st.lists(
        st.one_of(st.sampled_from([0.0, -0.0, 30.0]), st.floats(0.0, 150.0)), min_size=4, max_size=4
    ),
)
def test_fov_rectangles_kernel_is_the_vector_rule(scenario, pos, z):
    """fov_rects_small gives the floats of Team.fov_rects (``x + z (-t)`` per bound), signed
    zeros included."""
    team = Team(scenario)
    assert team.n == 4
    team.pos[:] = pos
    team.z[:] = z
    assert _bits(np.array(fov_rects_small(team), dtype=np.float64)) == _bits(team.fov_rects())


@settings(max_examples=200, deadline=None)
@given(
    z=st.lists(
        st.one_of(st.sampled_from([math.nan, -0.0, 10.0, 100.0]), st.floats(-20.0, 200.0)),
        min_size=4,
        max_size=4,
    )
)
def test_sensing_confidence_kernel_is_the_vector_rule(scenario, z):
    """sensing_confidence_of(team, i) is Team.sensing_confidence()[i] bit for bit, for any
    altitude (below, inside and above the bounds, NaN), for agents that sense (clipped to
    0.4..1) and those that do not (0)."""
    team = Team(scenario)
    team.z[:] = z
    rule = team.sensing_confidence()
    for i in range(team.n):
        assert _bits(np.float64(sensing_confidence_of(team, i))) == _bits(rule[i])


def test_rule_constants_the_kernels_read_are_the_rules():
    """The constants the kernels read from the team class are the rules' own (mode codes,
    battery drain per px, the 3-second limit, the FOV scale) and SMALL_TEAM picks the kernels."""
    assert Team._modes == tuple(int(m) for m in Mode)
    assert Team._drain_per_px == DRAIN_PER_PX
    assert Team._idle_limit == float(np.float64(3.0 - 1e-9))
    assert Team._fov_scale_list == [-FOV_TAN_X, FOV_TAN_X, -FOV_TAN_Y, FOV_TAN_Y]
    team = Team(load_scenario(1))
    assert team._small == (0 < team.n <= SMALL_TEAM)
