"""Tests of fcplan.render.frame: snapshots of a live world."""

from __future__ import annotations

import numpy as np

from fcplan import World, load_scenario
from fcplan.render import snapshot
from fcplan.team import Command


def test_snapshot_copies_the_world():
    """A frame keeps what the world showed when it was taken, whatever the world does next."""
    w = World().reset(load_scenario("practice"), seed=0)
    w.step({aid: Command(route=((400.0, 400.0),)) for aid in w.team.ids})
    frame = snapshot(w)
    pos, fire = frame.agent_pos.copy(), frame.fire.copy()
    for _ in range(20):
        w.step()
    assert np.array_equal(frame.agent_pos, pos) and np.array_equal(frame.fire, fire)
    assert not np.array_equal(w.team.pos, pos)


def test_default_routes_are_the_goals_ahead():
    """Without explicit routes, an agent with a goal shows the goals still ahead of it and an
    idle agent none; explicit routes are taken as (k, 2) float arrays."""
    w = World().reset(load_scenario("practice"), seed=0)
    w.step({w.team.ids[0]: Command(route=((400.0, 400.0), (500.0, 400.0)))})
    frame = snapshot(w)
    assert frame.routes[0].tolist() == [[400.0, 400.0], [500.0, 400.0]]
    assert all(len(r) == 0 for r in frame.routes[1:])
    given = snapshot(w, routes=[[(1, 2)]] + [[]] * (w.team.n - 1))
    assert given.routes[0].dtype == np.float64 and given.routes[0].shape == (1, 2)
