"""Making recordings: the :class:`Recorder` observer and the in-memory :class:`Recording`.

A :class:`Recorder` is an :class:`fcplan.mission.EpisodeObserver`: give it to a
:class:`fcplan.mission.Mission` (``observers=[recorder]``; :func:`fcplan.run_episode` does with
``record=PATH``, the game always does) and it keeps every command, the fire events and the goal
each agent flies to, tick by tick, plus every plan and human input. :meth:`Recorder.recording`
turns that, with the world's trace, into a :class:`Recording`; :meth:`Recording.save` writes the
file (:mod:`fcplan.recording` documents the format). The two live together because each makes
the other: a recorder produces recordings, and :meth:`Recording.resimulate` records the episode
again.

Examples
--------
>>> from fcplan import load_scenario
>>> from fcplan.mission import Mission
>>> from fcplan.recording import Recorder
>>> from fcplan.team import Command
>>> sc = load_scenario("practice")
>>> rec = Recorder(sc, 3, source="human", settings={})
>>> mission = Mission(sc, seed=3, observers=[rec])
>>> mission.notify_input({"type": "click", "pos": [400, 400]})
>>> info = mission.step({"P1": Command(route=((400.0, 400.0),), altitude=50.0)})
>>> recording = rec.recording()
>>> recording.n_ticks, recording.inputs
(1, [{'type': 'click', 'pos': [400, 400]}])
>>> recording.resimulate().mismatches(recording)
[]
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.metrics import Metrics, compute_all
from fcplan.mission import BaseObserver, Commands, Mission
from fcplan.plan import Plan
from fcplan.recording.frames import recording_frames
from fcplan.recording.schema import (
    ALTITUDE,
    EVENTS,
    FORMAT,
    FORMAT_VERSION,
    HOME,
    JSON_ENTRIES,
    PATROL,
    REPLAYED_ENTRIES,
    ROUTE,
    SCHEMA,
    RecordingError,
    cast_entries,
    jsonable,
    versions,
)
from fcplan.scenario import Scenario
from fcplan.team import Command
from fcplan.trace import Trace
from fcplan.world import StepInfo, World

if TYPE_CHECKING:
    from fcplan.render import FrameData

__all__ = ["Recorder", "Recording", "scheduler_settings"]


def scheduler_settings(scheduler: Any) -> dict[str, Any]:
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


class Recorder(BaseObserver):
    """Collects one episode as it is played (an episode observer); :meth:`save` writes it.

    As an observer of a :class:`fcplan.mission.Mission` it hears every command before each
    step (:meth:`on_commands`), every step (:meth:`on_step`), every scheduler call
    (:meth:`on_replan`) and every raw human input (:meth:`on_input`); the hooks can also be
    called by hand around :meth:`fcplan.world.World.step`. Save before resetting the world.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    seed : int or None
        The seed the world was reset with (None: the recording cannot be re-simulated).
    source : str
        Scheduler name, or ``"human"``.
    settings : dict
        JSON-able settings worth keeping (replan period, time limit, scheduler settings, ...).
    """

    def __init__(
        self,
        scenario: Scenario,
        seed: Any,
        *,
        source: str,
        settings: Mapping[str, Any] | None = None,
    ) -> None:
        if seed is not None and not isinstance(seed, (int, np.integer)):
            seed = None  # SeedSequence / Generator: not storable, so not re-simulable
        self.scenario = scenario
        self.seed = None if seed is None else int(seed)
        self.source = str(source)
        self.settings = jsonable(dict(settings or {}))
        self._index = {a.id: i for i, a in enumerate(scenario.agents)}
        self._world: World | None = None
        self._events: dict[str, list[np.ndarray]] = {k: [] for k in EVENTS}
        self._goal_index: list[np.ndarray] = []
        self._cmd_tick: list[int] = []
        self._cmd_agent: list[int] = []
        self._cmd_flags: list[int] = []
        self._cmd_alt: list[float] = []
        self._cmd_routes: list[np.ndarray] = []
        self._replans: list[dict[str, Any]] = []
        self._replan_wall: list[float] = []
        self._inputs: list[dict[str, Any]] = []
        self._input_tick: list[int] = []

    def on_commands(self, tick: int, commands: Commands | None) -> None:
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
                flags |= ROUTE
                route = np.asarray(cmd.route, dtype=np.float64).reshape(-1, 2)
            if cmd.patrol:
                flags |= PATROL
            if cmd.home:
                flags |= HOME
            if cmd.altitude is not None:
                flags |= ALTITUDE
            self._cmd_tick.append(int(tick))
            self._cmd_agent.append(row)
            self._cmd_flags.append(flags)
            self._cmd_alt.append(float(cmd.altitude) if cmd.altitude is not None else math.nan)
            self._cmd_routes.append(route)

    def on_replan(self, tick: int, plan: Plan, stats: Any = None) -> None:
        """Record a scheduler's plan (task ids per agent) and its solve statistics (``stats``,
        by default the plan's)."""
        stats = stats if stats is not None else getattr(plan, "stats", None)
        as_dict = getattr(stats, "as_dict", None)
        entry = {
            "tick": int(tick),
            "routes": {a: list(r) for a, r in plan.routes.items()},
            "altitudes": dict(plan.altitudes),
            "patrol": sorted(plan.patrol),
            "home": sorted(plan.home),
            "stats": as_dict() if as_dict is not None else stats,
        }
        self._replans.append(jsonable(entry))
        self._replan_wall.append(float(getattr(stats, "wall_time_s", math.nan)))

    def on_step(self, world: World, info: StepInfo) -> None:
        """Record what one :meth:`fcplan.world.World.step` did (``info`` is its return value)."""
        self._world = world
        ev = self._events
        # own the event arrays: a view into a buffer the world reuses would change under us
        for key, arr in (("ignited", info.ignited), ("sensed", info.newly_sensed),
                         ("pruned", info.pruned)):  # fmt: skip
            ev[key].append(arr if arr.base is None else arr.copy())
        team = world.team
        self._goal_index.append(np.where(team.has_goal, team.goal_index, -1).astype(np.int16))

    def on_input(self, tick: int, event: Mapping[str, Any]) -> None:
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
        if self._world is not None:
            if self._world.tick != t:
                raise RecordingError(
                    f"the recorder saw {t} steps but the world is at tick {self._world.tick}; "
                    "call on_step after every step and save before resetting the world"
                )
            arrays = dict(self._world.trace().arrays())
        else:
            arrays = dict(World().reset(self.scenario, 0).trace().arrays())
        arrays.update(self._own_arrays())
        header = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "scenario": self.scenario.to_dict(),
            "seed": self.seed,
            "source": self.source,
            "settings": self.settings,
            "ticks": t,
            "versions": versions(),
        }
        return Recording(header, cast_entries(arrays), list(self._replans), list(self._inputs))

    def _own_arrays(self) -> dict[str, np.ndarray]:
        """The entries the recorder collects itself (goals, events, commands, replans, inputs)."""
        n = len(self._index)
        out = {
            "agent_goal_index": np.stack(self._goal_index)
            if self._goal_index
            else np.zeros((0, n), np.int16)
        }
        for k in EVENTS:
            parts = self._events[k]
            out[f"{k}_count"] = np.array([p.size for p in parts], dtype=np.int32)
            out[f"{k}_cells"] = (
                np.concatenate(parts).astype(np.int32) if parts else np.zeros(0, np.int32)
            )
        routes = self._cmd_routes
        out.update(
            command_tick=np.array(self._cmd_tick, dtype=np.int32),
            command_agent=np.array(self._cmd_agent, dtype=np.int16),
            command_flags=np.array(self._cmd_flags, dtype=np.uint8),
            command_altitude=np.array(self._cmd_alt, dtype=np.float64),
            command_route_len=np.array([len(x) for x in routes], dtype=np.int32),
            command_route_xy=np.concatenate(routes) if routes else np.zeros((0, 2)),
            replan_tick=np.array([r["tick"] for r in self._replans], dtype=np.int32),
            replan_wall_s=np.array(self._replan_wall, dtype=np.float64),
            input_tick=np.array(self._input_tick, dtype=np.int32),
        )
        return out

    def save(self, path: str | os.PathLike[str]) -> Recording:
        """Write the recording to ``path`` (an ``.npz`` file, replaced atomically); return it."""
        rec = self.recording()
        rec.save(path)
        return rec


