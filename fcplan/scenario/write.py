"""Writing scenarios: the TOML text of a :class:`~fcplan.scenario.model.Scenario`.

:func:`dump_scenario` writes the document of :func:`~fcplan.scenario.document.scenario_to_dict`
(values equal to the format's defaults left out) as TOML: scalars first, then sub-tables and arrays
of tables in document order; lists longer than 80 characters are written one item a line. Loading
the text again gives an equal scenario.

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> print(dump_scenario(load_scenario("#7")).splitlines()[1])
name = "#7"
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from fcplan.scenario.document import scenario_to_dict
from fcplan.scenario.model import Scenario

__all__ = ["dump_scenario", "scenario_to_dict"]


def _toml_string(text: str) -> str:
    out = []
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(v: Any, indent: str = "") -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)
    if isinstance(v, (list, tuple)):
        inline = "[" + ", ".join(_toml_value(x) for x in v) + "]"
        if len(inline) <= 80:
            return inline
        inner = indent + "    "
        return "[\n" + "".join(f"{inner}{_toml_value(x, inner)},\n" for x in v) + indent + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _is_table(v: Any) -> bool:
    return isinstance(v, dict)


def _is_table_array(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _emit(lines: list[str], path: str, table: dict[str, Any], array: bool = False) -> None:
    scalars = {k: v for k, v in table.items() if not _is_table(v) and not _is_table_array(v)}
    if path and (scalars or array):
        lines += ["", f"[[{path}]]" if array else f"[{path}]"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in scalars.items()]
    for k, v in table.items():
        sub = f"{path}.{k}" if path else k
        if _is_table(v):
            _emit(lines, sub, v)
        elif _is_table_array(v):
            for item in v:
                _emit(lines, sub, item, array=True)


def dump_scenario(scenario: Scenario, path: str | os.PathLike[str] | None = None) -> str:
    """The scenario as TOML text; also written to ``path`` when given.

    ``load_scenario`` of the written file gives a scenario equal to ``scenario``.

    Examples
    --------
    >>> from fcplan.scenario import load_scenario
    >>> text = dump_scenario(load_scenario(1))
    >>> "[[fire.regions]]" in text and 'cell = "D-04"' in text
    True
    """
    lines = ["# Written by fcplan.scenario.dump_scenario."]
    _emit(lines, "", scenario_to_dict(scenario))
    text = "\n".join(lines) + "\n"
    if path is not None:
        Path(path).write_text(text, encoding="utf-8")
    return text
