"""Episode recordings: everything that happened in one episode, in one safe ``.npz`` file.

A recording is complete: its header holds the scenario and the seed, and its arrays hold every
command given to the team, so :meth:`Recording.resimulate` re-runs the world from the header and
reproduces every recorded array exactly, whether the commands came from a scheduler or from a
human playing the game. It also holds the per-tick trace, so :meth:`Recording.metrics` scores the
episode from the file alone, and the fire events, so a replay (:meth:`Recording.frames`) can draw
any tick without simulating.

Write one with :class:`Recorder` (hooks called by the episode loop or the game), with
``run_episode(..., record=PATH)`` or with ``fcplan run --record PATH``; read one with
:func:`load_recording`.

File format (version 1)
-----------------------
One ``numpy.savez_compressed`` archive. It is loaded with ``allow_pickle=False``: no entry may be an
object array, so opening a recording never runs code. ``T`` ticks, ``N`` agents (scenario order:
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

The header is a JSON object: ``format`` (``"fcplan-recording"``), ``format_version`` (1),
``scenario`` (:meth:`fcplan.scenario.Scenario.to_dict`), ``seed`` (int, or null when the episode
was not seeded: then it cannot be re-simulated), ``source`` (scheduler name, ``"human"`` or
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

import io
import json
import math
import os
import sys
import zipfile
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.team import Command

__all__ = [
    "Recorder",
    "Recording",
    "RecordingError",
    "load_recording",
    "scheduler_settings",
    "FORMAT",
    "FORMAT_VERSION",
]

FORMAT = "fcplan-recording"
FORMAT_VERSION = 1

_ROUTE, _PATROL, _HOME, _ALTITUDE = 1, 2, 4, 8
_EVENTS = ("ignited", "sensed", "pruned")

#: entry -> (dtype, shape with "T", "N", "F" or None for a free axis): the file schema.
_SCHEMA: dict[str, tuple[str, tuple]] = {
    "active": ("int64", ("T",)),
    "pruned": ("int64", ("T",)),
    "sensed_active": ("int64", ("T",)),
    "sensed_ever": ("int64", ("T",)),
    "facility_burning": ("int64", ("T", "F")),
    "facility_pruned": ("int64", ("T", "F")),
    "agent_xyz": ("float64", ("T", "N", 3)),
    "agent_battery": ("float64", ("T", "N")),
    "agent_tank": ("int16", ("T", "N")),
    "agent_mode": ("int8", ("T", "N")),
    "agent_dumps": ("int16", ("T", "N")),
    "agent_goal_index": ("int16", ("T", "N")),
    "ignited_cells": ("int32", (None,)),
    "ignited_count": ("int32", ("T",)),
    "sensed_cells": ("int32", (None,)),
    "sensed_count": ("int32", ("T",)),
    "pruned_cells": ("int32", (None,)),
    "pruned_count": ("int32", ("T",)),
    "command_tick": ("int32", ("C",)),
    "command_agent": ("int16", ("C",)),
    "command_flags": ("uint8", ("C",)),
    "command_altitude": ("float64", ("C",)),
    "command_route_len": ("int32", ("C",)),
    "command_route_xy": ("float64", (None, 2)),
    "replan_tick": ("int32", ("R",)),
    "replan_wall_s": ("float64", ("R",)),
    "input_tick": ("int32", ("K",)),
}
_JSON_ENTRIES = ("header", "replans", "inputs")
#: entries that re-simulating the header's scenario, seed and commands reproduces
WORLD_ENTRIES = tuple(k for k in _SCHEMA if not k.startswith(("command_", "replan_", "input_")))


class RecordingError(FcplanError, ValueError):
    """A recording file is unreadable, foreign, corrupted, or cannot do what was asked."""


# ---------------------------------------------------------------------------------------- json
def _jsonable(x: Any) -> Any:
    """Plain JSON values: numpy scalars and arrays to Python, tuples and sets to lists, NaN and
    infinities to None."""
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, set, frozenset)):
        items = sorted(x, key=str) if isinstance(x, (set, frozenset)) else x
        return [_jsonable(v) for v in items]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if x is None or isinstance(x, (bool, int, float, str)):
        return x
    if hasattr(x, "__dataclass_fields__"):
        from dataclasses import asdict

        return _jsonable(asdict(x))
    return str(x)


def scheduler_settings(scheduler) -> dict[str, Any]:
    """The plain public attributes of a scheduler object (numbers, strings, booleans, None), a
    best-effort record of its settings.

    Examples
    --------
    >>> from fcplan import make_scheduler
    >>> scheduler_settings(make_scheduler("routing:deterministic=true"))["deterministic"]
    True
    """
    attrs = getattr(scheduler, "__dict__", {})
    return {
        k: v
        for k, v in attrs.items()
        if not k.startswith("_") and (v is None or isinstance(v, (bool, int, float, str)))
    }


def _versions() -> dict[str, str]:
    import fcplan

    return {
        "fcplan": fcplan.__version__,
        "numpy": np.__version__,
        "python": ".".join(map(str, sys.version_info[:3])),
    }


# ------------------------------------------------------------------------------------ recorder
class Recorder:
    """Collects one episode as it is played; :meth:`save` writes it.

    Call :meth:`on_commands` with every command dict passed to :meth:`fcplan.world.World.step`
    (before the step), :meth:`on_step` after every step, :meth:`on_replan` after every scheduler
    call and :meth:`on_input` for every raw human input. Save before resetting the world.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    seed : int or None
        The seed the world was reset with (None: the recording cannot be re-simulated).
    source : str
        Scheduler name, or ``"human"``.
    settings : dict
        JSON-able settings worth keeping (replan period, time limit, scheduler settings, ...).

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> from fcplan.team import Command
    >>> sc = load_scenario("practice")
    >>> world, rec = World().reset(sc, seed=3), Recorder(sc, 3, source="human", settings={})
    >>> cmds = {"P1": Command(route=((400.0, 400.0),), altitude=50.0)}
    >>> rec.on_input(0, {"type": "click", "pos": [400, 400]})
    >>> rec.on_commands(world.tick, cmds)
    >>> rec.on_step(world, world.step(cmds))
    >>> rec.recording().n_ticks
    1
    """

    def __init__(self, scenario, seed, *, source: str, settings: dict | None = None) -> None:
        if seed is not None and not isinstance(seed, (int, np.integer)):
            seed = None  # SeedSequence / Generator: not storable, so not re-simulable
        self.scenario = scenario
        self.seed = None if seed is None else int(seed)
        self.source = str(source)
        self.settings = _jsonable(dict(settings or {}))
        self._index = {a.id: i for i, a in enumerate(scenario.agents)}
        self._world = None
        self._events: dict[str, list[np.ndarray]] = {k: [] for k in _EVENTS}
        self._goal_index: list[np.ndarray] = []
        self._cmd_tick: list[int] = []
        self._cmd_agent: list[int] = []
        self._cmd_flags: list[int] = []
        self._cmd_alt: list[float] = []
        self._cmd_routes: list[np.ndarray] = []
        self._replans: list[dict] = []
        self._replan_wall: list[float] = []
        self._inputs: list[dict] = []
        self._input_tick: list[int] = []

    def on_commands(self, tick: int, commands: Mapping[str | int, Command] | None) -> None:
        """Record the command dict given to the world at ``tick`` (its tick before the step)."""
        if not commands:
            return
        for key, cmd in commands.items():
            row = int(key) if isinstance(key, (int, np.integer)) else self._index.get(key, -1)
            if not 0 <= row < len(self._index):
                raise RecordingError(f"command for unknown agent {key!r}")
            flags = 0
            route = np.zeros((0, 2))
            if cmd.route is not None:
                flags |= _ROUTE
                route = np.asarray(cmd.route, dtype=np.float64).reshape(-1, 2)
            if cmd.patrol:
                flags |= _PATROL
            if cmd.home:
                flags |= _HOME
            if cmd.altitude is not None:
                flags |= _ALTITUDE
            self._cmd_tick.append(int(tick))
            self._cmd_agent.append(row)
            self._cmd_flags.append(flags)
            self._cmd_alt.append(float(cmd.altitude) if cmd.altitude is not None else math.nan)
            self._cmd_routes.append(route)

    def on_replan(self, tick: int, plan, stats=None) -> None:
        """Record a scheduler's plan (task ids per agent) and its solve statistics."""
        stats = stats if stats is not None else getattr(plan, "stats", None)
        entry = {
            "tick": int(tick),
            "routes": {a: list(r) for a, r in plan.routes.items()},
            "altitudes": dict(plan.altitudes),
            "patrol": sorted(plan.patrol),
            "home": sorted(plan.home),
            "stats": stats.as_dict() if hasattr(stats, "as_dict") else stats,
        }
        self._replans.append(_jsonable(entry))
        self._replan_wall.append(float(getattr(stats, "wall_time_s", math.nan)))

    def on_step(self, world, info) -> None:
        """Record what one :meth:`fcplan.world.World.step` did (``info`` is its return value)."""
        self._world = world
        ev = self._events
        # own the event arrays: a view into a buffer the world reuses would change under us
        for key, arr in (("ignited", info.ignited), ("sensed", info.newly_sensed),
                         ("pruned", info.pruned)):  # fmt: skip
            ev[key].append(arr if arr.base is None else arr.copy())
        team = world.team
        self._goal_index.append(np.where(team.has_goal, team.goal_index, -1).astype(np.int16))

    def on_input(self, tick: int, event: dict) -> None:
        """Record one raw human input (a JSON-able dict, e.g. ``{"type": "key", "key": "up"}``)."""
        try:
            json.dumps(event)
        except (TypeError, ValueError) as exc:
            raise RecordingError(f"input event is not JSON-able: {exc}") from None
        self._inputs.append(dict(event))
        self._input_tick.append(int(tick))

    @property
    def n_ticks(self) -> int:
        """Steps recorded so far."""
        return len(self._goal_index)

    def recording(self) -> Recording:
        """The recording so far, in memory."""
        t = self.n_ticks
        n = len(self._index)
        if self._world is not None:
            if self._world.tick != t:
                raise RecordingError(
                    f"the recorder saw {t} steps but the world is at tick {self._world.tick}; "
                    "call on_step after every step and save before resetting the world"
                )
            arrays = {k: v for k, v in self._world.trace().arrays().items()}
        else:
            from fcplan.world import World

            arrays = World().reset(self.scenario, 0).trace().arrays()
        arrays["agent_goal_index"] = np.stack(self._goal_index) if t else np.zeros((0, n), np.int16)
        for k in _EVENTS:
            parts = self._events[k]
            arrays[f"{k}_count"] = np.array([p.size for p in parts], dtype=np.int32)
            arrays[f"{k}_cells"] = (
                np.concatenate(parts).astype(np.int32) if parts else np.zeros(0, np.int32)
            )
        arrays.update(_command_arrays(self))
        arrays["replan_tick"] = np.array([r["tick"] for r in self._replans], dtype=np.int32)
        arrays["replan_wall_s"] = np.array(self._replan_wall, dtype=np.float64)
        arrays["input_tick"] = np.array(self._input_tick, dtype=np.int32)
        header = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "scenario": self.scenario.to_dict(),
            "seed": self.seed,
            "source": self.source,
            "settings": self.settings,
            "ticks": t,
            "versions": _versions(),
        }
        return Recording(header, _cast(arrays), list(self._replans), list(self._inputs))

    def save(self, path: str | os.PathLike) -> Recording:
        """Write the recording to ``path`` (an ``.npz`` file, replaced atomically); return it."""
        rec = self.recording()
        rec.save(path)
        return rec


