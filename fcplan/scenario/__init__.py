"""Scenarios: what a FireCommander mission is, its TOML files, and their validation.

* :mod:`~fcplan.scenario.model`: the frozen dataclasses (:class:`Scenario`, :class:`FireRegion`,
  :class:`Facility`, :class:`Depot`, :class:`Lake`, :class:`AgentSpec`, :class:`Scoring`,
  :class:`Role`).
* :mod:`~fcplan.scenario.grid`: the chess-like 100-px grid (``"D-05"``) and object centres.
* :mod:`~fcplan.scenario.io`: the TOML format, :func:`load_scenario`, :func:`dump_scenario`, the
  shipped scenario names.
* :mod:`~fcplan.scenario.validate`: physical validity (errors) and the manual's GUI limits.

The 25 shipped scenarios (practice and #1..#24) follow the FireCommander manual's tables for counts,
team and fire parameters and the reference data for coordinates; each file notes where the 2020
reference code used other values.

Examples
--------
>>> from fcplan.scenario import load_scenario, list_scenarios
>>> len(list_scenarios())
27
>>> s = load_scenario(12)
>>> s.summary()
'#12  moderate  team 3P/2A  regions D-08(3f) K-11(10f, +60s)'
>>> s.manual_limit_violations()
[]
"""

from fcplan.errors import ScenarioError, UnknownNameError
from fcplan.scenario.grid import cell_center, cell_name
from fcplan.scenario.io import dump_scenario, list_scenarios, load_scenario, scenario_path
from fcplan.scenario.model import (
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    Scenario,
    Scoring,
)

__all__ = [
    "Role",
    "FireRegion",
    "Facility",
    "Depot",
    "Lake",
    "AgentSpec",
    "Scoring",
    "Scenario",
    "load_scenario",
    "list_scenarios",
    "scenario_path",
    "dump_scenario",
    "cell_center",
    "cell_name",
    "ScenarioError",
    "UnknownNameError",
]
