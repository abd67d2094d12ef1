"""Tests of fcplan.scenario.io: the one import path of the file functions."""

from __future__ import annotations

import fcplan.scenario as scenario
from fcplan.scenario import catalogue, document, io, read, write


def test_io_exports_the_objects_of_read_write_catalogue_and_document():
    """fcplan.scenario.io exports every public name it had, as the very objects of the modules
    that define them (and fcplan.scenario the ones it exported before)."""
    assert io.load_scenario is read.load_scenario is scenario.load_scenario
    assert io.scenario_from_dict is read.scenario_from_dict
    assert io.dump_scenario is write.dump_scenario is scenario.dump_scenario
    assert io.scenario_to_dict is document.scenario_to_dict is write.scenario_to_dict
    assert io.list_scenarios is catalogue.list_scenarios is scenario.list_scenarios
    assert io.scenario_path is catalogue.scenario_path is scenario.scenario_path
    assert io.REGION_DEFAULTS is document.REGION_DEFAULTS
    assert io.TEAM_DEFAULTS is document.TEAM_DEFAULTS
    assert set(io.__all__) == {
        "load_scenario",
        "list_scenarios",
        "scenario_path",
        "dump_scenario",
        "scenario_from_dict",
        "scenario_to_dict",
        "REGION_DEFAULTS",
        "TEAM_DEFAULTS",
    }
