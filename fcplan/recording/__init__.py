"""Episode recordings: everything that happened in one episode, in one safe ``.npz`` file.

A recording is complete: its header holds the scenario and the seed, and its arrays hold every
command given to the team, so :meth:`Recording.resimulate` re-runs the world from the header and
reproduces every recorded array exactly, whether the commands came from a scheduler or from a
human playing the game. It also holds the per-tick trace, so :meth:`Recording.metrics` scores the
episode from the file alone, and the fire events, so a replay (:meth:`Recording.frames`) can draw
any tick without simulating.

Write one with :class:`Recorder`, an observer of the episode loop (:class:`fcplan.mission.Mission`,
``observers=[recorder]``; the game uses one too), with ``run_episode(..., record=PATH)`` or with
``fcplan run --record PATH``; read one with :func:`load_recording`.

=====================================  ======================================================
module                                 what
=====================================  ======================================================
:mod:`~fcplan.recording.schema`        the entries below (the trace schema
                                       :data:`fcplan.trace.TRACE_FIELDS` plus the recording's
                                       own), header constants, :class:`RecordingError`
:mod:`~fcplan.recording.writer`        :class:`Recorder` and the in-memory :class:`Recording`
:mod:`~fcplan.recording.reader`        :func:`load_recording` and its checks
:mod:`~fcplan.recording.frames`        replay frames rebuilt from a recording
=====================================  ======================================================

File format (version 1)
-----------------------
One ``numpy.savez_compressed`` archive; its arrays are :data:`fcplan.recording.schema.SCHEMA`. It is
loaded with ``allow_pickle=False``: no entry may be an object array, so opening a recording never
runs code. ``T`` ticks, ``N`` agents (scenario order:
perception, action, hybrid), ``F`` scored facilities (houses, hospitals, power stations, depot),
``W`` map side in px. Flat cell index = ``x * W + y``. Trace row ``k`` is the world after tick
``k + 1``.

=========================  ===========  =======  ===========================================================
entry                      shape        dtype    meaning
=========================  ===========  =======  ===========================================================
``header``                 ()           str      JSON: see below
``active``                 (T,)         int64    burning, unpruned cells (:class:`fcplan.trace.Trace`)
``pruned``                 (T,)         int64    cumulative pruned cells
``sensed_active``          (T,)         int64    active cells sensed at least once
``sensed_ever``            (T,)         int64    cells that ever burned and were sensed
``facility_burning``       (T, F)       int64    active cells inside each facility footprint
``facility_pruned``        (T, F)       int64    cumulative pruned cells inside each footprint
``agent_xyz``              (T, N, 3)    float64  position (px) and altitude (m) after the tick
``agent_battery``          (T, N)       float64  remaining battery
``agent_tank``             (T, N)       int16    remaining dumps
``agent_mode``             (T, N)       int8     :class:`fcplan.team.Mode`
``agent_dumps``            (T, N)       int16    cumulative dumps
``agent_goal_index``       (T, N)       int16    index of the goal being flown to in the agent's route, -1: none
``ignited_cells``          (I,)         int32    cells that started burning, tick by tick
``ignited_count``          (T,)         int32    how many of ``ignited_cells`` belong to each tick
``sensed_cells``           (S,)         int32    cells sensed for the first time, tick by tick
``sensed_count``           (T,)         int32    per tick
``pruned_cells``           (P,)         int32    cells put out, tick by tick
``pruned_count``           (T,)         int32    per tick
``command_tick``           (C,)         int32    tick at which a command was given (applied by step ``tick + 1``)
``command_agent``          (C,)         int16    agent row
``command_flags``          (C,)         uint8    bit 0 route given, 1 patrol, 2 home, 3 altitude given
``command_altitude``       (C,)         float64  target altitude (NaN when not given)
``command_route_len``      (C,)         int32    goals in the command's route
``command_route_xy``       (G, 2)       float64  every command's goals, concatenated in command order
``replan_tick``            (R,)         int32    tick of each replan
``replan_wall_s``          (R,)         float64  wall seconds of each scheduler call
``replans``                ()           str      JSON list, per replan: tick, plan (routes of task ids,
                                                 altitudes, patrol, home) and solve statistics
``input_tick``             (K,)         int32    tick of each human input
``inputs``                 ()           str      JSON list of the raw input events (dicts), in order
=========================  ===========  =======  ===========================================================

The header is a JSON object: ``format`` (``"fcplan-recording"``), ``format_version`` (2; version
1 reads too), ``scenario`` (:meth:`fcplan.scenario.Scenario.to_dict`), ``seed`` (int, or null
when the episode was not seeded: then it cannot be re-simulated), ``source`` (scheduler name, ``"human"`` or
``"legacy"``), ``settings`` (replan period, time limit, scheduler settings, ...), ``ticks`` (T) and
``versions`` (fcplan, numpy, python).

A 180-s episode of #24 with greedy takes about 0.1 MB (budget: 5 MB).

Examples
--------
>>> import os, tempfile
>>> from fcplan import run_episode
>>> from fcplan.recording import load_recording
>>> path = os.path.join(tempfile.mkdtemp(), "practice.npz")
>>> result = run_episode("practice", "greedy", seed=0, record=path)
>>> rec = load_recording(path)
>>> rec.source, rec.n_ticks
('greedy', 1800)
>>> rec.metrics()["manual"].final_score == result.metrics["manual"].final_score
True
"""

from __future__ import annotations

# (_read_bytes, _cast, _versions: private helpers fcplan.legacy imports from here)
from fcplan.recording.reader import load_recording
from fcplan.recording.reader import read_bytes as _read_bytes  # noqa: F401
from fcplan.recording.schema import (
    FORMAT,
    FORMAT_VERSION,
    SCHEMA,
    WORLD_ENTRIES,
    RecordingError,
)
from fcplan.recording.schema import cast_entries as _cast  # noqa: F401
from fcplan.recording.schema import versions as _versions  # noqa: F401
from fcplan.recording.writer import Recorder, Recording, scheduler_settings

__all__ = [
    "Recorder",
    "Recording",
    "RecordingError",
    "load_recording",
    "scheduler_settings",
    "FORMAT",
    "FORMAT_VERSION",
    "SCHEMA",
    "WORLD_ENTRIES",
]
