"""Inputs for fuzzing the readers of outside files: seeds, mutations and adversarial cases.

The targets are :func:`fcplan.legacy.restricted_loads`, :func:`fcplan.legacy.import_legacy` and
:func:`fcplan.recording.load_recording`. Their property: every input gives a value or the
reader's own error (``LegacyError`` / ``RecordingError``), never another exception, a crash, a
hang or more memory than a bound. :func:`outcome` classifies one call.

* Seeds: small valid pickles of the legacy layouts (protocols 2 and 4, with numpy arrays and
  scalars), a short synthetic legacy folder, a 3-s recording.
* Mutations: byte edits (flip, set, delete, insert, duplicate, truncate) of a file; value edits
  of a legacy file's content (a number, list or string replaced by NaN, infinities, huge or
  negative numbers, wrong types), re-pickled; entry edits of a recording (one ``.npy`` entry's
  bytes edited, the archive re-packed so the zip layer is valid).
* :data:`ADVERSARIAL`: the hostile files of issues 15 and 17, each built small.
"""

from __future__ import annotations

import io
import json
import math
import os
import pickle
import struct
import zipfile
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

from fcplan.errors import LegacyError
from fcplan.recording import RecordingError

#: a byte edit: (kind, position, payload); positions wrap around the data's length
Edit = tuple[str, int, bytes]
EDIT_KINDS = ("flip", "set", "delete", "insert", "duplicate", "truncate")
#: values a value edit puts in place of a number, list or string
ODD_VALUES: tuple[Any, ...] = (
    math.nan,
    math.inf,
    -math.inf,
    1e308,
    -1,
    0,
    2**63,
    "x",
    None,
    [],
    [[]],
    {},
    (1, 2),
    True,
    np.full((2, 3), np.nan),
    np.zeros((0, 7)),
    [1.0] * 17,
)


def outcome(call: Callable[[], Any], clean: type[Exception]) -> tuple[str, str]:
    """``("loaded", "")``, ``("clean", message)`` for the reader's own error, or
    ``("traceback", "Type: message")`` for any other exception."""
    try:
        call()
    except clean as exc:
        return "clean", str(exc)
    except Exception as exc:  # noqa: BLE001 - what a fuzzer looks for
        return "traceback", f"{type(exc).__name__}: {exc}"
    return "loaded", ""


# ------------------------------------------------------------------------------- seeds
def pickle_seeds() -> dict[str, bytes]:
    """Small valid pickles shaped like the 2020 GUI's files, in protocols 2 and 4."""
    states = [
        float(v)
        for k in range(3)  # 3 frames of 16 values
        for v in (400 + k, 300, 20, 0, 0, 0, 0, 100 * k, 1, 1, k, 0, 10, 1, 0, 0)
    ]
    values: dict[str, Any] = {
        "background": [
            [800, 60, 1, 1, 0, 0, 1],
            [1, 1, 0, 0],
            [[[450, 150]], [3, 0, 10, 5, 45, 1.25, 0.1, 90, 80, 0], [[100, 200], 1]],
            [[[10, 100]], [[500]], [[20]]],
            8,
            [math.pi / 4, math.pi / 6],
        ],
        "agent_states": [states],
        "fire_states": [[[450.0, 150.0, 1.0, 100.0 * k] for k in range(6)], []],
        "pruned": [[[], [[[450, 150, 1.0]], [450.0, 150.0, 300.0]]]],
        "sensed": [[np.array([[450.0, 150.0, 1.0, 0.0]]), []]],
        "numpy": [
            np.arange(6.0).reshape(2, 3),
            np.arange(6.0).reshape(2, 3).T,
            np.array([1, 2], np.int16),
            np.float64(2.5),
            np.int64(7),
            np.array(["ab", "c"]),
            np.array([True, False]),
            np.array([[1, "a"], [2.5, None]], dtype=object),
        ],
        "plain": {"a": (1, 2.5, "s", b"b", None, True), "b": [[1, 2], {3, 4}, frozenset({5})]},
    }
    return {
        f"{name}.p{proto}": pickle.dumps(v, protocol=proto)
        for name, v in values.items()
        for proto in (2, 4)
    }


def mini_legacy_folder(folder: str) -> None:
    """A 12-s synthetic 2020 GUI folder (practice with greedy), with a small ``Fire_Map.pkl``
    (the importer reads but does not use it) so one import takes a fraction of a second."""
    from tests.legacy.folders import dump_pickle, write_legacy_folder

    write_legacy_folder(folder, duration_s=12)
    dump_pickle(folder, "Fire_Map.pkl", np.zeros((4, 4)))


