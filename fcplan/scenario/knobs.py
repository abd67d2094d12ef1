"""Knobs: typed, range-checked fields of a frozen settings dataclass.

A *knob* is a dataclass field whose metadata says what it accepts: a kind and an allowed range.
:func:`check_knobs` validates and normalises every knob of an instance, typically from its
``__post_init__``. A bad value raises a one-line :class:`~fcplan.errors.ScenarioError` that names
the knob, the allowed values and the value given.

====================  ==========================================  ==========================
kind                  accepts                                     stored as
====================  ==========================================  ==========================
``int``               an integer in the range (and a multiple     ``int``
                      of ``step``)
``float``             a finite number in the range                ``float``
``optional``          as ``float``, or None                       ``float`` or None
``choice``            one of ``choices``                          ``str``
``irange``            an integer, or a pair ``[lo, hi]`` of       ``(lo, hi)`` ints
                      integers with ``lo <= hi``, in the range
``frange``            a number, or a pair ``[lo, hi]``            ``(lo, hi)`` floats
``pair``              a pair ``[lo, hi]`` (no single number)      ``(lo, hi)`` floats
====================  ==========================================  ==========================

A single number given to a range kind means ``(v, v)``. Bools are not numbers, NaN and infinities
are out of every range, and numpy scalars are accepted.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class Settings:
...     size: int | tuple[int, int] = knob(4, "irange", 1, 10)
...     rate: float = knob(0.5, "float", 0, 1, open_lo=True)
...     def __post_init__(self) -> None:
...         check_knobs(self, source="settings")
>>> Settings(size=(2, 3)).size, Settings().size
((2, 3), (4, 4))
>>> Settings(rate=0)
Traceback (most recent call last):
...
fcplan.errors.ScenarioError: settings: rate: must be a number in (0, 1] (got 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

from fcplan.errors import ScenarioError
from fcplan.scenario.validate import is_integer, is_number

__all__ = ["KINDS", "Knob", "check_knobs", "knob", "knob_table", "knobs_of", "span"]

KINDS = ("int", "float", "optional", "choice", "irange", "frange", "pair")
"""The kinds of knob (see the module docstring)."""


@dataclass(frozen=True)
class Knob:
    """What one knob accepts: its ``kind`` (one of :data:`KINDS`), the range ``lo..hi``
    (``(lo, hi]`` when ``open_lo``), a ``step`` integers must be multiples of, the ``choices``;
    ``doc`` says what it means (a few words, with the unit).

    Examples
    --------
    >>> Knob("irange", 800, 10_000, step=100).allowed()
    'an integer or a pair [lo, hi] of integers, lo <= hi, in 800..10000, multiples of 100'
    >>> Knob("frange", 0, 1, open_lo=True).check("p", [0.2, 0.5])
    (0.2, 0.5)
    """

    kind: str
    lo: float = 0.0
    hi: float = 0.0
    open_lo: bool = False
    step: int = 1
    choices: tuple[str, ...] = ()
    doc: str = ""

    def allowed(self) -> str:
        """What the knob accepts, as the end of a "must be ..." sentence."""
        lo, hi = f"{self.lo:g}", f"{self.hi:g}"
        within = f"({lo}, {hi}]" if self.open_lo else f"{lo}..{hi}"
        steps = f", multiples of {self.step}" if self.step > 1 else ""
        return {
            "int": f"an integer in {within}{steps}",
            "float": f"a number in {within}",
            "optional": f"a number in {within}, or None",
            "choice": "one of " + ", ".join(map(repr, self.choices)),
            "irange": f"an integer or a pair [lo, hi] of integers, lo <= hi, in {within}{steps}",
            "frange": f"a number or a pair [lo, hi], lo <= hi, in {within}",
            "pair": f"a pair [lo, hi], lo <= hi, in {within}",
        }[self.kind]

    def short(self) -> str:
        """The allowed values in a few characters (a table cell).

        Examples
        --------
        >>> Knob("irange", 800, 10_000, step=100).short(), Knob("optional", 0, 1, open_lo=True).short()
        ('800..10000 (x100)', '(0, 1] or None')
        """
        if self.kind == "choice":
            return ", ".join(self.choices)
        lo, hi = _number(self.lo), _number(self.hi)
        text = f"({lo}, {hi}]" if self.open_lo else f"{lo}..{hi}"
        if self.step > 1:
            text += f" (x{self.step})"
        return text + (" or None" if self.kind == "optional" else "")

    def _one(self, v: Any, integer: bool) -> int | float | None:
        ok = is_integer(v) if integer else is_number(v) and math.isfinite(v)
        if not ok or not (self.lo < v if self.open_lo else self.lo <= v) or v > self.hi:
            return None
        if integer and v % self.step:
            return None
        return int(v) if integer else float(v)

    def check(self, name: str, value: Any, source: str | None = None) -> Any:
        """``value`` normalised (see the module docstring), or a
        :class:`~fcplan.errors.ScenarioError` naming ``name``."""
        out: Any = None
        if self.kind == "choice":
            out = value if isinstance(value, str) and value in self.choices else None
        elif self.kind == "optional" and value is None:
            return None
        elif self.kind in ("int", "float", "optional"):
            out = self._one(value, self.kind == "int")
        else:
            pair = value
            if self.kind != "pair" and not isinstance(value, (list, tuple)):
                pair = (value, value)
            if isinstance(pair, (list, tuple)) and len(pair) == 2:
                lo, hi = (self._one(v, self.kind == "irange") for v in pair)
                if lo is not None and hi is not None and lo <= hi:
                    out = (lo, hi)
        if out is None:
            raise ScenarioError(name, f"must be {self.allowed()}", got=value, source=source)
        return out


def knob(default: Any, kind: str, lo: float = 0.0, hi: float = 0.0, **spec: Any) -> Any:
    """A dataclass field with a default and a :class:`Knob` in its metadata (``spec`` gives
    ``open_lo``, ``step`` or ``choices``)."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    return field(default=default, metadata={"knob": Knob(kind, lo, hi, **spec)})


