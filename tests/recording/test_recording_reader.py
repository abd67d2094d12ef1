"""Tests of fcplan.recording.reader: load_recording refuses foreign, corrupted and pickled files
and reads the files earlier versions of fcplan wrote."""

from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from fcplan.recording import RecordingError, load_recording

#: a recording written before fcplan.recording became a package (practice, 25 s, greedy, seed 7)
OLD_FILE = Path(__file__).parent.parent / "data" / "recording_v1_practice.npz"


def test_recording_written_before_still_loads_and_resimulates():
    """A file written by an earlier fcplan loads, re-simulates to identical world and command
    arrays, and scores the same from its arrays as from the re-simulation."""
    rec = load_recording(OLD_FILE)
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
