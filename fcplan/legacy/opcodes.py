"""The pickle opcodes the legacy reader knows, from :mod:`pickletools`' table (no code runs).

:data:`OPCODES` maps each opcode byte to its name and :mod:`pickletools` argument reader (which
decodes an argument from the stream and executes nothing); protocol-0 ``STRING`` arguments are
decoded as latin-1, as :mod:`pickle` does with ``encoding="latin1"``. :data:`GLOBALS` are the only
names a pickle may refer to; :data:`REFUSED_OPS` the opcodes refused outright. The upper-case
codes (:data:`INLINE_CODES`) are the opcodes the interpreter's loop handles inline.

Examples
--------
>>> OPCODES[ord("G")][0], GLOBALS[("numpy", "dtype")]
('BINFLOAT', 'dtype')
>>> leaf_weight("x" * 80), leaf_weight(2.5)
(11, 1)
"""

from __future__ import annotations

import codecs
import pickletools
import struct
import warnings
from collections.abc import Callable
from typing import IO, Any

__all__ = ["GLOBALS", "OPCODES", "REFUSED_OPS", "MalformedError", "leaf_weight"]

#: The only globals a pickle may name, and the builder each stands for.
GLOBALS: dict[tuple[str, str], str] = {
    ("numpy", "ndarray"): "ndarray",
    ("numpy", "dtype"): "dtype",
    ("_codecs", "encode"): "encode",
    ("builtins", "bytes"): "bytes",
    ("__builtin__", "bytes"): "bytes",
    **{(f"numpy.{c}.multiarray", "_reconstruct"): "reconstruct" for c in ("core", "_core")},
    **{(f"numpy.{c}.multiarray", "scalar"): "scalar" for c in ("core", "_core")},
    **{(f"numpy.{c}.numeric", "_frombuffer"): "frombuffer" for c in ("core", "_core")},
}


class MalformedError(ValueError):
    """The opcode stream is not a well-formed pickle."""


#: leaf types whose weight depends on their size (every other leaf weighs 1)
SIZED_TYPES = frozenset((str, bytes, bytearray, int))


def leaf_weight(x: Any) -> int:
    if isinstance(x, (str, bytes, bytearray)):
        return 1 + len(x) // 8
    if type(x) is int:
        return 1 + x.bit_length() // 64
    return 1


def _read_stringnl_latin1(f: IO[bytes]) -> str:
    """Protocol-0 ``STRING`` argument as latin-1 text (pickletools decodes it as ASCII only)."""
    data = f.readline()
    if not data.endswith(b"\n") or len(data) < 3 or data[0] not in b"'\"" or data[-2] != data[0]:
        raise MalformedError("STRING argument is not a quoted line")
    with warnings.catch_warnings():  # (invalid escapes warn; they decode as pickle decodes them)
        warnings.simplefilter("ignore", DeprecationWarning)
        return codecs.escape_decode(data[1:-2])[0].decode("latin1")


def _opcode_table() -> dict[int, tuple[str, Callable[[IO[bytes]], Any] | None]]:
    table: dict[int, tuple[str, Callable[[IO[bytes]], Any] | None]] = {}
    for op in pickletools.opcodes:
        reader = None if op.arg is None else op.arg.reader
        if op.name == "STRING":
            reader = _read_stringnl_latin1
        table[ord(op.code)] = (op.name, reader)
    return table


OPCODES = _opcode_table()
BINFLOAT, BININT1, BININT, BINGET, LONG_BINGET, SHORT_BINUNICODE, SHORT_BINBYTES = b"GKJhj\x8cC"
BINPUT, LONG_BINPUT, MEMOIZE = b"qr\x94"
PUT_CODES = frozenset((BINPUT, LONG_BINPUT, MEMOIZE))
INLINE_CODES = frozenset(
    (BINFLOAT, BININT1, BININT, BINGET, LONG_BINGET, SHORT_BINUNICODE, SHORT_BINBYTES, *PUT_CODES)
)
F8, I4, U4 = struct.Struct(">d"), struct.Struct("<i"), struct.Struct("<I")
REFUSED_OPS = {
    "PERSID": "a persistent reference",
    "BINPERSID": "a persistent reference",
    "OBJ": "an object construction (OBJ)",
    "NEWOBJ": "an object construction (NEWOBJ)",
    "NEWOBJ_EX": "an object construction (NEWOBJ_EX)",
    "EXT1": "an extension-registry reference",
    "EXT2": "an extension-registry reference",
    "EXT4": "an extension-registry reference",
    "NEXT_BUFFER": "an out-of-band buffer",
    "READONLY_BUFFER": "an out-of-band buffer",
}