def check_knobs(obj: Any, source: str | None = None) -> None:
    """Validate and normalise, in place, every knob field of the dataclass instance ``obj``
    (frozen or not)."""
    for f in fields(obj):
        spec = f.metadata.get("knob")
        if spec is not None:
            object.__setattr__(obj, f.name, spec.check(f.name, getattr(obj, f.name), source))


def span(value: Any) -> tuple[Any, Any]:
    """``(lo, hi)`` of a range knob's value (a single number ``v`` gives ``(v, v)``).

    Examples
    --------
    >>> span((1, 4)), span(3)
    ((1, 4), (3, 3))
    """
    return (value[0], value[1]) if isinstance(value, tuple) else (value, value)


def _number(v: float) -> str:
    """``v`` in few characters: ``1e6`` rather than ``1e+06``."""
    return f"{v:g}".replace("e+0", "e").replace("e+", "e")


def knobs_of(cls: Any) -> dict[str, tuple[Knob, Any]]:
    """``{name: (Knob, default)}`` of every knob field of the dataclass ``cls``, in order."""
    return {f.name: (f.metadata["knob"], f.default) for f in fields(cls) if "knob" in f.metadata}


def _cell(value: Any) -> str:
    if isinstance(value, tuple) and len(value) == 2 and value[0] == value[1]:
        value = value[0]
    if isinstance(value, tuple):
        return "(" + ", ".join(_cell(v) for v in value) + ")"
    if isinstance(value, float):
        return _number(value)
    return repr(value) if isinstance(value, str) else str(value)


def knob_table(cls: Any) -> str:
    """The reStructuredText table of the knobs of ``cls``: name, default, allowed values, meaning.

    A settings class's docstring holds this table; a test checks that it is up to date.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Settings:
    ...     size: int | tuple[int, int] = knob((4, 4), "irange", 1, 10, doc="cells (range)")
    >>> print(knob_table(Settings))
    ====  =======  =======  =============
    knob  default  allowed  meaning
    ====  =======  =======  =============
    size  4        1..10    cells (range)
    ====  =======  =======  =============
    """
    rows = [("knob", "default", "allowed", "meaning")]
    rows += [(n, _cell(d), k.short(), k.doc) for n, (k, d) in knobs_of(cls).items()]
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    rule = "  ".join("=" * w for w in widths)

    def line(row: tuple[str, ...]) -> str:
        return "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip()

    return "\n".join([rule, line(rows[0]), rule, *map(line, rows[1:]), rule])