def short_recording(path: str, seconds: float = 3.0) -> bytes:
    """A recording of practice played by greedy for ``seconds`` (replans, commands); its bytes."""
    from fcplan import load_scenario, run_episode

    run_episode(load_scenario("practice").replace(duration_s=seconds), "greedy", record=path)
    with open(path, "rb") as f:
        return f.read()


# ------------------------------------------------------------------------------- mutations
def mutate_bytes(data: bytes, edits: list[Edit]) -> bytes:
    """``data`` with each byte edit applied in turn."""
    b = bytearray(data)
    for kind, pos, payload in edits:
        i = pos % max(len(b), 1)
        if kind == "flip" and b:
            b[i] ^= 1 << (pos % 8)
        elif kind == "set" and b:
            b[i : i + len(payload)] = payload
        elif kind == "delete":
            del b[i : i + 1 + len(payload)]
        elif kind == "insert":
            b[i:i] = payload
        elif kind == "duplicate":
            b[i:i] = b[i : i + 1 + 16 * len(payload)]
        elif kind == "truncate":
            del b[i:]
    return bytes(b)


def _slots(x: Any, out: list[tuple[Any, Any]]) -> None:
    """Every (container, key) holding a value inside ``x`` (depth first)."""
    if isinstance(x, list):
        for k, v in enumerate(x):
            out.append((x, k))
            _slots(v, out)
    elif isinstance(x, dict):
        for k, v in x.items():
            out.append((x, k))
            _slots(v, out)


def mutate_value(obj: Any, index: int, odd: Any) -> Any:
    """``obj`` (a list/dict structure; tuples become lists) with its ``index``-th slot set to
    ``odd``; unchanged when it has no slot."""
    obj = _listify(obj)
    slots: list[tuple[Any, Any]] = []
    _slots(obj, slots)
    if slots:
        container, key = slots[index % len(slots)]
        container[key] = odd
    return obj


def _listify(x: Any) -> Any:
    if isinstance(x, (list, tuple)):
        return [_listify(v) for v in x]
    if isinstance(x, dict):
        return {k: _listify(v) for k, v in x.items()}
    return x


def npz_entries(data: bytes) -> dict[str, bytes]:
    """The raw ``.npy`` bytes of every entry of an npz archive."""
    with zipfile.ZipFile(io.BytesIO(data)) as z:
        return {i.filename: z.read(i) for i in z.infolist()}


