"""Scenario overrides of a sweep: dotted paths into a scenario's TOML document.

A sweep file's ``[overrides]`` table (:mod:`fcplan.experiments.config`) sets values at dotted
paths of each scenario's document (:mod:`fcplan.scenario.document`): ``key`` descends into a
table, ``key[i]`` indexes a list and ``key[*]`` means every item; ``a+b`` sets both paths. The
changed document is read again with :func:`fcplan.scenario.read.scenario_from_dict`, so every
bound and validity check applies, and a bad combination fails before anything runs.

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> s = apply_overrides(load_scenario(3), {"team.action.count+team.perception.count": 3})
>>> s.team_counts["action"], s.team_counts["perception"]
(3, 3)
"""

from __future__ import annotations

import copy
import re
from collections.abc import Mapping
from typing import Any

from fcplan.errors import FcplanError

__all__ = ["SweepConfigError", "apply_overrides"]


class SweepConfigError(FcplanError, ValueError):
    """A sweep file (or dict) is malformed: the message names the file, the field and what is
    allowed."""


_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[(?:\*|\d+)\])*)$")


def _set_path(node: Any, parts: list[str], value: Any, path: str) -> None:
    """Set ``value`` at the dotted ``parts`` inside ``node`` (dicts and lists)."""
    head, rest = parts[0], parts[1:]
    m = _PART.match(head)
    if m is None:
        raise FcplanError(f"malformed path element {head!r} (use key, key[0] or key[*])")
    key, idx_text = m.group(1), m.group(2)
    indices = re.findall(r"\[(\*|\d+)\]", idx_text)
    if not isinstance(node, dict):
        raise FcplanError(f"{path}: {key!r} is not inside a table")
    if not indices and not rest:
        node[key] = copy.deepcopy(value)
        return
    if key not in node:
        raise FcplanError(
            f"{path}: no field {key!r} here; fields: {', '.join(sorted(node)) or '(none)'}"
        )
    slots: list[tuple[Any, Any]] = [(node, key)]  # (container, index) pairs to descend into
    for ix in indices:
        nxt: list[tuple[Any, Any]] = []
        for parent, k in slots:
            t = parent[k]
            if not isinstance(t, list):
                raise FcplanError(f"{path}: {key!r} is not a list, so [{ix}] does not apply")
            if ix == "*":
                nxt.extend((t, i) for i in range(len(t)))
            elif int(ix) < len(t):
                nxt.append((t, int(ix)))
            else:
                raise FcplanError(f"{path}: index {ix} out of range 0..{len(t) - 1}")
        slots = nxt
    for parent, k in slots:
        if rest:
            _set_path(parent[k], rest, value, path)
        else:
            parent[k] = copy.deepcopy(value)


def apply_overrides(scenario: Any, overrides: Mapping[str, Any], *, source: str = "") -> Any:
    """A copy of ``scenario`` with dotted-path ``overrides`` applied to its TOML document.

    Paths are keys separated by dots; ``key[i]`` indexes a list and ``key[*]`` means every item,
    e.g. ``"team.perception.count"``, ``"fire.regions[*].wind_speed"``, ``"duration_s"``. In
    ``uniform`` fire mode the region parameters live in ``fire`` itself (``"fire.wind_speed"``).
    Several paths joined by ``+`` all receive the value (``"team.perception.count+team.action.count"``).

    Raises
    ------
    SweepConfigError
        A path that does not exist in the document, or a value the scenario rejects (the
        scenario's validation message is included).

    Examples
    --------
    >>> from fcplan.scenario import load_scenario
    >>> s = apply_overrides(load_scenario(12), {"fire.regions[*].wind_speed": 15})
    >>> [r.wind_speed for r in s.regions]
    [15.0, 15.0]
    """
    from fcplan.scenario.read import scenario_from_dict

    if not overrides:
        return scenario
    doc = copy.deepcopy(scenario.to_dict())
    where = f"{source}: " if source else ""
    for path, value in overrides.items():
        try:
            for one in path.split("+"):
                _set_path(doc, one.strip().split("."), value, path)
        except FcplanError as exc:
            raise SweepConfigError(f"{where}overrides: scenario {scenario.name}: {exc}") from None
    try:
        return scenario_from_dict(doc, source=scenario.source)
    except FcplanError as exc:
        shown = ", ".join(f"{k}={v!r}" for k, v in overrides.items())
        raise SweepConfigError(
            f"{where}overrides {shown} make scenario {scenario.name} invalid: {exc}"
        ) from None
