"""The shipped scenarios: their names and files.

Scenarios ship in the ``scenarios/`` folder, installed as the ``fcplan.scenarios`` package data:
``practice.toml``, ``01.toml``..``24.toml`` (the manual's pre-designed scenarios #1..#24) and
open-world examples. A scenario is named by its number (``12``, ``"12"``, ``"#12"``, ``"01"``; 0
is practice) or by its file's stem (``"practice"``, ``"scale_example"``). The benchmark suites'
scenarios (:mod:`fcplan.scenario.suite`) are named ``"hard-01"`` (in the current suite) or
``"fcplan-bench-v1/hard-01"`` (fully qualified). Anything else that looks like a path (ending in
``.toml`` or holding a path separator) is a file of the user's own.

Examples
--------
>>> list_scenarios()[:3]
['practice', '1', '2']
>>> scenario_path("#7") == scenario_path(7) == scenario_path("07")
True
>>> scenario_path("hard-01") == scenario_path("fcplan-bench-v1/hard-01")
True
>>> list_scenarios(suites=True)[-1]
'fcplan-bench-v2/hard-12'
"""

from __future__ import annotations

import functools
import importlib.util
import os
from pathlib import Path
from typing import Any

from fcplan.errors import UnknownNameError
from fcplan.scenario.suite import load_suite, suite_scenario_path, suite_versions
from fcplan.scenario.validate import is_integer

__all__ = ["list_scenarios", "scenario_path"]


@functools.cache
def _shipped_dir() -> Path:
    """Folder of the shipped scenario files: the installed ``fcplan.scenarios`` package data, or
    ``<repo>/scenarios`` in a source checkout."""
    try:
        spec = importlib.util.find_spec("fcplan.scenarios")
    except ImportError:
        spec = None
    for location in (spec.submodule_search_locations or []) if spec else []:
        if any(Path(location).glob("*.toml")):
            return Path(location)
    return Path(__file__).resolve().parents[2] / "scenarios"


def _shipped() -> dict[str, Path]:
    """Shipped scenario names -> files: practice, "1".."24", then the other files' stems."""
    files = {p.stem: p for p in _shipped_dir().glob("*.toml")}
    numbered = sorted((int(stem), p) for stem, p in files.items() if stem.isdigit())
    out = {"practice": files["practice"]} if "practice" in files else {}
    out.update((str(n), p) for n, p in numbered)
    out.update(
        (stem, files[stem]) for stem in sorted(files) if not stem.isdigit() and stem != "practice"
    )
    return out


def list_scenarios(*, suites: bool = False) -> list[str]:
    """Names of the shipped scenarios, in order: practice, 1..24, then the examples; with
    ``suites``, then every benchmark suite's scenarios (fully qualified, oldest suite first).

    Examples
    --------
    >>> names = list_scenarios()
    >>> names[0], names[1], names[24], names[25:]
    ('practice', '1', '24', ['open_world_example', 'scale_example'])
    >>> list_scenarios(suites=True)[27]
    'fcplan-bench-v1/hard-01'
    """
    names = list(_shipped())
    if suites:
        for version in suite_versions():
            names += load_suite(version).names()
    return names


def scenario_path(name: str | int | os.PathLike[str]) -> Path:
    """File of a scenario given by name (``"12"``, ``12``, ``"#12"``, ``"01"``, ``"practice"``,
    ``"scale_example"``, ``"hard-01"``, ``"fcplan-bench-v1/hard-01"``) or by path (anything
    path-like, ending in ``.toml`` or containing a path separator).

    Raises
    ------
    UnknownNameError
        If the name is not a shipped scenario; the message lists the known names.

    Examples
    --------
    >>> scenario_path("#12").name, scenario_path(0).name
    ('12.toml', 'practice.toml')
    """
    if isinstance(name, os.PathLike):
        return Path(name)
    if isinstance(name, str) and not name.endswith(".toml"):
        in_suite = suite_scenario_path(name)
        if in_suite is not None:
            return in_suite
    if isinstance(name, str) and (name.endswith(".toml") or "/" in name or os.sep in name):
        return Path(name)
    key: Any = name
    if isinstance(name, str):
        key = name.strip().lower().removeprefix("#")
        if key.isdigit():
            key = int(key)
    if is_integer(key):
        key = "practice" if key == 0 else str(key)
    shipped = _shipped()
    if isinstance(key, str) and key in shipped:
        return shipped[key]
    known = ", ".join(shipped)
    for version in suite_versions():
        for entries in load_suite(version).tiers().values():
            known += f", {version}/{entries[0].name}..{entries[-1].name}"
    raise UnknownNameError(
        f"unknown scenario {name!r}; known scenarios: {known} (or the path of a .toml file)"
    )
