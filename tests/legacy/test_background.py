"""Tests of fcplan.legacy.background: the scenario document of a Background_Info.pkl list."""

from __future__ import annotations

import pytest

from fcplan.legacy import LegacyError, scenario_dict_from_background
from fcplan.scenario import Scenario


def _background(specific: bool = False) -> list:
    """A Background_Info.pkl list (section 3 layout): 800 px, 60 s, 2 regions, 1P/1A/1H."""
    fire = [3, 0, 10, 5, 45, 1.25, 0.1, 90, 80, 1 if specific else 0]
    if specific:
        fire[:5] = [[3, 6], [0, 20], [10, 12], [5, 4], [45, 90]]
    loci = [[(450, 150), (350, 550)], fire, [(100, 200), 1], [(600, 500)], [], [], []]
    adv = [[[10, 100]], [[20, 60]], [[500]], [[400]], [[450]], [[20]], [[15]], [[18]]]
    return [[800, 60], [1, 1, 1], loci, adv + [[[10]], [[6]]]]


def test_uniform_and_specific_fire_settings():
    """Uniform mode gives every region the one setting; specific mode reads one per region; the
    pruning gate is the 2020 rule and the result builds a valid Scenario."""
    doc = scenario_dict_from_background(_background())
    assert doc["fire"]["mode"] == "uniform" and doc["fire"]["action_gate"] == "reference"
    assert [r["fronts"] for r in doc["fire"]["regions"]] == [3, 3]
    doc = scenario_dict_from_background(_background(specific=True))
    regions = doc["fire"]["regions"]
    assert [(r["fronts"], r["delay_s"], r["wind_dir_deg"]) for r in regions] == [
        (3, 0.0, 45.0),
        (6, 20.0, 90.0),
    ]
    s = Scenario.from_dict(doc)
    assert s.team_counts == {"perception": 1, "action": 1, "hybrid": 1}
    assert [a.prune_confidence for a in s.agents] == [0.0, 0.9, 0.8]
    assert s.agents[2].altitude == (20.0, 60.0) and s.agents[1].tank == 10


def test_battery_info_overrides_the_capacities():
    """Battery_Info.pkl rows give each agent's capacity in team order."""
    doc = scenario_dict_from_background(_background(), batteries=[[300], [310], [320]])
    team = doc["team"]
    assert (team["perception"]["battery"], team["action"]["battery"]) == ([300.0], [310.0])
    assert team["hybrid"]["battery"] == [320.0]


def test_a_wrong_layout_names_the_file():
    """A list without the documented entries raises LegacyError naming Background_Info.pkl."""
    with pytest.raises(LegacyError, match="^Background_Info.pkl: unexpected layout"):
        scenario_dict_from_background([[800, 60]])
    bad = _background()
    bad[0][0] = "wide"
    with pytest.raises(LegacyError, match="W must be a number"):
        scenario_dict_from_background(bad)
