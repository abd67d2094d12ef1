"""Tests for fcplan.experiments.ranges: the CLI's range lists."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.errors import FcplanError
from fcplan.experiments.compare import RangeError as CompareRangeError
from fcplan.experiments.ranges import RangeError, parse_range


def test_parse_range_cases():
    """Single numbers, inclusive ranges, lists, names and duplicates parse in the order given."""
    assert parse_range("1-24") == list(range(1, 25))
    assert parse_range("1,3,5-7") == [1, 3, 5, 6, 7]
    assert parse_range("practice") == ["practice"]
    assert parse_range(" practice , 2-3, 2 ") == ["practice", 2, 3]
    assert parse_range("0", names=False) == [0]
    assert parse_range("4-4", names=False) == [4]


@pytest.mark.parametrize(
    ("text", "names", "match"),
    [
        ("", True, "empty item"),
        ("1,,2", True, "empty item"),
        ("5-3", True, "empty range"),
        ("a-b", False, "integer >= 0"),
        ("-1", False, "integer >= 0"),
        ("1.5", False, "integer >= 0"),
        ("0-100000000", False, "more than"),
    ],
)
def test_parse_range_errors(text, names, match):
    """Malformed lists raise RangeError (an FcplanError and a ValueError) naming the problem."""
    with pytest.raises(RangeError, match=match) as info:
        parse_range(text, names=names)
    assert isinstance(info.value, FcplanError) and isinstance(info.value, ValueError)


@given(st.lists(st.integers(0, 500), min_size=1, max_size=20))
def test_parse_range_reads_back_joined_lists(values):
    """Joining integers with commas and parsing gives them back, first occurrences only."""
    assert parse_range(",".join(map(str, values)), names=False) == list(dict.fromkeys(values))


def test_old_import_path_is_the_same_error():
    """fcplan.experiments.compare still exports the RangeError that parse_range raises."""
    assert CompareRangeError is RangeError
