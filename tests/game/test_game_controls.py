"""The manual's controls (fcplan.game.controls): selection, goals, patrol loops, altitude, home."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.game.controls import ALTITUDE_STEP, Controller, InputError
from fcplan.game.session import GameSession, replay_inputs
from fcplan.team import Mode


@pytest.fixture
def world():
    return World().reset(load_scenario("practice"), seed=0)


def click(ctl, x, y):
    ctl.handle({"type": "click", "map": [x, y]})


def key(ctl, k):
    ctl.handle({"type": "key", "key": k})


def test_keys_select_agents_and_ignore_missing_ones(world):
    """Keys 1-9 select the agent of that rank; a key beyond the team keeps the selection."""
    ctl = Controller(world)
    key(ctl, "3")
    assert ctl.selected == 2 and "A1" in ctl.message
    key(ctl, "9")
    assert ctl.selected == 2 and "no agent 9" in ctl.message


def test_clicks_append_goals_to_the_selected_agents_route(world):
    """Each click adds a goal at the end of the selected agent's route, also after a step."""
    ctl = Controller(world)
    key(ctl, "1")
    click(ctl, 400, 300)
    world.step(ctl.take_commands())
    click(ctl, 700, 300)
    cmd = ctl.pending["P1"]
    assert cmd.route == ((400.0, 300.0), (700.0, 300.0)) and not cmd.patrol


def test_click_near_first_goal_closes_a_patrol_loop(world):
    """A click within 5 steps (100 px) of the first goal closes a loop over the goals so far."""
    ctl = Controller(world)
    for x, y in [(300, 300), (600, 300), (600, 600), (350, 330)]:
        click(ctl, x, y)
    cmd = ctl.pending["P1"]
    assert cmd.patrol and cmd.route == ((300.0, 300.0), (600.0, 300.0), (600.0, 600.0))
    world.step(ctl.take_commands())
    assert world.team.patrol[0]
    click(ctl, 900, 900)  # a later click replaces the loop
    assert ctl.pending["P1"].route == ((900.0, 900.0),) and not ctl.pending["P1"].patrol


def test_patrol_needs_two_goals_and_keeps_the_current_goal_first(world):
    """With a single goal a nearby click is a goal; a loop closed en route starts at the goal
    the agent is flying to."""
    ctl = Controller(world)
    click(ctl, 300, 300)
    click(ctl, 320, 300)
    assert not ctl.pending["P1"].patrol and len(ctl.pending["P1"].route) == 2
    ctl.take_commands()
    ctl.clicked[0] = []
    for x, y in [(300, 300), (700, 300), (700, 700)]:
        click(ctl, x, y)
    world.step(ctl.take_commands())
    while world.team.goal_index[0] < 2:
        world.step()
    click(ctl, 310, 310)
    cmd = ctl.pending["P1"]
    assert cmd.patrol and cmd.route == ((700.0, 700.0), (300.0, 300.0), (700.0, 300.0))


def test_altitude_keys_step_within_bounds_and_skip_action_agents(world):
    """Up/Down move the target altitude by 5 m, clipped to the bounds; action agents stay."""
    ctl = Controller(world)
    z0 = world.team.z_target[0]
    key(ctl, "up")
    key(ctl, "up")
    assert ctl.pending["P1"].altitude == z0 + 2 * ALTITUDE_STEP
    for _ in range(40):
        key(ctl, "down")
    assert ctl.pending["P1"].altitude == world.team.alt_lo[0]
    key(ctl, "3")
    key(ctl, "up")
    assert "A1" not in ctl.pending and "fixed" in ctl.message


def test_click_on_depot_sends_the_agent_home(world):
    """A click inside the depot footprint sends the selected agent home, where it idles."""
    ctl = Controller(world)
    click(ctl, 600, 300)
    world.step(ctl.take_commands())
    for _ in range(10):
        world.step()
    x, y = world.scenario.depot.center
    click(ctl, x, y)
    assert ctl.pending["P1"].home
    world.step(ctl.take_commands())
    for _ in range(200):
        world.step()
    assert world.team.mode[0] == Mode.IDLE and world.team.at_home[0]
    assert ctl.planned_route(0).shape == (0, 2)


def test_battery_at_goal_subtracts_the_planned_path(world):
    """Battery at goal = battery now - 0.1 per px of the route still ahead."""
    ctl = Controller(world)
    p = world.team.pos[0]
    click(ctl, p[0] + 300, p[1])
    click(ctl, p[0] + 300, p[1] + 400)
    assert ctl.battery_at_goal(0) == pytest.approx(world.team.battery[0] - 0.1 * 700)


def test_unknown_event_type_is_refused(world):
    """An input dict of unknown type raises a one-line InputError."""
    with pytest.raises(InputError, match="unknown input event type"):
        Controller(world).handle({"type": "wheel"})


_events = st.one_of(
    st.builds(lambda k: {"type": "key", "key": k},
              st.sampled_from(["1", "2", "3", "4", "5", "up", "down"])),
    st.builds(lambda x, y: {"type": "click", "map": [x, y]},
              st.floats(-50, 1250), st.floats(-50, 1250)),
)  # fmt: skip


@settings(max_examples=25, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 29), _events), max_size=25), st.integers(0, 3))
def test_any_inputs_give_valid_commands_and_replay_identically(timed, seed):
    """Any input sequence gives commands inside the map and the altitude bounds, and replaying
    the recorded inputs reaches exactly the same state and scores."""
    sc = load_scenario("practice").replace(duration_s=3)
    game = GameSession(sc, seed)
    pending = sorted(timed, key=lambda te: te[0])
    while not game.done:
        while pending and pending[0][0] <= game.tick:
            game.input(pending.pop(0)[1])
        team = game.world.team
        for aid, cmd in game.controller.pending.items():
            i = team.index(aid)
            if cmd.route is not None:
                r = np.asarray(cmd.route).reshape(-1, 2)
                assert ((r >= 0) & (r <= sc.world_size - 1)).all()
            if cmd.altitude is not None:
                assert team.alt_lo[i] <= cmd.altitude <= team.alt_hi[i]
        game.step()
    again = replay_inputs(sc, seed, game.inputs)
    assert np.array_equal(again.world.team.pos, game.world.team.pos)
    assert again.final_metrics()["manual"] == game.final_metrics()["manual"]