def make_npz(entries: dict[str, bytes], method: int = zipfile.ZIP_DEFLATED) -> bytes:
    """An npz archive of raw entries (``name.npy`` -> bytes)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=method) as z:
        for name, raw in entries.items():
            z.writestr(name, raw)
    return buf.getvalue()


def npy_bytes(a: np.ndarray, shape: tuple[int, ...] | None = None) -> bytes:
    """``a`` as ``.npy`` bytes; ``shape`` replaces the shape its header declares."""
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a, allow_pickle=False)
    raw = buf.getvalue()
    if shape is None:
        return raw
    hlen = struct.unpack("<H", raw[8:10])[0]
    head = raw[10 : 10 + hlen].decode("latin1")
    new = head.replace(repr(a.shape), repr(shape)).rstrip("\n ")
    new = new.ljust(hlen - 1) + "\n"
    if len(new) != hlen:
        raise ValueError("the new shape does not fit the old header")
    return raw[:10] + new.encode("latin1") + raw[10 + hlen :]


# ------------------------------------------------------------------------------- adversarial
def _object_pickle() -> bytes:
    """numpy.ndarray((1,), dtype("O")) from the bytes b"AAAAAAAA": reading its element would
    dereference address 0x4141414141414141 (issue 15)."""
    return (
        b"cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\n)U\x01b\x87R"
        b"(K\x01K\x01\x85cnumpy\ndtype\nU\x02O8\x89\x88\x87R"
        b"(K\x03U\x01|NNNJ\xff\xff\xff\xffJ\xff\xff\xff\xffK?tb\x89U\x08AAAAAAAAtb."
    )


def _memo_pickle() -> bytes:
    """9 bytes whose memo index is 3e8 (CPython's unpickler grows its memo table to 2.4 GB)."""
    return b"\x80\x02Nr" + struct.pack("<I", 300_000_000) + b"."


def _shared_lists_pickle(levels: int = 750) -> bytes:
    """6 KB: each list holds the previous one twice (2**750 elements as a tree)."""
    return b"\x80\x02]q\x00" + b"](h\x00h\x00eq\x00" * levels + b"."


def _deep_pickle(depth: int = 100_000) -> bytes:
    """A list nested 100 000 deep."""
    return b"\x80\x02" + b"]" * depth + b"a" * (depth - 1) + b"."


def _write(path: str, data: bytes) -> str:
    with open(path, "wb") as f:
        f.write(data)
    return path


def _legacy_with(folder: str, seed_folder: str, name: str, data: bytes | None) -> str:
    """A copy of ``seed_folder`` whose file ``name`` holds ``data`` (None: is a FIFO)."""
    os.makedirs(folder, exist_ok=True)
    for f in os.listdir(seed_folder):
        with open(os.path.join(seed_folder, f), "rb") as src:
            _write(os.path.join(folder, f), src.read())
    os.remove(os.path.join(folder, name))
    if data is None:
        os.mkfifo(os.path.join(folder, name))
    else:
        _write(os.path.join(folder, name), data)
    return folder


def _zip(entries: list[tuple[str, int, int, bytes]]) -> bytes:
    """A zip archive of already deflated entries: (name, crc32, uncompressed size, deflate data)."""
    out, central = bytearray(), bytearray()
    for name, crc, size, raw in entries:
        fields = (20, 0, zipfile.ZIP_DEFLATED, 0, 0x21, crc, len(raw), size, len(name), 0)
        central += struct.pack("<IH", 0x02014B50, 20) + struct.pack("<HHHHHIIIHH", *fields)
        central += struct.pack("<HHHII", 0, 0, 0, 0, len(out)) + name.encode()
        out += struct.pack("<I", 0x04034B50) + struct.pack("<HHHHHIIIHH", *fields)
        out += name.encode() + raw
    eocd = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(entries), len(entries), len(central),
                       len(out), 0)  # fmt: skip
    return bytes(out + central + eocd)


def _deflated(body: bytes) -> tuple[int, int, bytes]:
    c = zlib.compressobj(6, zlib.DEFLATED, -15)
    return zlib.crc32(body), len(body), c.compress(body) + c.flush()


def _recording_with_bomb(seed: bytes, n_mib: int = 1024) -> bytes:
    """``seed`` plus an entry ``extra.npy`` that decompresses to ``n_mib`` MiB of zeros (1 MB of
    file: one deflated MiB, fully flushed so it can be repeated, ``n_mib`` times)."""
    chunk = bytes(1 << 20)
    c = zlib.compressobj(9, zlib.DEFLATED, -15)
    block = c.compress(chunk) + c.flush(zlib.Z_FULL_FLUSH)
    raw = block * n_mib + c.flush(zlib.Z_FINISH)
    crc = 0
    for _ in range(n_mib):
        crc = zlib.crc32(chunk, crc)
    entries = [(n, *_deflated(body)) for n, body in npz_entries(seed).items()]
    return _zip([*entries, ("extra.npy", crc, n_mib << 20, raw)])


def _recording_entry(seed: bytes, name: str, raw: bytes) -> bytes:
    e = npz_entries(seed)
    e[f"{name}.npy"] = raw
    return make_npz(e)


def _header_edit(seed: bytes, edit: Callable[[dict[str, Any]], Any]) -> bytes:
    e = npz_entries(seed)
    header = json.loads(str(np.lib.format.read_array(io.BytesIO(e["header.npy"]))))
    edit(header)
    return _recording_entry(seed, "header", npy_bytes(np.array(json.dumps(header))))


def _unsupported_method(seed: bytes) -> bytes:
    """``seed`` whose entries claim compression method 99 (zipfile: NotImplementedError)."""
    data = bytearray(seed)
    for sig, off in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        i = data.find(sig)
        while i >= 0:
            data[i + off : i + off + 2] = struct.pack("<H", 99)
            i = data.find(sig, i + 4)
    return bytes(data)


