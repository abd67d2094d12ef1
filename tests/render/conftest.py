"""Shared fixtures of the renderer tests."""

from __future__ import annotations

import pytest

from fcplan import World, load_scenario
from fcplan.team import Command


@pytest.fixture(scope="module")
def world():
    """Scenario 1 after a few seconds with agents sent out (so routes and FOVs exist)."""
    w = World().reset(load_scenario(1), seed=0)
    cmds = {
        aid: Command(route=((600.0, 600.0), (700.0, 300.0)), altitude=50.0) for aid in w.team.ids
    }
    w.step(cmds)
    for _ in range(40):
        w.step()
    return w
