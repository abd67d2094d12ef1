"""Tests of fcplan.recording.reader: load_recording refuses foreign, corrupted and pickled files
and reads the files earlier versions of fcplan wrote."""

from __future__ import annotations

import contextlib
import io
import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fcplan.recording import Recording, RecordingError, load_recording
from fcplan.recording.reader import check_recording

#: a recording written before fcplan.recording became a package (practice, 25 s, greedy, seed 7)
OLD_FILE = Path(__file__).parent.parent / "data" / "recording_v1_practice.npz"


def test_recording_written_before_still_loads_and_resimulates():
    """A file written by an earlier fcplan (format version 1, whose scenarios name no wind model:
    they used "fresh", the default then) loads with that wind model, re-simulates to identical
    world and command arrays, and scores the same from its arrays as from the re-simulation."""
    rec = load_recording(OLD_FILE)
    assert rec.header["format_version"] == 1 and rec.scenario.wind_model == "fresh"
    assert rec.source == "greedy" and rec.seed == 7 and rec.n_ticks == 250
    assert (
        rec.arrays["pruned_cells"].size > 0 and len(rec.replans) == rec.arrays["replan_tick"].size
    )
    again = rec.resimulate()
    assert again.mismatches(rec) == []
    assert again.metrics()["manual"].as_dict() == rec.metrics()["manual"].as_dict()


def _write_npz(path, **entries):
    with open(path, "wb") as f:
        np.savez(f, **entries)


@pytest.mark.parametrize(
    "make, match",
    [
        (lambda p: p.write_bytes(b"not a zip file at all"), "not a readable npz"),
        (lambda p: _write_npz(p, x=np.arange(3)), "no 'header'"),
        (lambda p: _write_npz(p, header=np.array("{bad json")), "not valid JSON"),
        (lambda p: _write_npz(p, header=np.array('{"format": "other"}')), "not an fcplan"),
        (
            lambda p: _write_npz(
                p, header=np.array(json.dumps({"format": "fcplan-recording", "format_version": 99}))
            ),
            "format_version 99",
        ),
    ],
)
def test_foreign_files_are_refused(tmp_path, make, match):
    """Foreign, non-npz and future-version files raise RecordingError naming the file."""
    path = tmp_path / "bad.npz"
    make(path)
    with pytest.raises(RecordingError, match=match) as err:
        load_recording(path)
    assert str(path) in str(err.value)


def test_missing_file(tmp_path):
    """A missing file is a RecordingError, not an OSError traceback."""
    with pytest.raises(RecordingError, match="cannot read"):
        load_recording(tmp_path / "nope.npz")


