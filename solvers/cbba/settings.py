"""Checks of the CBBA scheduler's settings, made once at construction.

Each check names the setting, the allowed range and the value it got, in one line, and raises
:class:`CBBASettingsError` (an :class:`fcplan.errors.FcplanError`, so the CLI prints it and exits
with status 2, and a :class:`ValueError`). Booleans are not numbers here, and an integer setting
does not take a float.

Examples
--------
>>> number("search_altitude", 70, lo=0.0, unit="m")
70.0
>>> number("search_altitude", float("nan"), lo=0.0, unit="m")
Traceback (most recent call last):
...
solvers.cbba.settings.CBBASettingsError: cbba: search_altitude must be a finite number >= 0 (m), got nan
>>> integer("bundle_length", 0, lo=1)
Traceback (most recent call last):
...
solvers.cbba.settings.CBBASettingsError: cbba: bundle_length must be an integer >= 1, got 0
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from typing import Any

from fcplan.errors import FcplanError

__all__ = ["CBBASettingsError", "flag", "integer", "number"]


class CBBASettingsError(FcplanError, ValueError):
    """A CBBA setting has the wrong type or is out of range."""


def _fail(name: str, allowed: str, value: Any) -> CBBASettingsError:
    return CBBASettingsError(f"cbba: {name} must be {allowed}, got {value!r}")


def number(name: str, value: Any, *, lo: float, strict: bool = False, unit: str = "") -> float:
    """``value`` as a float, finite and ``>= lo`` (``> lo`` when ``strict``)."""
    allowed = f"a finite number {'>' if strict else '>='} {lo:g}" + (f" ({unit})" if unit else "")
    if isinstance(value, bool) or not isinstance(value, Real):
        raise _fail(name, allowed, value)
    out = float(value)
    if not math.isfinite(out) or out < lo or (strict and out == lo):
        raise _fail(name, allowed, value)
    return out


def integer(name: str, value: Any, *, lo: int) -> int:
    """``value`` as an int, ``>= lo``."""
    if isinstance(value, bool) or not isinstance(value, Integral) or value < lo:
        raise _fail(name, f"an integer >= {lo}", value)
    return int(value)


def flag(name: str, value: Any) -> bool:
    """``value`` as a bool (True or False only)."""
    if not isinstance(value, bool):
        raise _fail(name, "true or false", value)
    return value
