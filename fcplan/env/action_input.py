"""Actions from a learner: integer arrays of a known shape, checked at the env's boundary.

Every discrete fcplan env takes integer actions. A policy's output often arrives as floats (an
array made with ``np.zeros``, a tensor of sampled indices cast to float): whole-valued floats are
accepted as the integers they hold, but a fractional or non-finite value is an error, where
``np.asarray(a, dtype=np.int64)`` alone would truncate ``1.7`` to ``1`` in silence. The array
views (``fcplan/Motion-v0``, ``fcplan/Task-v0`` and the batched envs) check a whole array with
:func:`integer_actions`; the PettingZoo task env checks each agent's value with
:func:`integer_action`. (The PettingZoo motion env indexes its action tables with the value
itself, so it takes Python or numpy integers only.)

Examples
--------
>>> integer_actions(np.array([[0.0, 2.0]]), (1, 2)).tolist()
[[0, 2]]
>>> integer_actions([1.5, 0], (2,))
Traceback (most recent call last):
...
fcplan.errors.EnvError: actions[0]: must be a whole number (got 1.5)
"""

from __future__ import annotations

import operator
from typing import Any

import numpy as np

from fcplan.errors import EnvError

__all__ = ["integer_actions", "integer_action"]


def integer_actions(actions: Any, shape: tuple[int, ...], name: str = "actions") -> np.ndarray:
    """``actions`` as an int64 array of ``shape``: integers, or floats of whole values.

    Raises
    ------
    EnvError
        For another shape, a value that is not a number, or a fractional or non-finite one
        (the first such entry is named).
    """
    try:
        raw = np.asarray(actions)
        if raw.dtype.kind == "O":
            raw = raw.astype(np.float64)
        raw = raw.reshape(shape)
    except (TypeError, ValueError):
        raise EnvError(f"{name}: must be integers of shape {shape}") from None
    kind = raw.dtype.kind
    if kind in "iub":
        return raw.astype(np.int64, copy=False)
    if kind != "f":
        raise EnvError(f"{name}: must be integers of shape {shape} (got {raw.dtype} values)")
    bad = ~np.isfinite(raw) | (raw != np.trunc(raw))
    if np.count_nonzero(bad):
        at = tuple(int(k[0]) for k in np.nonzero(bad))
        where = ", ".join(map(str, at))
        raise EnvError(f"{name}[{where}]: must be a whole number (got {float(raw[at])!r})")
    return raw.astype(np.int64)


def integer_action(value: Any, name: str) -> int:
    """One agent's action as an int: an integer, or a float of a whole value.

    >>> integer_action(np.float32(3.0), "action of uav_0")
    3
    """
    try:
        return operator.index(value)
    except TypeError:
        pass
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise EnvError(f"{name}: must be an integer (got {value!r})") from None
    if not (np.isfinite(f) and f == int(f)):
        raise EnvError(f"{name}: must be a whole number (got {value!r})")
    return int(f)
