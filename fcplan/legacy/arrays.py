"""numpy values rebuilt from plain data: the only non-builtin values a legacy pickle may hold.

numpy pickles an array as calls of a few module functions with plain arguments (protocols 0-4:
``_reconstruct(ndarray, (0,), b"b")`` then ``__setstate__((1, shape, dtype, is_fortran, raw))``;
protocol 5: ``_frombuffer(raw, dtype, shape, order)``; scalars: ``scalar(dtype, raw)``; dtypes:
``dtype(typestr, False, True)`` then ``__setstate__((3, byteorder, ...))``). The legacy reader
never calls those functions: it hands their plain arguments to the builders here, which

* accept only the dtypes of :data:`DTYPE_RE` (bool, integers, floats, complex, fixed-width
  strings, and the object dtype), composed from the validated parts, never from a raw string;
* check the shape (non-negative ints, at most ``max_depth`` dimensions, ``prod(shape)`` within the
  element bound) and that the payload has exactly ``prod(shape) * itemsize`` bytes *before*
  allocating anything;
* build an object array only from a list of already-built plain values, element by element; an
  object array (or object scalar) from raw bytes is refused, because its bytes would be read as
  pointers (a 60-byte pickle could make numpy dereference any address);
* return arrays that own their data (a copy of the payload), bool arrays normalised to 0/1, string
  arrays checked for valid code points.

Examples
--------
>>> dt = build_dtype(("f8", False, True))
>>> set_dtype_state(dt, (3, "<", None, None, None, -1, -1, 0))
dtype('float64')
>>> build_array(b"\\x00" * 16, dt, (2,), False, cap=10).tolist()
[0.0, 0.0]
>>> build_array(b"AAAAAAAA", build_dtype(("O8", False, True)), (1,), False, cap=10)
Traceback (most recent call last):
...
fcplan.legacy.arrays.RefusedError: an object array from raw bytes (its bytes would be read as pointers)
"""

from __future__ import annotations

import functools
import math
import re
from typing import Any

import numpy as np

__all__ = [
    "DTYPE_RE",
    "RefusedError",
    "build_array",
    "build_dtype",
    "build_scalar",
    "set_dtype_state",
]

#: The dtype strings a pickle may name (numpy's ``typestr`` without byte order).
DTYPE_RE = re.compile(r"(b1|[iu][1248]|f(2|4|8|16)|c(8|16|32)|[US][0-9]{1,7}|O8)")
_MAX_ITEMSIZE = 2**20
_MAX_NDIM = 32


class RefusedError(Exception):
    """A reason to refuse the file (the reader adds the file's name)."""


def build_dtype(args: Any) -> np.dtype:
    """The dtype of ``numpy.dtype(typestr, align, copy)``'s arguments, if allowed."""
    if not (isinstance(args, tuple) and 1 <= len(args) <= 3 and isinstance(args[0], str)):
        raise RefusedError(
            f"numpy.dtype arguments must be (typestr, align, copy), got {args!r:.60}"
        )
    return _dtype_of(args[0])


@functools.lru_cache(maxsize=64)
def _dtype_of(typestr: str) -> np.dtype:
    if not DTYPE_RE.fullmatch(typestr):
        raise RefusedError(f"dtype {typestr!r:.40} is not a plain numeric, bool or string dtype")
    dt = np.dtype(typestr)
    if dt.itemsize > _MAX_ITEMSIZE:
        raise RefusedError(f"dtype {typestr!r} has items of more than {_MAX_ITEMSIZE} bytes")
    return dt


def set_dtype_state(dt: np.dtype, state: Any) -> np.dtype:
    """``dt`` with the byte order (and string width) of a dtype ``__setstate__`` tuple."""
    if not (isinstance(state, tuple) and len(state) in (8, 9) and state[0] in (3, 4)):
        raise RefusedError(f"unexpected dtype state {state!r:.60}")
    if len(state) == 9 and state[8] not in (None, {}):
        raise RefusedError("dtype metadata is refused")
    if not all(v is None or type(v) in (int, str) for v in state[:8]):
        raise RefusedError("structured and sub-array dtypes are refused")
    return _with_state(dt, state[:8])


@functools.lru_cache(maxsize=64)
def _with_state(dt: np.dtype, state: tuple[Any, ...]) -> np.dtype:
    order, subarray, names, fields, elsize = state[1:6]
    if subarray is not None or names is not None or fields is not None:
        raise RefusedError("structured and sub-array dtypes are refused")
    if order not in ("<", ">", "|", "="):
        raise RefusedError(f"dtype byte order {order!r:.20}")
    if dt.kind in "US" and isinstance(elsize, int) and elsize > 0 and elsize != dt.itemsize:
        if elsize > _MAX_ITEMSIZE or (dt.kind == "U" and elsize % 4):
            raise RefusedError(f"string dtype of {elsize!r} bytes")
        dt = np.dtype(f"{dt.kind}{elsize // 4 if dt.kind == 'U' else elsize}")
    new = dt.newbyteorder(order) if order in "<>" else dt
    return dt if new == dt else new  # (native order: numpy's own dtype object)