def adversarial_cases(tmp: str, legacy_seed: str, rec_seed: bytes) -> dict[str, tuple[str, str]]:
    """Name -> (target, path) of each hostile input, written under ``tmp``. Targets:
    ``pickle`` (restricted_load), ``legacy`` (import_legacy), ``recording`` (load_recording),
    ``results`` (fcplan.experiments.results.load_results)."""
    xyz = np.lib.format.read_array(io.BytesIO(npz_entries(rec_seed)["agent_xyz.npy"]))
    nan_xyz, far_xyz = xyz.copy(), xyz.copy()
    nan_xyz[3, 0, 0] = np.nan
    far_xyz[3, 0, 1] = 1e300
    j = os.path.join
    cases = {
        "object array from raw bytes (pickle)": ("pickle", _write(j(tmp, "obj.pkl"), _object_pickle())),
        "memo index 3e8 (pickle)": ("pickle", _write(j(tmp, "memo.pkl"), _memo_pickle())),
        "shared nested lists, 6 KB (pickle)": ("pickle", _write(j(tmp, "shared.pkl"), _shared_lists_pickle())),
        "list nested 100 000 deep (pickle)": ("pickle", _write(j(tmp, "deep.pkl"), _deep_pickle())),
        "object array in Agent_States.pkl (folder)": (
            "legacy", _legacy_with(j(tmp, "obj"), legacy_seed, "Agent_States.pkl", _object_pickle())
        ),
        "NaN world_size (folder)": ("legacy", _legacy_with(
            j(tmp, "nanw"), legacy_seed, "Background_Info.pkl",
            pickle.dumps([[math.nan, 12.0], [1, 1, 0]] + [None] * 2, protocol=2),
        )),
        "decompression bomb, 1 GiB extra entry (recording)": (
            "recording", _write(j(tmp, "bomb.npz"), _recording_with_bomb(rec_seed))
        ),
        "declared 7 TiB agent_xyz (recording)": ("recording", _write(
            j(tmp, "huge.npz"),
            _recording_entry(rec_seed, "agent_xyz", npy_bytes(xyz, (2**40, 1000, 3))),
        )),
        "header JSON nested 100 000 deep (recording)": ("recording", _write(
            j(tmp, "nested.npz"),
            _recording_entry(rec_seed, "header", npy_bytes(np.array("[" * 100_000 + "]" * 100_000))),
        )),
        "header without scenario (recording)": ("recording", _write(
            j(tmp, "noscen.npz"), _header_edit(rec_seed, lambda h: h.pop("scenario"))
        )),
        "NaN position (recording)": ("recording", _write(
            j(tmp, "nanpos.npz"), _recording_entry(rec_seed, "agent_xyz", npy_bytes(nan_xyz))
        )),
        "position 1e300 (recording)": ("recording", _write(
            j(tmp, "farpos.npz"), _recording_entry(rec_seed, "agent_xyz", npy_bytes(far_xyz))
        )),
        "compression method 99 (recording)": (
            "recording", _write(j(tmp, "method.npz"), _unsupported_method(rec_seed))
        ),
        "one flipped bit (recording)": ("recording", _write(
            j(tmp, "flip.npz"), mutate_bytes(rec_seed, [("flip", len(rec_seed) // 3, b"")])
        )),
    }  # fmt: skip
    if hasattr(os, "mkfifo"):
        os.mkfifo(j(tmp, "fifo.npz"))
        cases["FIFO named .npz (recording)"] = ("recording", j(tmp, "fifo.npz"))
        os.makedirs(j(tmp, "results"))
        os.mkfifo(j(tmp, "results", "abc.parquet"))
        cases["FIFO named .parquet (results folder)"] = ("results", j(tmp, "results"))
        fifo_folder = _legacy_with(j(tmp, "fifo"), legacy_seed, "Agent_States.pkl", None)
        cases["FIFO named Agent_States.pkl (folder)"] = ("legacy", fifo_folder)
    return cases


#: the reader's own error of each target
CLEAN: dict[str, type[Exception]] = {
    "pickle": LegacyError,
    "legacy": LegacyError,
    "recording": RecordingError,
}


def load_target(target: str, path: str) -> Any:
    """Call the reader of ``target`` on ``path``."""
    if target == "pickle":
        from fcplan.legacy import restricted_load

        return restricted_load(path)
    if target == "legacy":
        from fcplan.legacy import import_legacy

        return import_legacy(path)
    if target == "recording":
        from fcplan.recording import load_recording

        return load_recording(path)
    from fcplan.experiments.results import load_results

    return load_results(path)


def clean_error(target: str) -> type[Exception]:
    """The reader's own error class of ``target``."""
    if target == "results":
        from fcplan.experiments.results import ResultsError

        return ResultsError
    return CLEAN[target]
