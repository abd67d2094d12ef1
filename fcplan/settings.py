"""Checks of scheduler settings, made once at construction: the types, ranges and messages.

A factory checks each setting it takes with one of these helpers, which return the value as the
type it should have and raise :class:`SettingError` otherwise: one line naming the setting, what
is allowed and the value it got (``bad setting route_length=0: must be an integer in 1..1000``;
:func:`fcplan.scheduling.make_scheduler` adds the scheduler's name, the CLI prints the line and
exits with status 2). Booleans are not numbers here, NaN and infinities are refused, and an
integer setting does not take a float.

One range per kind of setting lives here, so that every scheduler and the task-level env take
the same values: an altitude (a watch, search or dump altitude) is a number of metres in
``(0, MAX_ALTITUDE_M]`` (:func:`altitude_setting`), clipped later to each agent's bounds by the
task graph.

Examples
--------
>>> altitude_setting("watch_altitude", 35)
35.0
>>> altitude_setting("dump_altitude", 0)
Traceback (most recent call last):
...
fcplan.settings.SettingError: bad setting dump_altitude=0: must be a number in (0, 10000] m
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from fcplan.errors import FcplanError

__all__ = [
    "MAX_ALTITUDE_M", "SettingError", "altitude_setting", "bool_setting", "choice_setting",
    "float_setting", "int_setting", "show_value",
]  # fmt: skip

#: The highest altitude a setting may ask for, in metres (a task graph clips it to each agent's
#: bounds, which are far lower).
MAX_ALTITUDE_M = 10_000.0

_MISSING = object()


class SettingError(FcplanError, ValueError):
    """A scheduler setting of the wrong type or out of range.

    Factories raise it from their constructor (the helpers :func:`int_setting`,
    :func:`float_setting`, :func:`altitude_setting`, :func:`bool_setting` and
    :func:`choice_setting` do); :func:`fcplan.scheduling.make_scheduler` adds the scheduler's
    name. The message is one line:
    ``scheduler 'greedy': bad setting route_length=0: must be an integer in 1..1000``.

    Parameters
    ----------
    setting : str
        The setting's name.
    reason : str
        What is wrong and what is allowed.
    value : Any, optional
        The offending value.
    scheduler : str, optional
        The scheduler's registered name.
    """

    def __init__(
        self, setting: str, reason: str, *, value: Any = _MISSING, scheduler: str | None = None
    ) -> None:
        self.setting, self.reason, self.value, self.scheduler = setting, reason, value, scheduler
        what = setting if value is _MISSING else f"{setting}={show_value(value)}"
        head = f"scheduler {scheduler!r}: " if scheduler else ""
        super().__init__(f"{head}bad setting {what}: {reason}")

    def for_scheduler(self, scheduler: str) -> SettingError:
        """The same error naming ``scheduler``."""
        return SettingError(self.setting, self.reason, value=self.value, scheduler=scheduler)


def show_value(value: Any) -> str:
    """A setting's value for a message: short, one line."""
    text = repr(value) if not isinstance(value, str) else value
    text = text.replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."


def int_setting(name: str, value: Any, lo: int, hi: int | None = None) -> int:
    """``value`` as an int in ``lo..hi`` (bools and non-integral numbers refused).

    Examples
    --------
    >>> int_setting("route_length", 3, 1, 1000)
    3
    >>> int_setting("route_length", 0, 1, 1000)
    Traceback (most recent call last):
    ...
    fcplan.settings.SettingError: bad setting route_length=0: must be an integer in 1..1000
    """
    allowed = f"an integer in {lo}..{hi}" if hi is not None else f"an integer >= {lo}"
    ok = isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
    if not ok or value < lo or (hi is not None and value > hi):
        raise SettingError(name, f"must be {allowed}", value=value)
    return int(value)


def float_setting(
    name: str,
    value: Any,
    lo: float,
    hi: float = math.inf,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
    unit: str = "",
) -> float:
    """``value`` as a finite float in the interval ``lo..hi`` (open ends as asked; NaN, infinities
    and bools refused). ``hi=math.inf`` leaves it unbounded above (but finite).

    Examples
    --------
    >>> float_setting("fresh_s", 2, 0, lo_open=True)
    2.0
    >>> float_setting("time_limit", float("nan"), 0, lo_open=True, unit=" s")
    Traceback (most recent call last):
    ...
    fcplan.settings.SettingError: bad setting time_limit=nan: must be a finite number > 0 s
    """
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )
    v = float(value) if ok else math.nan
    inside = (
        math.isfinite(v) and (v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
    )
    if not inside:
        raise SettingError(
            name, f"must be {_interval(lo, hi, lo_open, hi_open)}{unit}", value=value
        )
    return v


def _interval(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    if math.isinf(hi):
        return f"a finite number {'>' if lo_open else '>='} {lo:g}"
    return f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


def bool_setting(name: str, value: Any) -> bool:
    """``value`` as a bool (only ``True``/``False``; ``"true"`` in a spec is already a bool)."""
    if not isinstance(value, (bool, np.bool_)):
        raise SettingError(name, "must be true or false", value=value)
    return bool(value)


def choice_setting(name: str, value: Any, choices: Iterable[str]) -> str:
    """``value`` if it is one of ``choices``."""
    options = tuple(choices)
    if not isinstance(value, str) or value not in options:
        raise SettingError(name, f"must be one of {', '.join(options)}", value=value)
    return value


def altitude_setting(name: str, value: Any) -> float:
    """``value`` as an altitude: a finite number of metres in ``(0, MAX_ALTITUDE_M]`` (the range
    of every scheduler's watch, search and dump altitudes and of the task env's).

    Examples
    --------
    >>> altitude_setting("search_altitude", 70)
    70.0
    """
    return float_setting(name, value, 0.0, MAX_ALTITUDE_M, lo_open=True, unit=" m")
