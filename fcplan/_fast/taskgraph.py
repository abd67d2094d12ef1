"""Fast construction of the frozen dataclass instances built at every replan.

Specification: ``new_frozen(cls, fields, cached)`` is ``cls(**fields)`` followed by
``obj.__dict__.update(cached)`` (values of ``functools.cached_property`` attributes filled in
at once), for a frozen dataclass ``cls`` without ``__slots__``, ``__post_init__`` or fields
with ``init=False``, given every field. The frozen dataclass's ``__init__`` sets each field
through ``object.__setattr__``; a task graph has 37 fields, and a graph is built every replan.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class P:
...     x: int
...     y: int = 0
>>> new_frozen(P, {"x": 1, "y": 2}, {}) == P(1, 2)
True
"""

from __future__ import annotations

from typing import Any, TypeVar

__all__ = ["new_frozen"]

_T = TypeVar("_T")


def new_frozen(cls: type[_T], fields: dict[str, Any], cached: dict[str, Any]) -> _T:
    """``cls(**fields)`` with ``cached`` put in its ``__dict__`` (see the module docstring)."""
    obj: _T = object.__new__(cls)
    d = obj.__dict__
    d.update(fields)
    d.update(cached)
    return obj