@dataclass(frozen=True, eq=False)
class Recording:
    """One recorded episode: the JSON header, the arrays (see :mod:`fcplan.recording`), the plans
    and the human inputs."""

    header: dict[str, Any]
    arrays: dict[str, np.ndarray]
    replans: list[Any] = field(default_factory=list)
    inputs: list[Any] = field(default_factory=list)

    # ------------------------------------------------------------------ facts
    @cached_property
    def scenario(self) -> Scenario:
        """The recorded :class:`fcplan.scenario.Scenario`."""
        return Scenario.from_dict(self.header["scenario"], source="recording header")

    @property
    def seed(self) -> int | None:
        """The world's seed (None: not re-simulable)."""
        return self.header.get("seed")

    @property
    def source(self) -> str:
        """Scheduler name, ``"human"`` or ``"legacy"``."""
        return str(self.header.get("source", ""))

    @property
    def settings(self) -> dict[str, Any]:
        """Settings the episode ran with."""
        return self.header.get("settings", {})

    @property
    def n_ticks(self) -> int:
        """Number of recorded ticks."""
        return int(len(self.arrays["active"]))

    # ------------------------------------------------------------------ scores
    def trace(self) -> Trace:
        """The per-tick :class:`fcplan.trace.Trace`, rebuilt from the arrays and the scenario."""
        ids = (x.id for x in self.scenario.agents)
        return Trace.from_rows(self.scenario, self.arrays, ids, agent_prefix="agent_")

    def metrics(self) -> dict[str, Metrics]:
        """Both metric definitions (:func:`fcplan.metrics.compute_all`) from the recording alone."""
        return compute_all(self.trace())

    # ------------------------------------------------------------------ commands and replay
    def commands(self) -> dict[int, dict[Any, Command]]:
        """Recorded commands by tick, as given to :meth:`fcplan.world.World.step`."""
        a = self.arrays
        ids = [x.id for x in self.scenario.agents]
        ends = np.cumsum(a["command_route_len"])
        starts = ends - a["command_route_len"]
        out: dict[int, dict[Any, Command]] = {}
        xy = a["command_route_xy"]
        for c in range(len(a["command_tick"])):
            flags = int(a["command_flags"][c])
            route = None
            if flags & ROUTE:
                route = tuple((float(x), float(y)) for x, y in xy[starts[c] : ends[c]])
            alt = float(a["command_altitude"][c]) if flags & ALTITUDE else None
            cmd = Command(
                route=route, patrol=bool(flags & PATROL), altitude=alt, home=bool(flags & HOME)
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
        if self.seed is None:
            raise RecordingError(
                f"this recording ({self.source or 'unknown source'}) has no integer seed, so it "
                "cannot be re-simulated"
            )
        sc = self.scenario
        rec = Recorder(sc, self.seed, source=self.source, settings=self.settings)
        mission = Mission(sc, self.seed, observers=[rec], belief=False)
        by_tick = self.commands()
        for t in range(self.n_ticks):
            mission.step(by_tick.get(t))
        new = rec.recording()
        arrays = dict(new.arrays)
        for k in SCHEMA:
            if k.startswith(("replan_", "input_")):
                arrays[k] = self.arrays[k]
        header = dict(self.header, versions=new.header["versions"])
        return Recording(header, arrays, list(self.replans), list(self.inputs))

    def mismatches(self, other: Recording) -> list[str]:
        """Names of the world and command entries that differ from ``other``'s (empty:
        identical)."""
        return [
            k
            for k in REPLAYED_ENTRIES
            if not np.array_equal(self.arrays[k], other.arrays[k], equal_nan=True)
            or self.arrays[k].dtype != other.arrays[k].dtype
        ]

    def frames(
        self, start: int = 1, end: int | None = None, step: int = 1, *, scores: bool = True
    ) -> Iterator[FrameData]:
        """:class:`fcplan.render.FrameData` for ticks ``start, start + step, ... <= end``
        (:func:`fcplan.recording.frames.recording_frames`: true and known fire, pruned cells,
        agents, the routes still ahead of each agent and, with ``scores``, the online manual
        scores)."""
        trace = self.trace() if scores else None
        return recording_frames(self.scenario, self.arrays, trace, start, end, step)

    # ------------------------------------------------------------------ i/o
    def save(self, path: str | os.PathLike[str]) -> None:
        """Write this recording to ``path`` (``.npz``; written to a temporary file, then renamed)."""
        path = os.fspath(path)
        if os.path.exists(path) and not os.path.isfile(path):  # never replace a device or FIFO
            raise RecordingError(f"{path}: not a regular file; recordings are written to files")
        entries: dict[str, Any] = dict(self.arrays)
        for name, value in zip(JSON_ENTRIES, (self.header, self.replans, self.inputs), strict=True):
            entries[name] = np.array(json.dumps(jsonable(value), allow_nan=False))
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
