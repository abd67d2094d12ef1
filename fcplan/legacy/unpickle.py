"""Read the 2020 GUI's pickles without running code, within bounds: :func:`restricted_loads`.

Nothing here calls :mod:`pickle`: :class:`~fcplan.legacy.machine.RestrictedUnpickler` interprets
the opcode stream itself and builds only ``None``, bools, numbers, strings, bytes, lists, tuples,
dicts, sets and numeric/bool/string numpy arrays, dtypes and scalars (object arrays only element
by element from built values). Any other global (``os.system``, ``builtins.eval``, a class) is
refused with :class:`~fcplan.errors.LegacyError` before it is looked up. Work and memory are
bounded by :class:`~fcplan.legacy.limits.LegacyLimits` (bytes per file, values built, tree size,
nesting, memo), and every failure, malformed or hostile, is a ``LegacyError`` naming the file.

:func:`read_regular_file` reads a file only if it is a regular file no larger than the bound (a
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
import stat
from typing import Any

from fcplan.errors import LegacyError
from fcplan.legacy.limits import DEFAULT_LIMITS, LegacyLimits
from fcplan.legacy.machine import RestrictedUnpickler

__all__ = ["RestrictedUnpickler", "read_regular_file", "restricted_load", "restricted_loads"]


def restricted_loads(
    data: bytes, source: str = "<bytes>", limits: LegacyLimits | None = None
) -> Any:
    """The plain value pickled in ``data``, or :class:`~fcplan.errors.LegacyError` naming
    ``source``."""
    return RestrictedUnpickler(data, source=source, limits=limits).load()


def read_regular_file(path: str, max_bytes: int, error: type[Exception] = LegacyError) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``max_bytes`` bytes.

    The file is opened without blocking (a FIFO has no writer to wait for), checked with
    ``fstat`` and read up to one byte past the bound, so neither a special file nor a huge one
    costs time or memory. Failures raise ``error`` naming the file.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{path}: not a regular file")
        if st.st_size > max_bytes:
            raise error(f"{path}: {st.st_size} bytes exceeds the bound of {max_bytes}")
        chunks, total = [], 0
        while chunk := os.read(fd, min(1 << 20, max_bytes + 1 - total)):
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:
                raise error(f"{path}: grew past the bound of {max_bytes} bytes while read")
        return b"".join(chunks)
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None
    finally:
        os.close(fd)


def restricted_load(path: str | os.PathLike[str], limits: LegacyLimits | None = None) -> Any:
    """Read one file with :func:`restricted_loads` (a regular file within ``limits.max_bytes``)."""
    path = os.fspath(path)
    limits = limits or DEFAULT_LIMITS
    return restricted_loads(read_regular_file(path, limits.max_bytes), source=path, limits=limits)
