"""Range lists of the command line: ``1-24``, ``1,3,5-7``, ``practice,1-3``.

``fcplan compare`` and friends take scenarios and seeds as comma-separated lists of integers,
inclusive integer ranges and (for scenarios) names or paths. :func:`parse_range` reads them, in
the order given and without duplicates; a malformed list is a one-line :class:`RangeError`.

Examples
--------
>>> parse_range("practice,1-3,2")
['practice', 1, 2, 3]
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from fcplan.errors import FcplanError

__all__ = ["RangeError", "parse_range"]

_MAX_RANGE = 100_000


class RangeError(FcplanError, ValueError):
    """A range list such as ``"1-24"`` or ``"0,2,5-7"`` is malformed."""


def parse_range(text: str, *, names: bool = True) -> list[int | str]:
    """Read a comma-separated list of integers, inclusive ranges and (optionally) names.

    Parameters
    ----------
    text : str
        e.g. ``"1-24"``, ``"1,3,5-7"``, ``"practice,1-3"``, ``"0"``.
    names : bool
        Accept items that are not integers (scenario names or paths) and return them as strings.
        With ``names=False`` (seeds) every item must be an integer >= 0 or a range ``a-b``.

    Returns
    -------
    list of int or str
        In the order given, duplicates removed.

    Raises
    ------
    RangeError
        An empty list or item, a descending range (``5-3``), a range of more than 100000 items, or
        (``names=False``) an item that is not a non-negative integer or range.

    Examples
    --------
    >>> parse_range("1-4")
    [1, 2, 3, 4]
    >>> parse_range("practice, 1,3,5-7, 3")
    ['practice', 1, 3, 5, 6, 7]
    >>> parse_range("a-b", names=False)
    Traceback (most recent call last):
    ...
    fcplan.experiments.ranges.RangeError: expected an integer >= 0 or a range like 0-4, got 'a-b'
    """
    if not isinstance(text, str):
        raise RangeError(f"expected a string like '1-24' or '1,3,5-7', got {text!r}")
    out: list[int | str] = []
    seen: set[int | str] = set()
    items = [t.strip() for t in text.split(",")]
    if not text.strip() or any(not t for t in items):
        raise RangeError(f"empty item in {text!r}; expected e.g. '1-24' or '1,3,5-7'")
    for item in items:
        if re.fullmatch(r"\d+", item):
            values: Iterable[int | str] = [int(item)]
        elif m := re.fullmatch(r"(\d+)\s*-\s*(\d+)", item):
            lo, hi = int(m.group(1)), int(m.group(2))
            if lo > hi:
                raise RangeError(f"empty range {item!r}: {lo} > {hi}")
            if hi - lo + 1 > _MAX_RANGE:
                raise RangeError(f"range {item!r} has more than {_MAX_RANGE} items")
            values = range(lo, hi + 1)
        elif names:
            values = [item]
        else:
            raise RangeError(f"expected an integer >= 0 or a range like 0-4, got {item!r}")
        for v in values:
            if v not in seen:
                seen.add(v)
                out.append(v)
    return out
