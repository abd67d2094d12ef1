"""Scenarios: what a FireCommander mission is, its TOML files, and their validation.

* :mod:`~fcplan.scenario.model`: the frozen, validated :class:`Scenario`.
* :mod:`~fcplan.scenario.parts`: its parts (:class:`FireRegion`, :class:`Facility`,
  :class:`Depot`, :class:`Lake`, :class:`AgentSpec`, :class:`Scoring`, :class:`Role`) and the
  game's tables (facility kinds and sizes, depot slots, the action altitude).
* :mod:`~fcplan.scenario.grid`: the chess-like 100-px grid (``"D-05"``) and object centres.
* :mod:`~fcplan.scenario.document`: the TOML format and its conversion to and from a Scenario.
* :mod:`~fcplan.scenario.read`: :func:`load_scenario` (by name or file), ``scenario_from_dict``.
* :mod:`~fcplan.scenario.write`: :func:`dump_scenario`.
* :mod:`~fcplan.scenario.catalogue`: the shipped scenarios' names and files.
* :mod:`~fcplan.scenario.validate`: physical validity (errors) and the manual's GUI limits.
* :mod:`~fcplan.scenario.io`: the file functions of read, write and catalogue under one name.
* :mod:`~fcplan.scenario.generate`: the seeded scenario generator (:class:`GeneratorConfig`, its
  ``default``/``hard``/``scale`` presets, :func:`recipe_of`), with :mod:`~fcplan.scenario.placement`
  (objects on the grid) and :mod:`~fcplan.scenario.knobs` (range-checked knobs). Call it as
  ``fcplan.scenario.generate.generate(seed, **knobs)`` or ``GeneratorConfig(**knobs)(seed)``.

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
from fcplan.scenario.catalogue import list_scenarios, scenario_path
from fcplan.scenario.generate import PRESETS, GeneratorConfig, recipe_of
from fcplan.scenario.grid import cell_center, cell_name
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
from fcplan.scenario.read import load_scenario
from fcplan.scenario.write import dump_scenario

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
    "GeneratorConfig",
    "PRESETS",
    "recipe_of",
    "cell_center",
    "cell_name",
    "ScenarioError",
    "UnknownNameError",
]
