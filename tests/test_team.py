"""Tests for fcplan.team: field of view, sensing curve, motion, battery, tank, depot rules."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.scenario import load_scenario
from fcplan.team import Command, Mode, Team, fov_half_extent, sensing_confidence
from tests.conftest import scenario_with


@pytest.mark.parametrize(
    ("z", "width", "height"),
    [(10, 20.0, 11.5), (20, 40.0, 23.1), (100, 200.0, 115.5), (30, 60.0, 34.6)],
)
def test_fov_size_matches_reference_table(z, width, height):
    """The field of view is 2z wide and 1.1547z high (spec 4.2 examples)."""
    hx, hy = fov_half_extent(float(z))
    assert 2 * hx == pytest.approx(width, abs=0.05)
    assert 2 * hy == pytest.approx(height, abs=0.05)


def test_sensing_curve_is_linear_from_100_to_40_percent():
    """Sensing confidence is 100% at the lowest altitude, 40% at the highest, linear between."""
    z = np.linspace(10, 100, 10)
    c = sensing_confidence(z, 10.0, 100.0)
    assert c[0] == pytest.approx(1.0) and c[-1] == pytest.approx(0.4)
    np.testing.assert_allclose(np.diff(c), -0.6 / 9)
    assert sensing_confidence(20.0, 10.0, 100.0) == pytest.approx(1 - 0.6 / 9)
    assert sensing_confidence(30.0, 30.0, 30.0) == 1.0


def test_agents_start_on_depot_slots_idle_and_full():
    """Agents start at their depot slots, idle, full battery and tank, at the start altitude."""
    sc = load_scenario(12)
    team = Team(sc)
    assert team.ids == ("P1", "P2", "P3", "A1", "A2")
    np.testing.assert_array_equal(team.pos[0], [60, 420])
    assert (team.mode == Mode.IDLE).all()
    np.testing.assert_array_equal(team.battery, 500)
    np.testing.assert_array_equal(team.tank, [0, 0, 0, 10, 10])
    np.testing.assert_array_equal(team.z, [20, 20, 20, 30, 30])


def test_speed_is_px_per_tick_at_10hz_and_rescales():
    """An agent flies 20 px per tick at 10 Hz and 10 px per tick at 20 Hz (same px per second)."""
    for tps, step in ((10, 20.0), (20, 10.0)):
        team = Team(scenario_with(1, ticks_per_second=tps))
        start = team.pos[0].copy()
        team.apply({"P1": Command(route=((600.0, 420.0),))})
        team.move()
        assert team.pos[0, 0] - start[0] == pytest.approx(step)


def test_route_goals_are_visited_in_order_and_patrol_repeats():
    """Goals are reached in order; a patrol loop keeps cycling through them."""
    team = Team(load_scenario(1))
    route = ((300.0, 420.0), (300.0, 600.0))
    team.apply({"P1": Command(route=route, patrol=True)})
    visits = []
    for _ in range(200):
        arrived = team.move()
        if 0 in arrived:
            visits.append(tuple(team.pos[0]))
    assert visits[:4] == [route[0], route[1], route[0], route[1]]
    assert team.mode[0] == Mode.ACTIVE


def test_action_agent_goes_home_after_three_seconds_idle():
    """An action agent hovering 3 s at its last goal flies home and idles there."""
    team = Team(load_scenario(1))
    a = team.index("A1")
    team.apply({"A1": Command(route=((200.0, 600.0),))})
    ticks_at_goal = None
    for t in range(200):
        arrived = team.move()
        if a in arrived:
            ticks_at_goal = t
        if team.mode[a] == Mode.HOMING:
            break
    assert ticks_at_goal is not None
    assert t - ticks_at_goal == 30  # 3 s at 10 Hz
    for _ in range(100):
        team.move()
    assert team.mode[a] == Mode.IDLE and team.at_home[a]


def test_perception_agent_hovers_until_battery_sends_it_home_then_resumes():
    """A hovering perception agent drains 0.05/tick; low battery forces it home, it recharges
    and resumes its route."""
    team = Team(scenario_with(1, **{"team.perception.battery": 200}))
    goal = (700.0, 420.0)
    team.apply({"P1": Command(route=(goal, (700.0, 500.0)))})
    seen_return = False
    for _ in range(20000):
        team.move()
        assert team.battery[0] >= 0
        if team.mode[0] == Mode.RETURNING:
            seen_return = True
        if seen_return and team.sorties[0] == 1:
            break
    assert seen_return and team.sorties[0] == 1
    assert team.battery[0] == 200 and team.mode[0] == Mode.ACTIVE
    # it resumes the goal it had not reached yet
    assert tuple(team.goal[0]) in {goal, (700.0, 500.0)}


def test_empty_tank_sends_action_agent_home_to_refill_and_resume():
    """Tank T gives T dumps; the last one sends the agent home, where it refills and resumes."""
    team = Team(scenario_with(1, **{"team.action.tank": 2}))
    a = team.index("A1")
    team.apply({"A1": Command(route=((400.0, 600.0), (500.0, 600.0), (600.0, 600.0)))})
    team.record_dump(a)
    assert team.tank[a] == 1 and team.mode[a] == Mode.ACTIVE
    team.record_dump(a)
    assert team.tank[a] == 0 and team.mode[a] == Mode.RETURNING
    for _ in range(200):
        team.move()
        if team.sorties[a]:
            break
    assert team.tank[a] == 2 and team.mode[a] == Mode.ACTIVE


def test_home_command_idles_at_the_depot():
    """A home command sends the agent back; it idles there with its route cleared."""
    team = Team(load_scenario(1))
    team.apply({"P1": Command(route=((800.0, 800.0),))})
    for _ in range(10):
        team.move()
    team.apply({"P1": Command(home=True)})
    for _ in range(100):
        team.move()
    assert team.mode[0] == Mode.IDLE and team.at_home[0] and len(team.routes[0]) == 0


def test_altitude_moves_toward_target_within_bounds():
    """Perception altitude climbs 5 m per tick toward the target, clipped to its bounds;
    action agents stay at 30 m."""
    team = Team(load_scenario(1))
    team.apply({"P1": Command(altitude=500.0), "A1": Command(altitude=80.0)})
    team.move()
    assert team.z[0] == 25.0
    for _ in range(40):
        team.move()
    assert team.z[0] == 100.0 and team.z[team.index("A1")] == 30.0


def test_unknown_agent_in_command_is_a_plan_error():
    """A command for an unknown agent raises PlanError naming the known agents."""
    from fcplan.errors import PlanError

    team = Team(load_scenario(1))
    with pytest.raises(PlanError, match="P1, P2, A1, A2"):
        team.apply({"Z9": Command(home=True)})


points = st.tuples(st.floats(0, 1199), st.floats(0, 1199))
commands = st.one_of(
    st.builds(
        Command,
        route=st.lists(points, max_size=4).map(tuple),
        patrol=st.booleans(),
        altitude=st.one_of(st.none(), st.floats(0, 150)),
    ),
    st.just(Command(home=True)),
    st.none(),
)


@settings(max_examples=40, deadline=None)
@given(
    script=st.lists(st.tuples(st.integers(0, 3), commands, st.booleans()), min_size=1, max_size=25),
    battery=st.sampled_from([200.0, 350.0, 500.0]),
    tank=st.integers(1, 4),
)
def test_battery_and_tank_never_negative_and_agents_recover(script, battery, tank):
    """Under any command sequence battery and tank stay in [0, capacity], agents forced home
    dock and get full battery and tank, and no agent is lost."""
    team = Team(
        scenario_with(
            1,
            **{
                "team.perception.battery": battery,
                "team.action.battery": battery,
                "team.action.tank": tank,
            },
        )
    )
    for agent, cmd, dump in script:
        if cmd is not None:
            team.apply({agent: cmd})
        if dump and team.can_act[agent] and team.tank[agent] > 0:
            team.record_dump(agent)
        for _ in range(60):
            before = team.sorties.copy()
            team.move()
            assert (team.battery >= 0).all() and (team.battery <= battery).all()
            assert (team.tank >= 0).all() and (team.tank <= tank).all()
            docked = team.sorties > before
            assert (team.battery[docked] == battery).all()
            assert (team.tank[docked] == team.tank_capacity[docked]).all()
            assert np.isfinite(team.pos).all()
    # everyone eventually gets home when told to
    team.apply({i: Command(home=True) for i in range(team.n)})
    for _ in range(2000):
        team.move()
    assert team.at_home.all() and (team.mode == Mode.IDLE).all()
