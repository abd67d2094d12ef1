"""Tests of fcplan.scenario.read: loading files (missing, unreadable, malformed) and documents."""

from __future__ import annotations

import tomllib

import pytest

from fcplan.scenario import Scenario, ScenarioError, load_scenario
from fcplan.scenario.read import scenario_from_dict
from tests.scenario.designs import BASE, edit, load_error


def test_missing_file_names_the_file(tmp_path):
    """A .toml path that does not exist is a one-line ScenarioError naming it."""
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(ScenarioError, match=f"^{missing}: file: no such scenario file$"):
        load_scenario(missing)


def test_malformed_toml_gives_line_and_column(tmp_path):
    """Invalid TOML is reported with field 'toml' and the parser's line and column."""
    msg = load_error(tmp_path, edit("fronts = 4", "fronts = = 4"))
    assert ": toml: not valid TOML: " in msg
    assert "line 10, column" in msg


def test_scenario_from_dict_is_the_classmethod():
    """read.scenario_from_dict builds the same scenario as Scenario.from_dict, and both record
    the source and attribute errors to it."""
    doc = tomllib.loads(BASE)
    assert (
        scenario_from_dict(doc, "a.toml")
        == Scenario.from_dict(doc)
        == load_scenario(1).from_dict(doc)
    )
    assert scenario_from_dict(doc, "a.toml").source == "a.toml"
    bad = tomllib.loads(edit("fuel = 8", "fuel = -1"))
    with pytest.raises(ScenarioError, match=r"^b\.toml: fire\.regions\[0\]\.fuel: "):
        scenario_from_dict(bad, "b.toml")
