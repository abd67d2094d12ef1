"""Tests of fcplan.recording.schema: one schema for the trace and the recording file."""

from __future__ import annotations

import re

import fcplan.recording
from fcplan import run_episode
from fcplan.recording.schema import JSON_ENTRIES, RECORDING_FIELDS, SCHEMA, WORLD_ENTRIES
from fcplan.trace import TRACE_FIELDS


def test_recording_schema_extends_the_trace_schema():
    """The recording's entries start with the trace schema's fields, the very same objects, and
    add only entries the trace does not have."""
    n = len(TRACE_FIELDS)
    assert RECORDING_FIELDS[:n] == TRACE_FIELDS
    assert all(a is b for a, b in zip(RECORDING_FIELDS, TRACE_FIELDS, strict=False))
    assert len(SCHEMA) == len(RECORDING_FIELDS)
    assert {f.key for f in TRACE_FIELDS} <= set(WORLD_ENTRIES)


def test_format_table_documents_exactly_the_schema():
    """The package docstring's entry table lists every schema entry and JSON entry, with the
    schema's dtype and axes (a free axis may have any letter), and nothing else."""
    rows = re.findall(r"^``(\w+)``\s+(\([^)]*\))\s+(\w+)\s", fcplan.recording.__doc__, re.M)
    documented = {name: (shape, dtype) for name, shape, dtype in rows}
    assert set(documented) == set(SCHEMA) | set(JSON_ENTRIES)
    for name in JSON_ENTRIES:
        assert documented[name] == ("()", "str")
    for key, f in SCHEMA.items():
        shape, dtype = documented[key]
        axes = [a.strip() for a in shape.strip("(),").split(",") if a.strip()]
        assert dtype == f.dtype, key
        assert len(axes) == len(f.axes), key
        for doc_axis, axis in zip(axes, f.axes, strict=True):
            assert axis is None or doc_axis == str(axis), key


def test_trace_arrays_are_the_recording_world_entries(tmp_path):
    """A recorded episode's trace arrays have the trace schema's keys and dtypes, and the file
    holds them unchanged."""
    path = tmp_path / "p.npz"
    res = run_episode(
        fcplan.load_scenario("practice").replace(duration_s=3), "greedy", 0, record=path
    )
    arrays = res.trace.arrays()
    assert list(arrays) == [f.key for f in TRACE_FIELDS]
    rec = fcplan.recording.load_recording(path)
    for f in TRACE_FIELDS:
        assert arrays[f.key].dtype == f.dtype and rec.arrays[f.key].dtype == f.dtype
        assert (arrays[f.key] == rec.arrays[f.key]).all()
