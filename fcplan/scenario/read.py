"""Reading scenarios: from a parsed TOML document, a file, or a shipped scenario's name.

:func:`load_scenario` finds the file (:func:`~fcplan.scenario.catalogue.scenario_path`), parses
it as TOML and builds the :class:`~fcplan.scenario.model.Scenario` with
:func:`scenario_from_dict`; the format is documented in :mod:`fcplan.scenario.document`. Every
problem is one :class:`~fcplan.errors.ScenarioError` line naming the file and the field.

Examples
--------
>>> s = load_scenario("#7")
>>> load_scenario(7) == load_scenario("07") == s
True
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from typing import Any

from fcplan.errors import ScenarioError
from fcplan.scenario.catalogue import scenario_path
from fcplan.scenario.model import Scenario

__all__ = ["load_scenario", "scenario_from_dict"]


def scenario_from_dict(doc: Mapping[str, Any], source: str | None = None) -> Scenario:
    """Build and validate a :class:`Scenario` from a TOML document (:mod:`fcplan.scenario.document`).

    The same as :meth:`Scenario.from_dict <fcplan.scenario.model.Scenario.from_dict>`: ``doc`` is
    the parsed TOML document, ``source`` the file name for error messages and
    :attr:`Scenario.source`; a :class:`~fcplan.errors.ScenarioError` names the field.

    Examples
    --------
    >>> doc = load_scenario("practice").to_dict()
    >>> scenario_from_dict(doc, "copy.toml").source
    'copy.toml'
    >>> doc["duration_s"] = 0
    >>> scenario_from_dict(doc, "copy.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: copy.toml: duration_s: must be a number > 0 ...
    """
    return Scenario.from_dict(doc, source)


def load_scenario(name_or_path: str | int | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario by name or from a TOML file.

    Parameters
    ----------
    name_or_path : str, int or path-like
        A shipped scenario (``12``, ``"12"``, ``"#12"``, ``"01"``, ``"practice"``, ``0``) or a
        ``.toml`` file.

    Raises
    ------
    UnknownNameError
        For an unknown name.
    ScenarioError
        If the file is missing, is not valid TOML or describes an invalid scenario. The one-line
        message names the file and the field.

    Examples
    --------
    >>> load_scenario("#24").regions[2].cell
    'A-12'
    """
    path = scenario_path(name_or_path)
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError("file", "no such scenario file", source=source) from None
    except (OSError, UnicodeDecodeError) as err:
        raise ScenarioError("file", f"cannot be read as UTF-8 text: {err}", source=source) from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ScenarioError("toml", f"not valid TOML: {err}", source=source) from None
    return scenario_from_dict(doc, source)
