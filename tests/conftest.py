"""Shared test helpers: scenarios with overrides."""

from __future__ import annotations

import copy
from typing import Any

import pytest

from fcplan.scenario import Scenario, load_scenario


def scenario_with(base: str | int = 1, **overrides: Any) -> Scenario:
    """A shipped scenario with dotted-path overrides of its TOML document.

    ``scenario_with(1, **{"team.action.battery": 50, "duration_s": 10})``
    """
    d = copy.deepcopy(load_scenario(base).to_dict())
    for path, value in overrides.items():
        node = d
        keys = path.split(".")
        for k in keys[:-1]:
            node = node.setdefault(k, {})
        node[keys[-1]] = value
    return Scenario.from_dict(d, source=f"test-{base}")


@pytest.fixture
def make_scenario():
    """Factory fixture for :func:`scenario_with`."""
    return scenario_with
