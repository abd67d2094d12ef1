"""The recording file format: its entries (dtype and axes), header constants and JSON helpers.

A recording's per-tick trace arrays are the simulator's trace schema,
:data:`fcplan.trace.TRACE_FIELDS`, under the same keys and dtypes; :data:`RECORDING_FIELDS`
extends it with the entries only a recording has (goals, fire events, commands, replans, inputs).
The package docstring (:mod:`fcplan.recording`) is the format's documentation page; its table
lists exactly these entries (a test checks it).

Examples
--------
>>> from fcplan.recording.schema import SCHEMA, WORLD_ENTRIES
>>> SCHEMA["command_route_xy"].dtype, SCHEMA["command_route_xy"].axes
('float64', (None, 2))
>>> "agent_goal_index" in WORLD_ENTRIES, "command_tick" in WORLD_ENTRIES
(True, False)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, is_dataclass
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.provenance import library_versions
from fcplan.trace import TRACE_FIELDS, TraceField

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "READ_VERSIONS",
    "RECORDING_FIELDS",
    "SCHEMA",
    "WORLD_ENTRIES",
    "JSON_ENTRIES",
    "EVENTS",
    "RecordingError",
]

FORMAT = "fcplan-recording"
FORMAT_VERSION = 2
"""Version this fcplan writes. Version 1 (before the default wind model became ``"tables"``)
reads too: its scenarios that name no wind model used ``"fresh"``."""
READ_VERSIONS = (1, 2)

#: bits of ``command_flags``: route given, patrol, home, altitude given
ROUTE, PATROL, HOME, ALTITUDE = 1, 2, 4, 8
#: the fire events kept tick by tick (``<event>_cells`` and ``<event>_count``)
EVENTS = ("ignited", "sensed", "pruned")

#: Every array entry of a recording file: the trace schema, then the recording's own entries.
#: Axes: ``T`` ticks, ``N`` agents, ``F`` scored facilities, ``C`` commands, ``R`` replans, ``K``
#: inputs, None a free length.
RECORDING_FIELDS: tuple[TraceField, ...] = (
    *TRACE_FIELDS,
    TraceField("agent_goal_index", "int16", ("T", "N"), "goal being flown to, -1: none"),
    TraceField("ignited_cells", "int32", (None,), "cells that started burning, tick by tick"),
    TraceField("ignited_count", "int32", ("T",), "ignited cells of each tick"),
    TraceField("sensed_cells", "int32", (None,), "cells sensed for the first time"),
    TraceField("sensed_count", "int32", ("T",), "sensed cells of each tick"),
    TraceField("pruned_cells", "int32", (None,), "cells put out, tick by tick"),
    TraceField("pruned_count", "int32", ("T",), "pruned cells of each tick"),
    TraceField("command_tick", "int32", ("C",), "tick at which a command was given"),
    TraceField("command_agent", "int16", ("C",), "agent row"),
    TraceField("command_flags", "uint8", ("C",), "route, patrol, home, altitude bits"),
    TraceField("command_altitude", "float64", ("C",), "target altitude (NaN: not given)"),
    TraceField("command_route_len", "int32", ("C",), "goals in the command's route"),
    TraceField("command_route_xy", "float64", (None, 2), "every command's goals"),
    TraceField("replan_tick", "int32", ("R",), "tick of each replan"),
    TraceField("replan_wall_s", "float64", ("R",), "wall seconds of each scheduler call"),
    TraceField("input_tick", "int32", ("K",), "tick of each human input"),
)
#: entry key -> field
SCHEMA: dict[str, TraceField] = {f.key: f for f in RECORDING_FIELDS}
#: the entries holding JSON strings
JSON_ENTRIES = ("header", "replans", "inputs")
#: entries that re-simulating the header's scenario, seed and commands reproduces
WORLD_ENTRIES = tuple(k for k in SCHEMA if not k.startswith(("command_", "replan_", "input_")))
#: entries a re-simulation reproduces or re-encodes (compared by ``Recording.mismatches``)
REPLAYED_ENTRIES = WORLD_ENTRIES + tuple(k for k in SCHEMA if k.startswith("command_"))


class RecordingError(FcplanError, ValueError):
    """A recording file is unreadable, foreign, corrupted, or cannot do what was asked."""


def jsonable(x: Any) -> Any:
    """Plain JSON values: numpy scalars and arrays to Python, tuples and sets to lists, NaN and
    infinities to None, dataclasses to dicts."""
    if isinstance(x, Mapping):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, set, frozenset)):
        items = sorted(x, key=str) if isinstance(x, (set, frozenset)) else x
        return [jsonable(v) for v in items]
    if isinstance(x, np.ndarray):
        return jsonable(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    if is_dataclass(x) and not isinstance(x, type):
        return jsonable(asdict(x))
    return str(x)


def versions() -> dict[str, str]:
    """Versions of fcplan, numpy and Python (kept in every header)."""
    return library_versions(("fcplan", "numpy"))


def cast_entries(arrays: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Every :data:`SCHEMA` entry of ``arrays`` as an array of its dtype (copied only if cast)."""
    out = {}
    for name, f in SCHEMA.items():
        a = np.asarray(arrays[name])
        if a.dtype != np.dtype(f.dtype):
            a = a.astype(f.dtype)
        out[name] = a
    return out