def _command_arrays(r: Recorder) -> dict[str, np.ndarray]:
    routes = r._cmd_routes
    return {
        "command_tick": np.array(r._cmd_tick, dtype=np.int32),
        "command_agent": np.array(r._cmd_agent, dtype=np.int16),
        "command_flags": np.array(r._cmd_flags, dtype=np.uint8),
        "command_altitude": np.array(r._cmd_alt, dtype=np.float64),
        "command_route_len": np.array([len(x) for x in routes], dtype=np.int32),
        "command_route_xy": np.concatenate(routes) if routes else np.zeros((0, 2)),
    }


def _cast(arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    out = {}
    for name, (dtype, _) in _SCHEMA.items():
        a = np.asarray(arrays[name])
        if a.dtype != np.dtype(dtype):
            a = a.astype(dtype)
        out[name] = a
    return out


# ----------------------------------------------------------------------------------- recording
@dataclass(frozen=True, eq=False)
class Recording:
    """One recorded episode: the JSON header, the arrays (see the module docstring), the plans
    and the human inputs."""

    header: dict
    arrays: dict[str, np.ndarray]
    replans: list = field(default_factory=list)
    inputs: list = field(default_factory=list)

    # ------------------------------------------------------------------ facts
    @cached_property
    def scenario(self):
        """The recorded :class:`fcplan.scenario.Scenario`."""
        from fcplan.scenario import Scenario

        return Scenario.from_dict(self.header["scenario"], source="recording header")

    @property
    def seed(self) -> int | None:
        """The world's seed (None: not re-simulable)."""
        return self.header.get("seed")

    @property
    def source(self) -> str:
        """Scheduler name, ``"human"`` or ``"legacy"``."""
        return self.header.get("source", "")

    @property
    def settings(self) -> dict:
        """Settings the episode ran with."""
        return self.header.get("settings", {})

    @property
    def n_ticks(self) -> int:
        """Number of recorded ticks."""
        return int(len(self.arrays["active"]))

    # ------------------------------------------------------------------ scores
    def trace(self):
        """The per-tick :class:`fcplan.trace.Trace`, rebuilt from the arrays and the scenario."""
        from fcplan.trace import Trace

        ids = (x.id for x in self.scenario.agents)
        return Trace.from_rows(self.scenario, self.arrays, ids, agent_prefix="agent_")

    def metrics(self) -> dict:
        """Both metric definitions (:func:`fcplan.metrics.compute_all`) from the recording alone."""
        from fcplan.metrics import compute_all

        return compute_all(self.trace())

    # ------------------------------------------------------------------ commands and replay
    def commands(self) -> dict[int, dict[str, Command]]:
        """Recorded commands by tick, as given to :meth:`fcplan.world.World.step`."""
        a = self.arrays
        ids = [x.id for x in self.scenario.agents]
        ends = np.cumsum(a["command_route_len"])
        starts = ends - a["command_route_len"]
        out: dict[int, dict[str, Command]] = {}
        xy = a["command_route_xy"]
        for c in range(len(a["command_tick"])):
            flags = int(a["command_flags"][c])
            route = None
            if flags & _ROUTE:
                route = tuple((float(x), float(y)) for x, y in xy[starts[c] : ends[c]])
            alt = float(a["command_altitude"][c]) if flags & _ALTITUDE else None
            cmd = Command(
                route=route, patrol=bool(flags & _PATROL), altitude=alt, home=bool(flags & _HOME)
            )
            row = int(a["command_agent"][c])
            at = out.setdefault(int(a["command_tick"][c]), {})
            # an agent named twice in one dict (by id and by row) keeps both, in order
            at[ids[row] if ids[row] not in at else row] = cmd
        return out

    def resimulate(self) -> Recording:
        """Re-run the world from the header's scenario and seed, applying the recorded commands at
        their ticks; return the new recording (its world arrays equal this one's when the
        recording is intact)."""
        from fcplan.world import World

        if self.seed is None:
            raise RecordingError(
                f"this recording ({self.source or 'unknown source'}) has no integer seed, so it "
                "cannot be re-simulated"
            )
        sc = self.scenario
        world = World().reset(sc, self.seed)
        rec = Recorder(sc, self.seed, source=self.source, settings=self.settings)
        by_tick = self.commands()
        for t in range(self.n_ticks):
            cmds = by_tick.get(t)
            rec.on_commands(t, cmds)
            rec.on_step(world, world.step(cmds))
        new = rec.recording()
        arrays = dict(new.arrays)
        for k in _SCHEMA:
            if k.startswith(("replan_", "input_")):
                arrays[k] = self.arrays[k]
        header = dict(self.header, versions=new.header["versions"])
        return Recording(header, arrays, list(self.replans), list(self.inputs))

    def mismatches(self, other: Recording) -> list[str]:
        """Names of the world entries that differ from ``other``'s (empty: identical)."""
        return [
            k
            for k in WORLD_ENTRIES + tuple(k for k in _SCHEMA if k.startswith("command_"))
            if not np.array_equal(self.arrays[k], other.arrays[k], equal_nan=True)
            or self.arrays[k].dtype != other.arrays[k].dtype
        ]

    def frames(
        self, start: int = 1, end: int | None = None, step: int = 1, *, scores: bool = True
    ) -> Iterator:
        """:class:`fcplan.render.FrameData` for ticks ``start, start + step, ... <= end``.

        Tick ``t`` (1..T) shows the world after ``t`` steps: true fire (cumulative ignitions
        minus prunes), known fire (cells sensed and still burning), pruned cells, agents, the
        routes still ahead of each agent (from the last command it got) and, with ``scores``,
        the online manual scores.
        """
        from fcplan.fire import BURNING, PRUNED
        from fcplan.render import FrameData

        t_max = self.n_ticks
        end = t_max if end is None else min(int(end), t_max)
        start = max(int(start), 1)
        step = max(int(step), 1)
        a, sc = self.arrays, self.scenario
        w = sc.world_size
        state = np.zeros(w * w, dtype=np.uint8)
        sensed = np.zeros(w * w, dtype=bool)
        offs = {
            k: np.concatenate([[0], np.cumsum(a[f"{k}_count"], dtype=np.int64)]) for k in _EVENTS
        }
        roles = np.array([int(x.role) for x in sc.agents])
        can_sense, can_act = roles != 1, roles != 0
        homes = np.array([x.start for x in sc.agents], np.float64).reshape(-1, 2)
        routes_by_agent = self._route_history()
        trace = self.trace() if scores else None
        done = 0  # ticks folded into the grids
        for t in range(start, end + 1, step):
            for k in _EVENTS:
                cells = a[f"{k}_cells"][offs[k][done] : offs[k][t]]
                if k == "ignited":
                    state[cells] = BURNING
                elif k == "sensed":
                    sensed[cells] = True
                else:
                    state[cells] = PRUNED
            done = t
            row = t - 1
            mode = a["agent_mode"][row]
            routes = []
            for i in range(len(sc.agents)):
                if mode[i] in (2, 3):
                    routes.append(homes[i : i + 1])
                    continue
                k = int(a["agent_goal_index"][row, i])
                route, patrol = _route_at(routes_by_agent[i], t)
                if k < 0 or route is None or k >= len(route):
                    routes.append(np.zeros((0, 2)))
                else:
                    ahead = route[k:]
                    if patrol and k > 0:
                        ahead = np.concatenate([ahead, route[:k]])
                    routes.append(ahead)
            fire = state.reshape(w, w).copy()
            yield FrameData(
                tick=t,
                time_s=t / sc.ticks_per_second,
                fire=fire,
                known=(sensed.reshape(w, w) & (fire == BURNING)),
                pruned=fire == PRUNED,
                agent_pos=a["agent_xyz"][row, :, :2].copy(),
                agent_z=a["agent_xyz"][row, :, 2].copy(),
                agent_can_sense=can_sense,
                agent_can_act=can_act,
                agent_battery=a["agent_battery"][row].copy(),
                agent_tank=a["agent_tank"][row].copy(),
                agent_mode=mode.copy(),
                routes=tuple(routes),
                scores=_online_scores(trace, t) if trace is not None else {},
            )

    def _route_history(self) -> list[list[tuple[int, np.ndarray | None, bool]]]:
        """Per agent, (tick the command takes effect, route or None for home, patrol)."""
        a = self.arrays
        hist: list[list] = [[] for _ in self.scenario.agents]
        ends = np.cumsum(a["command_route_len"])
        starts = ends - a["command_route_len"]
        for c in range(len(a["command_tick"])):
            flags = int(a["command_flags"][c])
            i = int(a["command_agent"][c])
            if flags & _HOME:
                hist[i].append((int(a["command_tick"][c]) + 1, None, False))
            elif flags & _ROUTE:
                route = a["command_route_xy"][starts[c] : ends[c]]
                hist[i].append((int(a["command_tick"][c]) + 1, route, bool(flags & _PATROL)))
        return hist

    # ------------------------------------------------------------------ i/o
    def save(self, path: str | os.PathLike) -> None:
        """Write this recording to ``path`` (``.npz``; written to a temporary file, then renamed)."""
        path = os.fspath(path)
        entries = dict(self.arrays)
        entries["header"] = np.array(json.dumps(_jsonable(self.header), allow_nan=False))
        entries["replans"] = np.array(json.dumps(_jsonable(self.replans), allow_nan=False))
        entries["inputs"] = np.array(json.dumps(_jsonable(self.inputs), allow_nan=False))
        tmp = f"{path}.tmp{os.getpid()}"
        try:
            with open(tmp, "wb") as f:
                np.savez_compressed(f, **entries)
            os.replace(tmp, path)
        except OSError as exc:
            raise RecordingError(f"{path}: cannot write the recording: {exc.strerror}") from None
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)


