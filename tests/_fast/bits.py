"""Helpers of the kernel equivalence tests in ``tests/_fast``: exact bytes of values."""

from __future__ import annotations

from typing import Any

import numpy as np


def bits(a: Any) -> bytes:
    """Exact bytes of an array (dtype, shape and data: ``-0.0`` and ``0.0`` differ, so do NaN
    payloads), so ``bits(a) == bits(b)`` means bit-identical."""
    a = np.asarray(a)
    return a.dtype.str.encode() + str(a.shape).encode() + np.ascontiguousarray(a).tobytes()
