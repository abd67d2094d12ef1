"""Read the 2020 GUI's pickles without running code, within bounds: :func:`restricted_loads`.

Nothing here calls :mod:`pickle`: :class:`~fcplan.legacy.machine.RestrictedUnpickler` interprets
the opcode stream itself and builds only ``None``, bools, numbers, strings, bytes, lists, tuples,
dicts, sets and numeric/bool/string numpy arrays, dtypes and scalars (object arrays only element
by element from built values). Any other global (``os.system``, ``builtins.eval``, a class) is
refused with :class:`~fcplan.errors.LegacyError` before it is looked up. Work and memory are
bounded by :class:`~fcplan.legacy.limits.LegacyLimits` (bytes per file, values built, tree size,
nesting, memo), and every failure, malformed or hostile, is a ``LegacyError`` naming the file.

:func:`restricted_load` reads a file only if it is a regular file no larger than the bound (a
FIFO or device named ``*.pkl`` is refused without blocking).

Examples
--------
>>> import pickle
>>> restricted_loads(pickle.dumps({"a": (1, 2.5)}))
{'a': (1, 2.5)}
>>> restricted_loads(b"not a pickle", source="x.pkl")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.LegacyError: x.pkl: not a readable pickle (...)
>>> restricted_loads(b"\\x80\\x02cos\\nsystem\\n.", source="x.pkl")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.LegacyError: x.pkl: refused to load os.system: ...
"""

from __future__ import annotations

import os
from typing import Any

from fcplan.errors import LegacyError
from fcplan.legacy.limits import DEFAULT_LIMITS, LegacyLimits
from fcplan.legacy.machine import RestrictedUnpickler
from fcplan.recording.reader import read_bytes

__all__ = ["RestrictedUnpickler", "restricted_load", "restricted_loads"]


def restricted_loads(
    data: bytes, source: str = "<bytes>", limits: LegacyLimits | None = None
) -> Any:
    """The plain value pickled in ``data``, or :class:`~fcplan.errors.LegacyError` naming
    ``source``."""
    return RestrictedUnpickler(data, source=source, limits=limits).load()


def restricted_load(path: str | os.PathLike[str], limits: LegacyLimits | None = None) -> Any:
    """Read one file with :func:`restricted_loads` (a regular file within ``limits.max_bytes``)."""
    path = os.fspath(path)
    limits = limits or DEFAULT_LIMITS
    data = read_bytes(path, LegacyError, limits.max_bytes)
    return restricted_loads(data, source=path, limits=limits)