def _route_at(history, t: int) -> tuple[np.ndarray | None, bool]:
    """The route in force at tick ``t`` from an agent's command history."""
    route, patrol = None, False
    for tick, r, p in history:
        if tick > t:
            break
        route, patrol = r, p
    return route, patrol


def _online_scores(trace, t: int) -> dict[str, float]:
    from fcplan.metrics import compute_metrics

    m = compute_metrics(trace, "manual", upto=t)
    return {
        "final score": m.final_score,
        "negative reward": -m.total_negative_reward,
        "firefighting (OFS)": m.overall_firefighting,
        "perception (PS)": m.perception,
        "action (AS)": m.action,
        "facilities (FPS)": m.facility_protection,
        "neg. reward ratio": m.negative_reward_ratio,
    }


# ------------------------------------------------------------------------------------- loading
def _read_bytes(path: str, error: type[FcplanError]) -> bytes:
    """The whole file, or ``error`` naming it and the reason."""
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror}") from None


def load_recording(path: str | os.PathLike) -> Recording:
    """Read and check a recording written by :meth:`Recorder.save` (never unpickles anything).

    Raises
    ------
    RecordingError
        If the file is missing, not an npz archive, holds object arrays, is not an fcplan
        recording, has an unknown format version, or an entry has the wrong dtype or shape.
    """
    path = os.fspath(path)
    data = _read_bytes(path, RecordingError)
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


