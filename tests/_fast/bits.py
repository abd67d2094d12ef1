"""Helpers of the equivalence tests (``tests/_fast``, the batched and copied envs): exact bytes of
values, and exact equality of nested results."""

from __future__ import annotations

from typing import Any

import numpy as np


def bits(a: Any) -> bytes:
    """Exact bytes of an array (dtype, shape and data: ``-0.0`` and ``0.0`` differ, so do NaN
    payloads), so ``bits(a) == bits(b)`` means bit-identical."""
    a = np.asarray(a)
    return a.dtype.str.encode() + str(a.shape).encode() + np.ascontiguousarray(a).tobytes()


def same_values(a: Any, b: Any) -> bool:
    """Equal values: arrays bit for bit (:func:`bits`); tuples, lists, dicts and object arrays
    element by element; anything else by ``==``."""
    if isinstance(a, tuple | list):
        return len(a) == len(b) and all(same_values(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return (
            isinstance(b, dict) and a.keys() == b.keys() and all(same_values(a[k], b[k]) for k in a)
        )
    if isinstance(a, np.ndarray) and a.dtype == object:
        return a.shape == b.shape and all(same_values(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and bits(a) == bits(b)
    return bool(a == b)
