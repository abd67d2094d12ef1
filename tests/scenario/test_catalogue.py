"""Tests of fcplan.scenario.catalogue: the shipped scenarios' names and files."""

from __future__ import annotations

import pytest

from fcplan.errors import UnknownNameError
from fcplan.scenario import list_scenarios, load_scenario, scenario_path
from tests.scenario.designs import BASE, write


def test_names_resolve_to_the_same_shipped_file():
    """12, "12", "#12", "012" and " #12 " all name scenario #12; 0 and "practice" the practice."""
    path = scenario_path(12)
    assert path.name == "12.toml"
    assert all(scenario_path(n) == path for n in ("12", "#12", "012", " #12 "))
    assert scenario_path(0) == scenario_path("practice") == scenario_path("Practice")
    assert scenario_path("scale_example").name == "scale_example.toml"
    assert load_scenario("01") == load_scenario(1)


def test_paths_are_loaded_as_files(tmp_path):
    """A path-like, a .toml name or a name with a separator is a file, not a shipped name."""
    path = write(tmp_path, BASE)
    assert scenario_path(path) == path
    assert scenario_path(str(path)) == path
    assert load_scenario(str(path)) == load_scenario(path)


def test_list_scenarios_order():
    """practice, 1..24, then the open-world examples."""
    names = list_scenarios()
    assert names == ["practice", *map(str, range(1, 25)), "open_world_example", "scale_example"]


@pytest.mark.parametrize("name", ["25", "#99", "nope", -1, 3.0])
def test_unknown_names_list_the_known_ones(name):
    """An unknown scenario name raises UnknownNameError, one line listing the known names."""
    with pytest.raises(UnknownNameError) as info:
        load_scenario(name)
    msg = str(info.value)
    assert "\n" not in msg
    assert repr(name) in msg
    assert "practice, 1, 2," in msg and "24, open_world_example, scale_example" in msg
    assert isinstance(info.value, KeyError)