def _load_json(raw: dict, name: str, path: str) -> Any:
    a = raw.get(name)
    if a is None or a.dtype.kind != "U" or a.shape != ():
        raise RecordingError(f"{path}: entry {name!r} must be a JSON string")
    try:
        return json.loads(str(a))
    except json.JSONDecodeError as exc:
        raise RecordingError(f"{path}: entry {name!r} is not valid JSON ({exc.msg})") from None


def _from_entries(raw: dict, path: str) -> Recording:
    header = _load_json(raw, "header", path)
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise RecordingError(f"{path}: not an fcplan recording (header.format is not {FORMAT!r})")
    if header.get("format_version") != FORMAT_VERSION:
        raise RecordingError(
            f"{path}: header.format_version {header.get('format_version')!r} is not supported "
            f"(this fcplan reads version {FORMAT_VERSION})"
        )
    missing = [k for k in (*_SCHEMA, *_JSON_ENTRIES) if k not in raw]
    if missing:
        raise RecordingError(f"{path}: missing entries {', '.join(missing)}")
    replans = _load_json(raw, "replans", path)
    inputs = _load_json(raw, "inputs", path)
    rec = Recording(header, {k: raw[k] for k in _SCHEMA}, replans, inputs)
    try:
        sc = rec.scenario
    except FcplanError as exc:
        raise RecordingError(f"{path}: header.scenario: {exc}") from None
    _check_arrays(rec, sc, path)
    return rec


def _check_arrays(rec: Recording, sc, path: str) -> None:
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
    for name, (dtype, shape) in _SCHEMA.items():
        arr = a[name]
        want = tuple(dims.get(d, d) if isinstance(d, str) else d for d in shape)
        ok = arr.dtype == np.dtype(dtype) and arr.ndim == len(want)
        ok = ok and all(w is None or w == s for w, s in zip(want, arr.shape, strict=False))
        if not ok:
            shown = tuple("*" if w is None else w for w in want)
            raise RecordingError(
                f"{path}: entry {name!r} is {arr.dtype}{list(arr.shape)}, expected {dtype}"
                f"{list(shown)}"
            )
    ncell = sc.world_size**2
    for k in _EVENTS:
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
