"""Tests for fcplan.belief: the team's knowledge versus the true world."""

from __future__ import annotations

import numpy as np

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.fire import BURNING
from fcplan.team import Command


def run(world, belief, ticks, commands=None):
    for t in range(ticks):
        belief.update(world.step(commands if t == 0 else None))


def test_known_cells_are_exactly_the_sensed_unpruned_burning_cells():
    """The belief's known fire equals the world's sensed, still-burning cells at every check,
    and never includes fire no agent has sensed."""
    world = World().reset(load_scenario(1), seed=4)
    belief = Belief(world.scenario)
    cmd = {
        "P1": Command(route=((350.0, 350.0),), altitude=40.0),
        "A1": Command(route=((350.0, 350.0),) * 1),
    }
    for t in range(600):
        info = world.step(cmd if t == 0 else None)
        belief.update(info)
        if t % 60 == 0 and t:
            truth = np.flatnonzero((world.fire.state == BURNING).reshape(-1) & world.sensed.ravel())
            np.testing.assert_array_equal(np.sort(belief.known), truth)
    assert belief.known.size > 0


def test_last_seen_is_the_tick_of_the_latest_sighting():
    """Every known cell's last_seen is the tick it was last sensed, never in the future."""
    world = World().reset(load_scenario(3), seed=1)
    belief = Belief(world.scenario)
    run(world, belief, 300, {"P1": Command(route=((350.0, 350.0),), altitude=30.0)})
    seen = belief.last_seen.reshape(-1)[belief.known]
    assert (seen >= 1).all() and (seen <= world.tick).all()
    assert seen.max() == world.tick  # the hovering agent keeps re-sensing


def test_coverage_marks_only_camera_views():
    """Coverage records where perception agents looked; action agents' views do not count."""
    sc = load_scenario(1)
    world = World().reset(sc, seed=0)
    belief = Belief(sc)
    run(
        world,
        belief,
        80,
        {
            "P1": Command(route=((900.0, 900.0),), altitude=100.0),
            "A1": Command(route=((900.0, 200.0),)),
        },
    )
    c = belief.coverage_px
    assert belief.coverage[900 // c, 900 // c] == world.tick
    assert belief.coverage[900 // c, 200 // c] == -1
    age = belief.coverage_age_s(100)
    assert age.shape == (12, 12)
    assert age[9, 9] < age[9, 2]  # looked at recently vs never