def _payload(raw: Any, what: str) -> bytes:
    """Bytes of a payload: bytes, bytearray, or the latin-1 text of protocol 0-2 pickles."""
    if isinstance(raw, (bytes, bytearray)):
        return bytes(raw)
    if isinstance(raw, str):
        try:
            return raw.encode("latin1")
        except UnicodeEncodeError:
            raise RefusedError(f"{what}: text payload is not latin-1") from None
    raise RefusedError(f"{what}: payload must be bytes, got {type(raw).__name__}")


def _check_shape(shape: Any, cap: int) -> int:
    """The number of elements of a shape tuple, checked against ``cap`` before any allocation."""
    if not isinstance(shape, tuple) or len(shape) > _MAX_NDIM:
        raise RefusedError(
            f"array shape must be a tuple of at most {_MAX_NDIM} ints, got {shape!r:.60}"
        )
    if not all(type(d) is int and d >= 0 for d in shape):
        raise RefusedError(f"array shape must hold ints >= 0, got {shape!r:.60}")
    size = math.prod(shape)
    if size > cap:
        raise RefusedError(f"array of {size} elements exceeds the bound of {cap}")
    return size


def _clean(a: np.ndarray) -> np.ndarray:
    """Bool arrays as 0/1; string arrays must hold valid code points."""
    if a.dtype.kind == "b":
        return a.view(np.uint8) != 0
    if a.dtype.kind == "U" and a.size:
        codes = a.view(a.dtype.byteorder.replace("=", "") + "u4")
        bad = (codes > 0x10FFFF) | ((codes >= 0xD800) & (codes < 0xE000))
        if bad.any():
            raise RefusedError("string array holds invalid code points")
    return a


def build_array(
    raw: Any, dt: Any, shape: Any, fortran: Any, *, cap: int, native: bool = False
) -> np.ndarray:
    """The array of a pickled ``(shape, dtype, is_fortran, raw)`` state, checked before allocating.

    ``raw`` is the payload bytes for a plain dtype, or a list of built values for the object
    dtype (in C order, as numpy writes it). ``native``: convert to native byte order, as numpy's
    ``__setstate__`` does (protocol 5's ``_frombuffer`` keeps the order).
    """
    if not isinstance(dt, np.dtype):
        raise RefusedError(f"array dtype must be a numpy dtype, got {type(dt).__name__}")
    if not isinstance(fortran, bool):
        raise RefusedError("array order flag must be a bool")
    size = _check_shape(shape, cap)
    if dt.kind == "O":
        if not isinstance(raw, list):
            raise RefusedError(
                "an object array from raw bytes (its bytes would be read as pointers)"
            )
        if len(raw) != size:
            raise RefusedError(f"object array of shape {shape} holds {len(raw)} values")
        out = np.empty(size, dtype=object)
        for i, v in enumerate(raw):
            out[i] = v
        out = out.reshape(shape)
        return np.asfortranarray(out) if fortran and out.ndim > 1 else out
    if not DTYPE_RE.fullmatch(dt.str[1:]) or dt.itemsize == 0:
        raise RefusedError(f"array dtype {dt.str!r} is not allowed")
    data = _payload(raw, "array")
    if len(data) != size * dt.itemsize:
        raise RefusedError(
            f"array payload has {len(data)} bytes, shape {shape} of {dt} needs {size * dt.itemsize}"
        )
    flat = np.frombuffer(data, dtype=dt, count=size) if size else np.empty(0, dt)
    out = flat.reshape(shape, order="F" if fortran else "C")
    if native and not dt.isnative:
        return _clean(out.astype(dt.newbyteorder("="), order="K"))
    return _clean(out.copy(order="K"))


def build_scalar(dt: Any, raw: Any) -> Any:
    """The numpy scalar of ``scalar(dtype, raw)``; object scalars are refused."""
    if not isinstance(dt, np.dtype) or dt.kind == "O" or dt.itemsize == 0:
        raise RefusedError("a numpy scalar must have a plain numeric, bool or string dtype")
    data = _payload(raw, "scalar")
    if len(data) != dt.itemsize:
        raise RefusedError(f"scalar payload has {len(data)} bytes, {dt} needs {dt.itemsize}")
    one = np.frombuffer(data, dtype=dt, count=1)
    return (_clean(one) if dt.kind in "bU" else one)[0]  # (a scalar: a copy)
