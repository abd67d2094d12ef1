"""Reading recordings: :func:`load_recording` opens a file safely and checks it entry by entry.

A recording is an ``.npz`` archive read with ``allow_pickle=False`` (an object array is refused,
never unpickled), whose JSON header must name the format and a supported version, and whose every
entry must have the dtype and shape the schema (:mod:`fcplan.recording.schema`) gives it for the
recorded scenario, with event counts adding up and cells and agent rows in range. Any failure is
a :class:`~fcplan.recording.schema.RecordingError` naming the file and the entry.

Examples
--------
>>> import os, tempfile
>>> from fcplan import load_scenario
>>> from fcplan.mission import Mission
>>> from fcplan.recording import Recorder, load_recording
>>> sc = load_scenario("practice")
>>> rec = Recorder(sc, 0, source="human")
>>> Mission(sc, seed=0, observers=[rec]).advance(20)
20
>>> path = os.path.join(tempfile.mkdtemp(), "short.npz")
>>> _ = rec.save(path)
>>> load_recording(path).n_ticks
20
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.recording.schema import (
    EVENTS,
    FORMAT,
    FORMAT_VERSION,
    JSON_ENTRIES,
    SCHEMA,
    RecordingError,
)
from fcplan.recording.writer import Recording
from fcplan.scenario import Scenario

__all__ = ["load_recording", "Recording", "read_bytes"]


def read_bytes(path: str, error: type[FcplanError]) -> bytes:
    """The whole file, or ``error`` naming it and the reason."""
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None


def load_recording(path: str | os.PathLike[str]) -> Recording:
    """Read and check a recording written by :meth:`Recorder.save
    <fcplan.recording.Recorder.save>` (never unpickles anything).

    Raises
    ------
    RecordingError
        If the file is missing, not an npz archive, holds object arrays, is not an fcplan
        recording, has an unknown format version, or an entry has the wrong dtype or shape.
    """
    path = os.fspath(path)
    data = read_bytes(path, RecordingError)
    if not data.startswith(b"PK"):
        raise RecordingError(f"{path}: not a readable npz archive (not a zip file)")
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            if "header" not in npz.files:
                raise RecordingError(f"{path}: not an fcplan recording (no 'header' entry)")
            raw = {k: npz[k] for k in npz.files}
    except RecordingError:
        raise
    except ValueError as exc:
        if "pickle" in str(exc):
            raise RecordingError(
                f"{path}: holds an object (pickled) array; recordings never do, refusing to load it"
            ) from None
        raise RecordingError(f"{path}: not a readable npz archive ({exc})") from None
    except (zipfile.BadZipFile, OSError, EOFError, KeyError) as exc:
        raise RecordingError(f"{path}: not a readable npz archive ({exc})") from None
    return _from_entries(raw, path)


def _load_json(raw: dict[str, np.ndarray], name: str, path: str) -> Any:
    a = raw.get(name)
    if a is None or a.dtype.kind != "U" or a.shape != ():
        raise RecordingError(f"{path}: entry {name!r} must be a JSON string")
    try:
        return json.loads(str(a))
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{path}: entry {name!r} is not valid JSON ({exc.msg})") from None


def _from_entries(raw: dict[str, np.ndarray], path: str) -> Recording:
    header = _load_json(raw, "header", path)
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise RecordingError(f"{path}: not an fcplan recording (header.format is not {FORMAT!r})")
    if header.get("format_version") != FORMAT_VERSION:
        raise RecordingError(
            f"{path}: header.format_version {header.get('format_version')!r} is not supported "
            f"(this fcplan reads version {FORMAT_VERSION})"
        )
    missing = [k for k in (*SCHEMA, *JSON_ENTRIES) if k not in raw]
    if missing:
        raise RecordingError(f"{path}: missing entries {', '.join(missing)}")
    replans = _load_json(raw, "replans", path)
    inputs = _load_json(raw, "inputs", path)
    rec = Recording(header, {k: raw[k] for k in SCHEMA}, replans, inputs)
    try:
        sc = rec.scenario
    except FcplanError as exc:
        raise RecordingError(f"{path}: header.scenario: {exc}") from None
    _check_arrays(rec, sc, path)
    return rec


def _check_arrays(rec: Recording, sc: Scenario, path: str) -> None:
    """Every entry's dtype and shape against the schema, then the cross-entry consistency."""
    a = rec.arrays
    dims = {
        "T": len(a["active"]),
        "N": len(sc.agents),
        "F": len(sc.scored_facilities),
        "C": len(a["command_tick"]),
        "R": len(a["replan_tick"]),
        "K": len(a["input_tick"]),
    }
    if (header_t := rec.header.get("ticks")) is not None and header_t != dims["T"]:
        raise RecordingError(f"{path}: header.ticks is {header_t} but 'active' has {dims['T']}")
    for name, f in SCHEMA.items():
        arr = a[name]
        if not f.fits(arr, dims):
            shown = ["*" if w is None else w for w in f.shape(dims)]
            raise RecordingError(
                f"{path}: entry {name!r} is {arr.dtype}{list(arr.shape)}, expected {f.dtype}{shown}"
            )
    ncell = sc.world_size**2
    for k in EVENTS:
        cells, count = a[f"{k}_cells"], a[f"{k}_count"]
        if int(count.sum(dtype=np.int64)) != len(cells) or (count < 0).any():
            raise RecordingError(f"{path}: {k}_count does not add up to len({k}_cells)")
        if cells.size and (cells.min() < 0 or cells.max() >= ncell):
            raise RecordingError(f"{path}: {k}_cells holds a cell outside 0..{ncell - 1}")
    if int(a["command_route_len"].sum(dtype=np.int64)) != len(a["command_route_xy"]):
        raise RecordingError(f"{path}: command_route_len does not add up to command_route_xy")
    if dims["C"] and not (a["command_agent"].min() >= 0 and a["command_agent"].max() < dims["N"]):
        raise RecordingError(f"{path}: command_agent holds a row outside 0..{dims['N'] - 1}")
    if len(rec.inputs) != dims["K"] or len(rec.replans) != dims["R"]:
        raise RecordingError(f"{path}: inputs/replans JSON lengths disagree with their tick arrays")
