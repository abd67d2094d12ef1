"""Tests of fcplan.scenario.knobs: typed, range-checked dataclass fields."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from fcplan.scenario import ScenarioError
from fcplan.scenario.knobs import KINDS, Knob, check_knobs, knob, span


@dataclass
class Settings:
    count: int | tuple[int, int] = knob(2, "irange", 0, 10)
    side: int = knob(800, "int", 800, 2000, step=100)
    rate: float = knob(0.5, "float", 0, 1, open_lo=True)
    limit: float | None = knob(None, "optional", 0, 100)
    mode: str = knob("a", "choice", choices=("a", "b"))
    bounds: tuple[float, float] = knob((1.0, 2.0), "pair", 0, 5)

    def __post_init__(self) -> None:
        check_knobs(self, source="test")


def test_values_are_normalised():
    """Normalisation: scalars of a range kind become (v, v), lists tuples, numpy scalars and ints
    plain int/float."""
    s = Settings(count=np.int64(3), rate=1, limit=np.float32(7), bounds=[0, 5])
    assert s.count == (3, 3) and type(s.count[0]) is int
    assert s.rate == 1.0 and type(s.rate) is float
    assert s.limit == 7.0 and type(s.limit) is float
    assert s.bounds == (0.0, 5.0)
    assert Settings(limit=None).limit is None


@pytest.mark.parametrize(
    ("field", "value", "allowed"),
    [
        ("count", 11, "an integer or a pair [lo, hi] of integers, lo <= hi, in 0..10"),
        ("count", (5, 4), "an integer or a pair [lo, hi] of integers, lo <= hi, in 0..10"),
        ("count", 2.0, "an integer or a pair [lo, hi] of integers, lo <= hi, in 0..10"),
        ("side", 850, "an integer in 800..2000, multiples of 100"),
        ("rate", 0, "a number in (0, 1]"),
        ("rate", math.inf, "a number in (0, 1]"),
        ("rate", True, "a number in (0, 1]"),
        ("limit", "3", "a number in 0..100, or None"),
        ("mode", "c", "one of 'a', 'b'"),
        ("bounds", 3.0, "a pair [lo, hi], lo <= hi, in 0..5"),
    ],
)
def test_bad_values_raise_one_line_errors_naming_the_field_and_range(field, value, allowed):
    """Errors: one line '<source>: <field>: must be <allowed> (got <value>)'."""
    with pytest.raises(ScenarioError) as info:
        Settings(**{field: value})
    assert str(info.value) == f"test: {field}: must be {allowed} (got {value!r})"


def test_unknown_kind_is_a_programming_error():
    """Declaring a knob of an unknown kind fails at class definition time."""
    with pytest.raises(ValueError, match="kind must be one of"):
        knob(1, "integer")
    assert set(KINDS) >= {Knob("int").kind, Knob("pair").kind}


def test_span_of_scalars_and_pairs():
    """span gives (lo, hi) for both stored forms."""
    assert span((1, 4)) == (1, 4) and span(2.5) == (2.5, 2.5)
