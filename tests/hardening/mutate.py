"""Mutated scenario files, as the robustness audit of issue 17 made them.

A mutant is a shipped scenario's TOML document with one change: a value replaced by a hostile one
(zero, negative, tiny, huge, infinite, NaN, the wrong type, a deeply nested array), a key
deleted, or a list grown. :func:`mutant` makes one from a seeded generator and :func:`to_toml`
writes any document as TOML (:mod:`tests.hardening.runner` classifies what a command did with it).
"""

from __future__ import annotations

import copy
import json
import math
import random
import re
from typing import Any

from fcplan.scenario import list_scenarios, load_scenario

__all__ = ["EVIL", "leaves", "mutant", "to_toml"]

#: Replacement values: numbers at and far beyond every range, special floats, wrong types.
EVIL: tuple[Any, ...] = (
    0, -1, 1, 2, 7, 100, 1_000, 10**6, 10**9, 10**12, 10**18, 2**63 - 1, -(2**63),
    0.5, 1e-300, -1e-300, 1e-9, 1e300, -1e300, 1e308, math.inf, -math.inf, math.nan,
    True, False, "", "x" * 200, "A-01", [], [1, 2], [[1, 2], [3, 4]], {}, {"a": 1},
)  # fmt: skip
_DEEP = 60  # levels of a deeply nested array (the audit's RecursionError)


def leaves(doc: Any, path: tuple = ()) -> list[tuple[tuple, Any]]:
    """``(path, value)`` of every value in ``doc`` (tables, arrays and scalars; the root
    excluded); a path is a tuple of keys and list indices."""
    out = []
    items = (
        doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else []
    )
    for k, v in items:
        out.append(((*path, k), v))
        out.extend(leaves(v, (*path, k)))
    return out


def _parent(doc: Any, path: tuple) -> Any:
    for k in path[:-1]:
        doc = doc[k]
    return doc


def mutant(rng: random.Random, name: str | None = None) -> tuple[str, dict[str, Any]]:
    """One mutated document: ``(description, document)``."""
    name = name or rng.choice(list_scenarios())
    doc = copy.deepcopy(load_scenario(name).to_dict())
    paths = leaves(doc)
    path, old = rng.choice(paths)
    parent = _parent(doc, path)
    kind = rng.random()
    where = ".".join(str(p) for p in path)
    if kind < 0.75:
        new = rng.choice(EVIL)
        if isinstance(old, (int, float)) and not isinstance(old, bool) and rng.random() < 0.3:
            new = type(old)(old * rng.choice((-1, 10, 1000, 10**6)))  # nearby magnitudes
        parent[path[-1]] = copy.deepcopy(new)
        return f"{name}: {where} = {_short(new)}", doc
    if kind < 0.85:
        del parent[path[-1]]
        return f"{name}: del {where}", doc
    if kind < 0.95:
        lists = [(p, v) for p, v in paths if isinstance(v, list) and v]
        if lists:
            path, value = rng.choice(lists)
            times = rng.choice((10, 100, 1_000))
            _parent(doc, path)[path[-1]] = value * times
            return f"{name}: {'.'.join(map(str, path))} x {times}", doc
    deep: Any = [1]
    for _ in range(_DEEP):
        deep = [deep]
    parent[path[-1]] = deep
    return f"{name}: {where} = [[[...]]] ({_DEEP} deep)", doc


def _short(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."


_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: Any) -> str:
    k = str(k)
    return k if _BARE.match(k) else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    raise TypeError(f"no TOML for {type(v).__name__}")


def to_toml(doc: dict[str, Any]) -> str:
    """``doc`` as TOML: one ``key = value`` line per top-level key, tables inline."""
    return "".join(f"{_key(k)} = {_value(v)}\n" for k, v in doc.items())
