"""Scenario files: loading, dumping and the names of the shipped scenarios (one import path).

The work is done in :mod:`fcplan.scenario.read` (:func:`load_scenario`,
:func:`scenario_from_dict`), :mod:`fcplan.scenario.write` (:func:`dump_scenario`),
:mod:`fcplan.scenario.catalogue` (:func:`list_scenarios`, :func:`scenario_path`) and
:mod:`fcplan.scenario.document` (the TOML format, :func:`scenario_to_dict`, the defaults); this
module exports their public names together.

Examples
--------
>>> from fcplan.scenario.io import dump_scenario, list_scenarios, load_scenario
>>> list_scenarios()[:3]
['practice', '1', '2']
>>> print(dump_scenario(load_scenario("#7")).splitlines()[1])
name = "#7"
"""

from __future__ import annotations

from fcplan.scenario.catalogue import list_scenarios, scenario_path
from fcplan.scenario.document import REGION_DEFAULTS, TEAM_DEFAULTS, scenario_to_dict
from fcplan.scenario.read import load_scenario, scenario_from_dict
from fcplan.scenario.write import dump_scenario

__all__ = [
    "load_scenario",
    "list_scenarios",
    "scenario_path",
    "dump_scenario",
    "scenario_from_dict",
    "scenario_to_dict",
    "REGION_DEFAULTS",
    "TEAM_DEFAULTS",
]
