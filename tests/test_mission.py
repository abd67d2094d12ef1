"""Tests for fcplan.mission: the one replan loop, its replan rule and its observers; a copied
mission runs on as the original."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import load_scenario, make_scheduler, run_episode
from fcplan.errors import FcplanError
from fcplan.mission import BaseObserver, EpisodeObserver, Mission
from tests.missions import play_until

SHORT = load_scenario("practice").replace(duration_s=6)


class Log(BaseObserver):
    """Writes down every hook call, in order."""

    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def on_replan(self, tick, plan) -> None:
        self.calls.append(("replan", tick))

    def on_commands(self, tick, commands) -> None:
        self.calls.append(("commands", tick, None if commands is None else sorted(commands)))

    def on_step(self, world, info) -> None:
        self.calls.append(("step", info.tick))

    def on_input(self, tick, event) -> None:
        self.calls.append(("input", tick, dict(event)))


def test_run_is_run_episode():
    """Mission.run plays the episode run_episode scores: same trace, replan ticks and solves."""
    mission = Mission(3, seed=1).run(make_scheduler("greedy"))
    res = run_episode(3, "greedy", seed=1)
    assert mission.done and mission.tick == res.ticks
    np.testing.assert_array_equal(mission.replan_ticks, res.replan_ticks)
    assert [s.status for s in mission.solves] == [s.status for s in res.solves]
    for k, v in res.trace.arrays().items():
        np.testing.assert_array_equal(mission.world.trace().arrays()[k], v, err_msg=k)


def test_periodic_rule_without_events():
    """Without event replans a replan is due exactly every period, from tick 0, and at no
    other tick."""
    mission = Mission(SHORT, seed=0, replan_period=0.5, event_replans=False)
    greedy = make_scheduler("greedy")
    due = []
    while not mission.done:
        commands = None
        if mission.replan_due():
            due.append(mission.tick)
            graph, plan = mission.replan(greedy)
            commands = mission.commands_for(plan, graph)
        mission.step(commands)
    assert due == list(range(0, SHORT.n_ticks, 5))
    np.testing.assert_array_equal(mission.replan_ticks, due)


def test_new_fire_outside_the_plan_makes_a_replan_due():
    """Sensing a cell in a tile without a fire task of the last graph makes a replan due at
    once; sensing one in a planned tile does not; the periodic schedule does not move."""
    mission = Mission(SHORT, seed=0, replan_period=5.0)
    idle = make_scheduler("idle")
    mission.replan(idle)  # tick 0: nothing known, no fire task
    world, belief = mission.world, mission.belief
    assert belief is not None
    i = int(np.flatnonzero(world.team.can_sense)[0])
    x, y = (int(v) for v in world.team.pos[i])
    world.ignite([[x, y]])
    while not belief.known.size:
        mission.step()
        assert not mission.done
    assert mission.replan_due() and 0 < mission.tick < 50  # the event, before the period
    graph, _ = mission.replan(idle)
    assert graph.fire_tasks.size and not mission.replan_due()
    tile = graph.tile_px
    (nx, ny), *_ = [
        (a, b)
        for a, b in ((x, y + 1), (x, y - 1), (x + 1, y), (x - 1, y))
        if a // tile[0] == x // tile[0] and b // tile[1] == y // tile[1]
    ]
    world.ignite([[nx, ny]])
    while belief.known.size < 2:
        mission.step()
        assert not mission.replan_due() and mission.tick < 50
    mission.advance(50 - mission.tick)
    assert mission.replan_due()  # the periodic replan, still at tick 50


def test_observers_hear_every_hook_in_order():
    """Observers hear on_replan, then on_commands before and on_step after every tick, and the
    inputs with the tick they arrived at; a BaseObserver subclass needs only its hooks."""
    log = Log()
    mission = Mission(SHORT, seed=0, observers=[log])
    assert isinstance(log, EpisodeObserver)
    mission.notify_input({"type": "key", "key": "1"})
    graph, plan = mission.replan(make_scheduler("greedy"))
    mission.step(mission.commands_for(plan, graph))
    mission.step()
    ids = sorted(mission.commands_for(plan, graph))
    assert log.calls == [
        ("input", 0, {"type": "key", "key": "1"}),
        ("replan", 0),
        ("commands", 0, ids),
        ("step", 1),
        ("commands", 1, None),
        ("step", 2),
    ]


def test_belief_follows_every_tick_or_none():
    """The belief is updated every tick; a mission without belief keeps none until asked, and
    cannot plan before."""
    mission = Mission(SHORT, seed=2)
    mission.advance(20)
    assert mission.belief is not None and mission.belief.tick == 20
    blind = Mission(SHORT, seed=2, belief=False)
    blind.advance(20)
    assert blind.belief is None
    with pytest.raises(ValueError, match="track_belief"):
        blind.replan(make_scheduler("greedy"))
    belief = blind.track_belief()
    blind.advance(3)
    assert belief is blind.belief and belief.tick == 23


def test_reset_replays_the_same_episode_on_the_same_world():
    """Resetting with the same seed replays the same episode on the same World object; the
    replan rule starts again at tick 0."""
    mission = Mission(SHORT, seed=4, replan_period=2.0)
    world = mission.world
    greedy = make_scheduler("greedy")
    first = mission.run(greedy).world.trace().arrays()
    ticks = mission.replan_ticks
    again = mission.reset(4)
    assert again is mission and mission.world is world and mission.tick == 0
    assert mission.replan_due() and mission.solves == []
    second = mission.run(greedy).world.trace().arrays()
    np.testing.assert_array_equal(mission.replan_ticks, ticks)
    for k, v in first.items():
        np.testing.assert_array_equal(second[k], v, err_msg=k)


def test_advance_stops_at_the_end_and_rule_changes_apply_at_once():
    """advance runs at most the ticks left; set_replan_rule makes the next replan due now and
    rejects non-positive periods."""
    mission = Mission(SHORT, seed=0)
    assert mission.advance(10) == 10
    mission.set_replan_rule(2.0, event_replans=False)
    assert mission.replan_due() and mission.period == 20
    mission.replan(make_scheduler("idle"))
    assert not mission.replan_due()
    assert mission.advance(10_000) == SHORT.n_ticks - 10 and mission.done
    assert mission.advance(5) == 0
    with pytest.raises(ValueError, match="replan_period"):
        mission.set_replan_rule(0.0, event_replans=True)


@settings(max_examples=10, deadline=None)
@given(st.floats(0.1, 2.5), st.booleans(), st.integers(0, 50))
def test_every_periodic_tick_is_a_replan(period, events, seed):
    """For any period and seed, the replans happen at every multiple of the period (in ticks)
    and, without event replans, only there."""
    sc = load_scenario("practice").replace(duration_s=3)
    mission = Mission(sc, seed=seed, replan_period=period, event_replans=events)
    mission.run(make_scheduler("greedy"))
    step = max(int(round(period * sc.ticks_per_second)), 1)
    periodic = set(range(0, sc.n_ticks, step))
    got = set(mission.replan_ticks.tolist())
    assert periodic <= got
    if not events:
        assert got == periodic


class _CommandTicks(BaseObserver):
    """Records the ticks at which the mission hands commands to the world."""

    def __init__(self) -> None:
        self.ticks: list[int] = []

    def on_commands(self, tick, commands) -> None:
        if commands is not None:
            self.ticks.append(tick)


def test_latency_in_ticks_delays_every_plan_and_blocks_replans_meanwhile():
    """With ``latency="ticks:N"`` each plan applies exactly N ticks after its replan, no replan
    starts while one is pending, and N = 0 is the same episode as no latency."""
    greedy = make_scheduler("greedy")
    seen = _CommandTicks()
    m = Mission("practice", seed=0, observers=[seen]).run(greedy, latency="ticks:4")
    replans = m.replan_ticks.tolist()
    assert seen.ticks == [t + 4 for t in replans if t + 4 < m.scenario.n_ticks]
    assert all(b - a >= 4 for a, b in zip(replans, replans[1:], strict=False))
    plain = Mission("practice", seed=0).run(greedy)
    zero = Mission("practice", seed=0).run(greedy, latency="ticks:0")
    assert np.array_equal(plain.world.trace().active, zero.world.trace().active)


def test_latency_changes_the_outcome_and_wall_latency_runs():
    """Planning that takes simulated time is not free: a 3-second latency changes the episode;
    ``latency="wall"`` plays to the end; a bad value is a one-line error."""
    fast = run_episode(24, "greedy", seed=0)
    slow = run_episode(24, "greedy", seed=0, latency="ticks:30")
    assert slow.metrics["manual"].final_score != fast.metrics["manual"].final_score
    assert run_episode("practice", "greedy", seed=0, latency="wall").ticks == 1800
    with pytest.raises(FcplanError, match=r"latency: must be None, 'wall' or 'ticks:N'"):
        run_episode("practice", "greedy", seed=0, latency="ticks:-1")


def test_set_graph_params_builds_the_graphs_with_them_from_then_on():
    """``Mission.set_graph_params`` reaches the graphs built after it, and survives a reset:
    200-px search blocks give the practice map 36 search tasks instead of 144."""
    from fcplan.taskgraph import TaskGraphParams

    mission = Mission("practice", 0)
    assert mission.task_graph().search_tasks.size == 144
    mission.set_graph_params(TaskGraphParams(search_block_px=200))
    assert mission.task_graph().search_tasks.size == 36
    mission.reset(1)
    assert mission.task_graph().search_tasks.size == 36


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"time_limit": float("nan")}, r"^time_limit: must be None or a finite number > 0"),
        ({"time_limit": 0}, r"^time_limit: must be None or a finite number > 0"),
        ({"time_limit": -1.0}, r"^time_limit: must be None or a finite number > 0"),
        ({"time_limit": True}, r"^time_limit: must be None or a finite number > 0"),
        ({"time_limit": "1"}, r"^time_limit: must be None or a finite number > 0"),
        ({"replan_period": -1}, r"^replan_period: must be a finite number > 0"),
        ({"replan_period": float("inf")}, r"^replan_period: must be a finite number > 0"),
        ({"replan_period": "1"}, r"^replan_period: must be a finite number > 0"),
    ],
)
def test_bad_time_limits_and_periods_are_one_line_argument_errors(kwargs, match):
    """run_episode refuses a time limit or replan period that is not a finite number > 0 (a
    NaN time limit used to reach every scheduler call) with one ArgumentError line, an
    FcplanError and ValueError, before any tick."""
    from fcplan import run_episode
    from fcplan.errors import ArgumentError, FcplanError

    with pytest.raises(ArgumentError, match=match) as err:
        run_episode("practice", "greedy", seed=0, **kwargs)
    assert isinstance(err.value, FcplanError) and isinstance(err.value, ValueError)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
def test_a_copied_mission_runs_on_as_the_original(how):
    """A mission of #1 copied at tick 400 (greedy replanning) and both run to the end with a
    fresh greedy: the same replan ticks and the same trace of active and pruned cells."""
    m = play_until(Mission("1", seed=3), make_scheduler("greedy"), 400)
    twin = copy.deepcopy(m) if how == "deepcopy" else pickle.loads(pickle.dumps(m))
    m.run(make_scheduler("greedy"))
    twin.run(make_scheduler("greedy"))
    assert twin.tick == m.tick and twin.replan_ticks.tolist() == m.replan_ticks.tolist()
    mine, theirs = m.world.trace(), twin.world.trace()
    for field in ("active", "pruned"):
        assert np.array_equal(getattr(theirs, field), getattr(mine, field)), field
