"""The restricted unpickler: read the 2020 GUI's pickles without running code.

:class:`RestrictedUnpickler` builds lists, tuples, dicts, numbers and strings as usual and admits
exactly the few numpy globals that rebuild arrays, dtypes and numpy scalars (and latin-1 bytes of
protocol-2 pickles); any other global (``os.system``, ``builtins.eval``, a class) is refused with
:class:`~fcplan.errors.LegacyError` before it is looked up, so it is never executed. Persistent
references are refused too.

Examples
--------
>>> import pickle
>>> restricted_loads(pickle.dumps({"a": (1, 2.5)}))
{'a': (1, 2.5)}
>>> restricted_loads(b"not a pickle", source="x.pkl")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.LegacyError: x.pkl: not a readable pickle (...)
"""

from __future__ import annotations

import io
import os
import pickle
from typing import Any

import numpy as np

from fcplan.errors import LegacyError

__all__ = ["RestrictedUnpickler", "restricted_load", "restricted_loads"]


def _numpy_globals() -> dict[tuple[str, str], Any]:
    """The only globals a pickle may name: what numpy arrays, dtypes and scalars need."""
    try:
        from numpy._core import multiarray
    except ImportError:  # pragma: no cover - numpy < 2
        from numpy.core import multiarray  # type: ignore[no-redef]
    allowed: dict[tuple[str, str], Any] = {
        ("numpy", "ndarray"): np.ndarray,
        ("numpy", "dtype"): np.dtype,
        ("_codecs", "encode"): _latin1_encode,  # bytes in protocol-2 pickles
        ("builtins", "bytes"): _small_bytes,  # b"" in protocol-2 pickles
        ("__builtin__", "bytes"): _small_bytes,
    }
    for mod in ("numpy.core.multiarray", "numpy._core.multiarray"):
        allowed[(mod, "_reconstruct")] = multiarray._reconstruct
        allowed[(mod, "scalar")] = multiarray.scalar
    return allowed


def _latin1_encode(text: str, encoding: str = "latin1") -> bytes:
    if not isinstance(text, str) or encoding not in ("latin1", "latin-1"):
        raise pickle.UnpicklingError("_codecs.encode is only admitted for latin1 text")
    return text.encode("latin1")


def _small_bytes(*args: Any) -> bytes:
    if args:
        raise pickle.UnpicklingError("bytes() is only admitted without arguments")
    return b""


_ALLOWED = _numpy_globals()


class RestrictedUnpickler(pickle.Unpickler):
    """An unpickler that admits only lists, tuples, dicts, numbers, strings and numpy arrays.

    ``find_class`` is the only way a pickle reaches a callable; here it returns numpy's array,
    dtype and scalar reconstructors and refuses every other name (without importing it).
    Persistent ids are refused too.
    """

    source = "<bytes>"

    def find_class(self, module: str, name: str) -> Any:
        obj = _ALLOWED.get((module, name))
        if obj is None:
            raise LegacyError(
                f"{self.source}: refused to load {module}.{name}: legacy files may only hold "
                "lists, tuples, numbers, strings and numpy arrays"
            )
        return obj

    def persistent_load(self, pid: Any) -> Any:
        raise LegacyError(f"{self.source}: refused a persistent reference in the pickle")


def restricted_loads(data: bytes, source: str = "<bytes>") -> Any:
    """Unpickle ``data`` with :class:`RestrictedUnpickler`; refuse anything but plain data."""
    up = RestrictedUnpickler(io.BytesIO(data), encoding="latin1")
    up.source = source
    try:
        return up.load()
    except LegacyError:
        raise
    except Exception as exc:  # truncated or malformed pickles raise many types
        raise LegacyError(
            f"{source}: not a readable pickle ({type(exc).__name__}: {exc})"
        ) from None


def restricted_load(path: str | os.PathLike) -> Any:
    """Read one file with :func:`restricted_loads`."""
    from fcplan.recording import _read_bytes

    path = os.fspath(path)
    return restricted_loads(_read_bytes(path, LegacyError), source=path)