def test_corrupted_entries_are_refused(recorded, tmp_path):
    """A truncated archive, an entry of the wrong dtype or shape, and inconsistent event counts
    are each refused with the entry named."""
    _, path = recorded
    data = path.read_bytes()
    (tmp_path / "cut.npz").write_bytes(data[: len(data) // 2])
    with pytest.raises(RecordingError):
        load_recording(tmp_path / "cut.npz")
    with np.load(path, allow_pickle=False) as z:
        entries = {k: z[k] for k in z.files}
    for name, value, match in [
        ("agent_tank", entries["agent_tank"].astype(np.float32), "agent_tank"),
        ("active", entries["active"][:-1], "ticks"),
        ("pruned_count", entries["pruned_count"] + 1, "pruned_count"),
        ("sensed_cells", entries["sensed_cells"] + 10**8, "outside"),
    ]:
        bad = dict(entries, **{name: value})
        p = tmp_path / f"{name}.npz"
        _write_npz(p, **bad)
        with pytest.raises(RecordingError, match=match):
            load_recording(p)


class _Boom:
    """Unpickling this would create a file (a stand-in for os.system)."""

    def __init__(self, path):
        self.path = path

    def __reduce__(self):
        return (open, (self.path, "w"))


def test_object_arrays_are_never_unpickled(recorded, tmp_path):
    """An npz holding a pickled object array is refused, and the pickle's side effect never
    happens."""
    _, path = recorded
    marker = tmp_path / "pwned"
    with np.load(path, allow_pickle=False) as z:
        entries = {k: z[k] for k in z.files}
    evil = np.empty(1, dtype=object)
    evil[0] = _Boom(str(marker))
    entries["inputs"] = evil
    p = tmp_path / "evil.npz"
    buf = io.BytesIO()
    np.savez(buf, **entries)
    p.write_bytes(buf.getvalue())
    assert b"pwned" in zipfile.ZipFile(p).read("inputs.npy")  # the payload is really there
    with pytest.raises(RecordingError, match="pickle"):
        load_recording(p)
    assert not marker.exists()


# ------------------------------------------------------------------------------ hardening
def _entries(path):
    with zipfile.ZipFile(path) as z:
        return {i.filename: z.read(i) for i in z.infolist()}


def _npz(path, entries):
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        for name, raw in entries.items():
            z.writestr(name, raw)
    return path


def _npy(a):
    buf = io.BytesIO()
    np.lib.format.write_array(buf, a, allow_pickle=False)
    return buf.getvalue()


def _array(entries, name):
    return np.lib.format.read_array(io.BytesIO(entries[f"{name}.npy"]))


def test_unknown_entries_are_never_decompressed(recorded, tmp_path):
    """An extra entry is ignored without being read: even a corrupt one (a CRC error would
    surface if it were decompressed) does not stop the recording from loading unchanged."""
    _, path = recorded
    entries = _entries(path)
    entries["extra.npy"] = bytes(1 << 20)
    p = _npz(tmp_path / "extra.npz", entries)
    data = bytearray(p.read_bytes())
    i = data.index(b"extra.npy", data.index(b"extra.npy") + 1)  # its central directory record
    crc_at = data.rindex(b"PK\x01\x02", 0, i) + 16
    data[crc_at : crc_at + 4] = b"\0\0\0\0"
    p.write_bytes(bytes(data))
    rec, orig = load_recording(p), load_recording(path)
    for k, a in orig.arrays.items():
        assert np.array_equal(rec.arrays[k], a, equal_nan=a.dtype.kind == "f"), k


def test_declared_shapes_are_checked_against_the_header(recorded, tmp_path):
    """An entry declaring a shape the header does not imply (more ticks, another agent count,
    more event cells than counted, a 0-d array) is refused, naming the entry and what the header
    allows, before its bytes are read."""
    _, path = recorded
    base = _entries(path)
    xyz = _array(base, "agent_xyz")
    for name, value, match in [
        ("agent_xyz", np.zeros((len(xyz) + 1, *xyz.shape[1:])), "header allows float64"),
        ("agent_xyz", np.zeros((len(xyz), xyz.shape[1] + 1, 3)), "agent_xyz"),
        ("ignited_cells", np.zeros(3, np.int32), "ignited_cells"),
        ("active", np.zeros((), np.int64), "active"),
    ]:
        p = _npz(tmp_path / f"{name}.npz", dict(base, **{f"{name}.npy": _npy(value)}))
        with pytest.raises(RecordingError, match=match):
            load_recording(p)


@pytest.mark.parametrize(
    "name, edit, match",
    [
        ("agent_xyz", lambda a: a.__setitem__((3, 0, 0), np.nan), "finite"),
        ("agent_xyz", lambda a: a.__setitem__((3, 0, 1), 1e300), "finite"),
        ("command_route_xy", lambda a: a.__setitem__((0, 0), np.inf), "command_route_xy"),
        ("agent_mode", lambda a: a.__setitem__((0, 0), 7), "mode"),
        ("command_tick", lambda a: a.__setitem__(0, 10**6), "tick"),
        ("replan_wall_s", lambda a: a.__setitem__(0, -1.0), "duration"),
        ("agent_goal_index", lambda a: a.__setitem__((0, 0), -5), ">= -1"),
    ],
)
def test_values_out_of_range_are_refused(recorded, tmp_path, name, edit, match):
    """NaN, infinite or absurd positions and goals, unknown modes, ticks outside the episode,
    negative durations and goal indices below -1 are refused, naming the entry."""
    _, path = recorded
    base = _entries(path)
    a = _array(base, name)
    edit(a)
    p = _npz(tmp_path / "bad.npz", dict(base, **{f"{name}.npy": _npy(a)}))
    with pytest.raises(RecordingError, match=match) as err:
        load_recording(p)
    assert name in str(err.value)


@pytest.mark.parametrize(
    "edit, match",
    [
        (lambda h: h.pop("scenario"), "header.scenario is missing"),
        (lambda h: h.update(seed=-1), "header.seed"),
        (lambda h: h.update(ticks="many"), "header.ticks"),
        (lambda h: h.update(settings=[1]), "header.settings"),
        (lambda h: h["scenario"].update(world_size="wide"), "header.scenario"),
        (lambda h: h["scenario"].update(duration_s=1), r"allows int64\[<= 10\]"),
    ],
)
def test_header_fields_are_checked(recorded, tmp_path, edit, match):
    """A header without a scenario, with fields of the wrong type, an invalid scenario or more
    ticks than its scenario has is refused with a RecordingError naming the field."""
    _, path = recorded
    base = _entries(path)
    header = json.loads(str(_array(base, "header")))
    edit(header)
    p = _npz(tmp_path / "h.npz", dict(base, **{"header.npy": _npy(np.array(json.dumps(header)))}))
    with pytest.raises(RecordingError, match=match):
        load_recording(p)


def test_damaged_archives_are_recording_errors(recorded, tmp_path):
    """Flipping any bit of the file, deeply nested header JSON, an unknown compression method or
    an archive listing thousands of entries gives a value or a RecordingError, never another
    exception."""
    _, path = recorded
    data = path.read_bytes()
    p = tmp_path / "d.npz"
    for k in range(0, len(data), max(1, len(data) // 300)):
        p.write_bytes(data[:k] + bytes([data[k] ^ (1 << (k % 8))]) + data[k + 1 :])
        with contextlib.suppress(RecordingError):
            load_recording(p)
    base = _entries(path)
    nested = _npy(np.array("[" * 50_000 + "]" * 50_000))
    with pytest.raises(RecordingError, match="not valid JSON"):
        load_recording(_npz(tmp_path / "n.npz", dict(base, **{"header.npy": nested})))
    raw = bytearray(data)
    for sig, off, value in ((b"PK\x03\x04", 8, 99), (b"PK\x01\x02", 10, 99)):
        i = raw.find(sig)
        raw[i + off : i + off + 2] = value.to_bytes(2, "little")
    p.write_bytes(bytes(raw))
    with pytest.raises(RecordingError, match="compression method 99"):
        load_recording(p)
    many = dict(base, **{f"x{i}": b"" for i in range(2000)})
    with pytest.raises(RecordingError, match="more than 1024 entries"):
        load_recording(_npz(tmp_path / "many.npz", many))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_only_regular_files_within_the_bound_are_read(recorded, tmp_path):
    """A FIFO named like a recording is refused at once, as is a file over max_bytes or whose
    decompressed entries exceed it."""
    _, path = recorded
    fifo = tmp_path / "fifo.npz"
    os.mkfifo(fifo)
    with pytest.raises(RecordingError, match="not a regular file"):
        load_recording(fifo)
    size = path.stat().st_size
    with pytest.raises(RecordingError, match="exceeds the bound"):
        load_recording(path, max_bytes=size - 1)
    with pytest.raises(RecordingError, match="bound on decompressed bytes"):
        load_recording(path, max_bytes=size + 1)


def test_check_recording_accepts_what_load_recording_loads(recorded):
    """check_recording passes a loaded recording and refuses it once a position is NaN."""
    _, path = recorded
    rec = load_recording(path)
    check_recording(rec, "r")
    arrays = dict(rec.arrays, agent_xyz=rec.arrays["agent_xyz"].copy())
    arrays["agent_xyz"][0, 0, 0] = np.nan
    with pytest.raises(RecordingError, match="^r: entry 'agent_xyz'"):
        check_recording(Recording(rec.header, arrays, rec.replans, rec.inputs), "r")


def test_read_bytes_asks_for_the_file_not_the_bound(tmp_path):
    """A small file read under a huge bound allocates what the file holds, not the bound (a
    buffered read of the bound reserved it: 1 TiB here, a MemoryError under an address-space
    limit), and a file over the bound is refused naming it."""
    from fcplan.recording.reader import read_bytes

    p = tmp_path / "small.bin"
    p.write_bytes(b"0123456789")
    assert read_bytes(str(p), max_bytes=2**40) == b"0123456789"
    assert read_bytes(str(p)) == b"0123456789"
    with pytest.raises(RecordingError, match="small.bin"):
        read_bytes(str(p), max_bytes=9)


def test_read_bytes_refuses_a_file_that_grows_past_the_bound(tmp_path, monkeypatch):
    """A file that grows while it is read is read on in bounded chunks and refused once it is
    past the bound; one that grows within the bound is read whole."""
    import os as os_module

    from fcplan.recording import reader

    p = tmp_path / "grows.bin"
    p.write_bytes(b"x" * 10)
    real_fstat = os_module.fstat

    def stale_fstat(fd):  # the size seen before the file grew to 10 bytes
        st = real_fstat(fd)
        return os_module.stat_result((st.st_mode, *st[1:6], 4, *st[7:]))

    monkeypatch.setattr(reader.os, "fstat", stale_fstat)
    assert reader.read_bytes(str(p), max_bytes=100) == b"x" * 10
    with pytest.raises(RecordingError, match="grew past the bound"):
        reader.read_bytes(str(p), max_bytes=7)
