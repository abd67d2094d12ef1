"""Tests of fcplan.legacy.machine and fcplan.legacy.arrays: the opcode interpreter builds what
pickle.loads builds for plain data and numpy values, refuses everything else, and stays within
its bounds."""

from __future__ import annotations

import contextlib
import os
import pickle
import struct

import numpy as np
import pytest

from fcplan.legacy import LegacyError, LegacyLimits, restricted_load, restricted_loads


def same(a, b) -> bool:
    """Equal values of the same types (arrays: dtype, shape, memory order, values, NaN = NaN)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        if (a.dtype, a.shape, a.flags.f_contiguous) != (b.dtype, b.shape, b.flags.f_contiguous):
            return False
        if a.dtype.kind == "O":
            return all(same(x, y) for x, y in zip(a.ravel(), b.ravel(), strict=True))
        return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return list(a) == list(b) and all(same(a[k], b[k]) for k in a)
    if isinstance(a, float) and a != a:
        return b != b
    return bool(a == b)


NUMPY_VALUES = [
    np.arange(6.0).reshape(2, 3),
    np.arange(6.0).reshape(2, 3).T,  # Fortran order
    np.array([True, False]),
    *(np.arange(3, dtype=t) for t in ("i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8")),
    *(np.array([1.5, np.nan], dtype=t) for t in ("f2", "f4", "f8", ">f8")),
    np.array([1 + 2j], dtype="c16"),
    np.array(["ab", "c"]),
    np.array([b"ab", b"c"]),
    np.array(3.5),
    np.zeros((0, 4)),
    np.array([[1, "a"], [2.5, None]], dtype=object).T,
    np.float64(2.5),
    np.int16(-3),
    np.bool_(True),
    np.str_("x"),
    [np.float32(1.5), np.uint8(7)],
]


@pytest.mark.parametrize("protocol", range(6))
def test_numpy_values_equal_what_pickle_builds(protocol):
    """Arrays of every plain dtype (either memory order, 0-d, empty, big-endian), object arrays
    and numpy scalars load as pickle.loads loads them, in every protocol 0-5."""
    for value in NUMPY_VALUES:
        data = pickle.dumps(value, protocol=protocol)
        got, want = restricted_loads(data), pickle.loads(data)
        assert same(got, want), (protocol, value)


def _evil(dtype_str: bytes, payload: bytes) -> bytes:
    """_reconstruct + __setstate__ of a (1,) array of ``dtype_str`` from raw ``payload``."""
    return (
        b"cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\n)U\x01b\x87R(K\x01K\x01\x85"
        b"cnumpy\ndtype\nU" + bytes([len(dtype_str)]) + dtype_str + b"\x89\x88\x87R"
        b"(K\x03U\x01|NNNJ\xff\xff\xff\xffJ\xff\xff\xff\xffK?tb\x89U"
        + bytes([len(payload)])
        + payload
        + b"tb."
    )


def test_object_arrays_from_raw_bytes_are_refused():
    """An object array built from raw bytes (whose element would be read as a pointer: issue 15)
    is refused, by __setstate__ and by protocol 5's _frombuffer; so is an object scalar; other
    dtypes outside the allow-list (datetime, void, structured) are refused by name."""
    with pytest.raises(LegacyError, match="object array from raw bytes"):
        restricted_loads(_evil(b"O8", b"AAAAAAAA"), source="evil.pkl")
    assert restricted_loads(_evil(b"i8", struct.pack("<q", 7))).tolist() == [7]
    for dt in (b"M8", b"V8", b"m8"):
        with pytest.raises(LegacyError, match="not a plain"):
            restricted_loads(_evil(dt, b"AAAAAAAA"))
    frombuffer = (
        b"\x80\x05cnumpy._core.numeric\n_frombuffer\n(C\x08AAAAAAAAcnumpy\ndtype\nX\x02\x00\x00"
        b"\x00O8\x89\x88\x87RK\x01\x85X\x01\x00\x00\x00Ct\x94R."
    )
    with pytest.raises(LegacyError, match="object array from raw bytes"):
        restricted_loads(frombuffer)
    scalar = (
        b"cnumpy.core.multiarray\nscalar\ncnumpy\ndtype\nU\x02O8\x89\x88\x87RU\x08AAAAAAAA\x86R."
    )
    with pytest.raises(LegacyError, match="plain numeric"):
        restricted_loads(scalar)


def test_payload_and_shape_are_checked_before_allocating():
    """A payload shorter or longer than shape x itemsize, a negative dimension, and a shape
    larger than the element bound are refused (nothing of that size is allocated)."""
    good = pickle.dumps(np.arange(4, dtype="i8"), protocol=2)
    i = good.index(b"K\x04\x85")  # shape (4,)
    for shape, match in [
        (b"K\x05\x85", "payload has 32 bytes"),
        (b"J\xff\xff\xff\xff\x85", "ints >= 0"),
    ]:
        with pytest.raises(LegacyError, match=match):
            restricted_loads(good[:i] + shape + good[i + 3 :])
    huge = good[:i] + b"\x8a\x08" + struct.pack("<q", 2**62) + b"\x85" + good[i + 3 :]
    with pytest.raises(LegacyError, match="exceeds the bound"):
        restricted_loads(huge)


@pytest.mark.parametrize(
    "data, match",
    [
        (b"\x80\x02Nr" + struct.pack("<I", 300_000_000) + b".", "memo index 300000000"),
        (b"\x80\x02]q\x00" + b"](h\x00h\x00eq\x00" * 750 + b".", "exceeds the bound"),
        (b"\x80\x02" + b"]" * 10_000 + b"a" * 9_999 + b".", "nesting deeper than 32"),
        (b"\x80\x02]q\x00h\x00a.", "contains itself"),
        (b"\x80\x02]q\x00]q\x01h\x00a0h\x01a.", "modified after it was used"),
        (b"\x80\x02}G" + struct.pack(">d", 1.5) + b"K\x03s.", "dict keys"),
        (b"\x80\x02}(K\x01K\x02\x86K\x03u.", "dict keys"),
        (b"\x80\x02cos\nsystem\n.", "refused to load os.system"),
        (b"\x80\x02ios\nsystem\n.", "refused to load os.system"),
        (b"\x80\x02U\x01xQ.", "persistent reference"),
        (b"\x80\x02\x82\x01.", "extension-registry"),
        (b"\x80\x05\x97.", "out-of-band"),
        (b"\x80\x02cnumpy\nndarray\n)\x81.", "NEWOBJ"),
        (b"\x80\x02cnumpy\ndtype\n)b.", "BUILD"),
        (b"\x80\x09N.", "protocol"),
        (b"\x80\x02", "exhausted"),
        (b"\x80\x02a.", "underflow"),
    ],
)
def test_hostile_streams_are_refused(data, match):
    """Memo bombs, shared-reference bombs, deep nesting, cycles, mutation after use, unhashable
    or collidable keys, globals, INST, persistent ids, extension codes, out-of-band buffers,
    object construction, BUILD on plain values, unknown protocols and truncated streams each
    raise LegacyError naming the file."""
    with pytest.raises(LegacyError, match=match) as err:
        restricted_loads(data, source="h.pkl")
    assert str(err.value).startswith("h.pkl: ")


def test_every_truncation_and_flipped_byte_is_a_legacy_error():
    """Each truncation of a valid pickle, and each byte of it replaced by 0xff, gives a value
    or LegacyError (never another exception)."""
    data = pickle.dumps([{"a": (1, 2.5)}, np.arange(6.0).reshape(2, 3), "text", [None]], 2)
    for k in range(len(data)):
        for bad in (data[:k], data[:k] + b"\xff" + data[k + 1 :]):
            with contextlib.suppress(LegacyError):
                restricted_loads(bad)


def test_limits_are_configurable():
    """LegacyLimits bounds the bytes of a file, the values built and the dict entries."""
    data = pickle.dumps(list(range(1000)), protocol=2)
    with pytest.raises(LegacyError, match="exceeds the bound of 100"):
        restricted_loads(data, limits=LegacyLimits(max_bytes=100))
    with pytest.raises(LegacyError, match="max_elements"):
        restricted_loads(data, limits=LegacyLimits(max_elements=500))
    dicts = pickle.dumps({str(i): i for i in range(50)}, protocol=2)
    with pytest.raises(LegacyError, match="dict or set entries"):
        restricted_loads(dicts, limits=LegacyLimits(max_dict_entries=10))
    assert restricted_loads(data, limits=LegacyLimits(max_elements=2000)) == list(range(1000))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_only_regular_files_are_read(tmp_path):
    """A FIFO named like a legacy file is refused at once (no wait for a writer); a missing file
    and a file over the byte bound are refused by name."""
    fifo = tmp_path / "Agent_States.pkl"
    os.mkfifo(fifo)
    with pytest.raises(LegacyError, match="not a regular file"):
        restricted_load(fifo)
    with pytest.raises(LegacyError, match="cannot read"):
        restricted_load(tmp_path / "nope.pkl")
    big = tmp_path / "big.pkl"
    big.write_bytes(pickle.dumps(list(range(100))))
    with pytest.raises(LegacyError, match="exceeds the bound"):
        restricted_load(big, limits=LegacyLimits(max_bytes=50))
