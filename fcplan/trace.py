"""Per-tick episode trace: the record every metric is computed from, and its schema.

A :class:`Trace` holds one row per simulated tick (after that tick's step) plus the few static
facts the metrics need (tick rate, scoring weights, facility penalties, region delays). Metrics are
pure functions of a trace (:mod:`fcplan.metrics`), so a recording, a replay or a hand-written test
array gives the same scores as the live episode.

Row ``k`` (0-based) describes the world at simulated time ``(k + 1) / ticks_per_second`` seconds.

The schema
----------
:data:`TRACE_FIELDS` is the one table of the per-tick arrays: the world writes its trace rows from
it (:meth:`fcplan.world.World.trace`), :class:`Trace` and :class:`AgentTrace` hold them, and an
episode recording stores them under the same keys with the same dtypes (:mod:`fcplan.recording`
adds its own entries to it). Axes: ``T`` ticks, ``N`` agents (scenario order: perception, action,
hybrid), ``F`` scored facilities (houses, hospitals, power stations, depot); an integer is a fixed
length.

=====================  =========  =======  ==================================================
key                    axes       dtype    meaning
=====================  =========  =======  ==================================================
``active``             (T,)       int64    ``|A|``: burning, unpruned cells
``pruned``             (T,)       int64    ``|P|``: cumulative pruned cells
``sensed_active``      (T,)       int64    ``|S ∩ A|``: active cells sensed at least once
``sensed_ever``        (T,)       int64    cells of ``A ∪ P`` sensed at least once
``facility_burning``   (T, F)     int64    active cells inside each facility footprint
``facility_pruned``    (T, F)     int64    cumulative pruned cells inside each footprint
``agent_xyz``          (T, N, 3)  float64  position (px) and altitude (m) after the tick
``agent_battery``      (T, N)     float64  remaining battery (capacity units)
``agent_tank``         (T, N)     int16    remaining dumps (0 for perception agents)
``agent_mode``         (T, N)     int8     :class:`fcplan.team.Mode` value
``agent_dumps``        (T, N)     int16    cumulative dumps
=====================  =========  =======  ==================================================

The ``agent_`` entries are the :class:`AgentTrace` attributes (and the world's rows) without the
prefix.

Examples
--------
>>> import numpy as np
>>> from fcplan.trace import TRACE_FIELDS, Trace
>>> tr = Trace.from_counts(ticks_per_second=10, active=[1, 2, 2], pruned=[0, 0, 1],
...                        sensed_active=[0, 1, 1], sensed_ever=[0, 1, 2])
>>> tr.n_ticks, tr.duration_s
(3, 0.3)
>>> [(f.key, f.dtype, f.axes) for f in TRACE_FIELDS][6]
('agent_xyz', 'float64', ('T', 'N', 3))
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Trace", "AgentTrace", "TraceField", "TRACE_FIELDS"]

#: an axis of a field: a dimension name (``"T"``, ``"N"``, ``"F"``, ...), a fixed length, or None
#: for a free length
Axis = str | int | None


@dataclass(frozen=True)
class TraceField:
    """One per-tick array of the schema (a row of the module docstring's table).

    Attributes
    ----------
    key : str
        Its name in :meth:`Trace.arrays` and in recordings.
    dtype : str
        numpy dtype name.
    axes : tuple
        Shape, each axis a dimension name, a fixed length or None (any length).
    doc : str
        What it holds.
    """

    key: str
    dtype: str
    axes: tuple[Axis, ...]
    doc: str = ""

    @property
    def agent(self) -> bool:
        """Whether it is an agent array (an :class:`AgentTrace` attribute)."""
        return self.key.startswith("agent_")

    @property
    def name(self) -> str:
        """The attribute of :class:`Trace` or :class:`AgentTrace` and the world's row name."""
        return self.key[len("agent_") :] if self.agent else self.key

    def shape(self, dims: Mapping[str, int]) -> tuple[int | None, ...]:
        """The shape for the dimension lengths ``dims`` (None: any length; an unknown name too)."""
        return tuple(dims.get(a) if isinstance(a, str) else a for a in self.axes)

    def fits(self, arr: np.ndarray, dims: Mapping[str, int]) -> bool:
        """Whether ``arr`` has this field's dtype and a shape that fits ``dims``."""
        want = self.shape(dims)
        if arr.dtype != np.dtype(self.dtype) or arr.ndim != len(want):
            return False
        return all(w is None or w == s for w, s in zip(want, arr.shape, strict=True))

    def zeros(self, dims: Mapping[str, int]) -> np.ndarray:
        """A zero array of this field for the dimension lengths ``dims`` (every axis known)."""
        shape = tuple(int(s) if s is not None else 0 for s in self.shape(dims))
        return np.zeros(shape, dtype=self.dtype)


#: The per-tick trace arrays, in order (see the module docstring).
TRACE_FIELDS: tuple[TraceField, ...] = (
    TraceField("active", "int64", ("T",), "burning, unpruned cells"),
    TraceField("pruned", "int64", ("T",), "cumulative pruned cells"),
    TraceField("sensed_active", "int64", ("T",), "active cells sensed at least once"),
    TraceField("sensed_ever", "int64", ("T",), "cells that ever burned and were sensed"),
    TraceField("facility_burning", "int64", ("T", "F"), "active cells inside each footprint"),
    TraceField("facility_pruned", "int64", ("T", "F"), "cumulative pruned cells in each footprint"),
    TraceField("agent_xyz", "float64", ("T", "N", 3), "position (px) and altitude (m)"),
    TraceField("agent_battery", "float64", ("T", "N"), "remaining battery"),
    TraceField("agent_tank", "int16", ("T", "N"), "remaining dumps"),
    TraceField("agent_mode", "int8", ("T", "N"), "fcplan.team.Mode value"),
    TraceField("agent_dumps", "int16", ("T", "N"), "cumulative dumps"),
)

#: default of the fields :meth:`Trace.__post_init__` fills in (None: derived from the others)
_DERIVED: Any = None


@dataclass(frozen=True, eq=False)
class AgentTrace:
    """Agent states per tick (the ``agent_`` fields of :data:`TRACE_FIELDS`). ``N`` agents in
    scenario order (perception, action, hybrid)."""

    ids: tuple[str, ...]
    xyz: np.ndarray  # (T, N, 3) float64 position and altitude after the tick
    battery: np.ndarray  # (T, N) float64 remaining battery (capacity units)
    tank: np.ndarray  # (T, N) int16 remaining dumps (0 for perception agents)
    mode: np.ndarray  # (T, N) int8 fcplan.team.Mode value
    dumps: np.ndarray  # (T, N) int16 cumulative dumps


@dataclass(frozen=True, eq=False)
class Trace:
    """Everything the scoring needs, tick by tick.

    Counts are over 1-px fire cells. ``active`` cells are burning and not pruned; ``pruned`` cells
    were put out (cumulative, they never burn again); ``A + P`` is every cell that ever burned.
    """

    ticks_per_second: int
    active: np.ndarray  # (T,) int64 |A|: burning, unpruned cells
    pruned: np.ndarray  # (T,) int64 |P|: cumulative pruned cells
    sensed_active: np.ndarray  # (T,) int64 |S ∩ A|: active cells sensed at least once
    sensed_ever: np.ndarray  # (T,) int64 cells of A ∪ P that were sensed at least once
    facility_burning: np.ndarray = field(default=_DERIVED)  # (T, F) int64 active cells in f
    facility_pruned: np.ndarray = field(default=_DERIVED)  # (T, F) int64 cumulative pruned in f
    facility_kinds: tuple[str, ...] = ()  # (F,) house | hospital | power_station | depot
    facility_penalties: np.ndarray = field(default=_DERIVED)  # (F,) float64 coefficient PC_f
    region_delays_s: np.ndarray = field(default=_DERIVED)  # (R,) float64 fire region delays
    fire_mode: str = "uniform"  # uniform | specific (reference2020 expectation)
    propagation_weight: float = 0.1  # w: penalty per active cell per second
    temporal_exponent: float = 1.25  # p: reference2020 time exponent
    agents: AgentTrace | None = None

    def __post_init__(self) -> None:
        t = len(self.active)
        for name in ("pruned", "sensed_active", "sensed_ever"):
            if len(getattr(self, name)) != t:
                raise ValueError(f"Trace.{name} has {len(getattr(self, name))} rows, expected {t}")
        if self.facility_burning is None:
            object.__setattr__(self, "facility_burning", np.zeros((t, 0), np.int64))
        if self.facility_pruned is None:
            object.__setattr__(self, "facility_pruned", np.zeros_like(self.facility_burning))
        if self.facility_penalties is None:
            object.__setattr__(self, "facility_penalties", np.zeros(self.facility_burning.shape[1]))
        if self.region_delays_s is None:
            object.__setattr__(self, "region_delays_s", np.zeros(1))
        f = self.facility_burning.shape[1]
        if self.facility_pruned.shape != (t, f) or len(self.facility_penalties) != f:
            raise ValueError("Trace facility arrays disagree in shape")
        if self.facility_kinds and len(self.facility_kinds) != f:
            raise ValueError("Trace.facility_kinds length disagrees with facility arrays")

    @classmethod
    def from_rows(
        cls,
        scenario: Any,
        rows: Mapping[str, np.ndarray],
        agent_ids: Sequence[str] | Any,
        *,
        agent_prefix: str = "",
    ) -> Trace:
        """Build a trace from per-tick row arrays and the scenario's constants.

        ``rows`` maps the :data:`TRACE_FIELDS` to arrays with one row per tick: the count fields
        by their key, the agent fields by their name after ``agent_prefix`` (the world's trace
        rows, ``xyz``, ``battery`` ...; or a recording's arrays, ``agent_xyz`` ..., with
        ``agent_prefix="agent_"``). The arrays are used as given, not copied.
        """
        per_agent: dict[str, Any] = {
            f.name: rows[agent_prefix + f.name] for f in TRACE_FIELDS if f.agent
        }
        counts: dict[str, Any] = {f.key: rows[f.key] for f in TRACE_FIELDS if not f.agent}
        facilities = scenario.scored_facilities
        return cls(
            ticks_per_second=scenario.ticks_per_second,
            **counts,
            facility_kinds=tuple(f.kind for f in facilities),
            facility_penalties=np.array([f.penalty for f in facilities], np.float64),
            region_delays_s=np.array([r.delay_s for r in scenario.regions], np.float64),
            fire_mode=scenario.fire_mode,
            propagation_weight=scenario.scoring.propagation_weight,
            temporal_exponent=scenario.scoring.temporal_exponent,
            agents=AgentTrace(ids=tuple(agent_ids), **per_agent),
        )

    @classmethod
    def from_counts(
        cls,
        *,
        ticks_per_second: int,
        active: Any,
        pruned: Any,
        sensed_active: Any,
        sensed_ever: Any,
        facility_burning: Any = None,
        facility_pruned: Any = None,
        facility_kinds: tuple[str, ...] = (),
        facility_penalties: Any = None,
        region_delays_s: Any = None,
        fire_mode: str = "uniform",
        propagation_weight: float = 0.1,
        temporal_exponent: float = 1.25,
    ) -> Trace:
        """Build a trace from plain sequences (handy for tests and hand-computed examples)."""

        def arr(x: Any, dtype: type = np.int64) -> Any:
            return None if x is None else np.asarray(x, dtype=dtype)

        fb = arr(facility_burning)
        if fb is not None and fb.ndim == 1:
            fb = fb[:, None]
        fp = arr(facility_pruned)
        if fp is not None and fp.ndim == 1:
            fp = fp[:, None]
        return cls(
            ticks_per_second=int(ticks_per_second),
            active=arr(active),
            pruned=arr(pruned),
            sensed_active=arr(sensed_active),
            sensed_ever=arr(sensed_ever),
            facility_burning=fb,
            facility_pruned=fp,
            facility_kinds=tuple(facility_kinds),
            facility_penalties=arr(facility_penalties, np.float64),
            region_delays_s=arr(region_delays_s, np.float64),
            fire_mode=fire_mode,
            propagation_weight=float(propagation_weight),
            temporal_exponent=float(temporal_exponent),
        )

    @property
    def n_ticks(self) -> int:
        """Number of ticks recorded."""
        return int(len(self.active))

    @property
    def duration_s(self) -> float:
        """Simulated seconds covered by the trace."""
        return self.n_ticks / self.ticks_per_second

    @property
    def times_s(self) -> np.ndarray:
        """(T,) simulated time of each row, ``(k + 1) / ticks_per_second``."""
        return np.arange(1, self.n_ticks + 1) / self.ticks_per_second

    def arrays(self) -> dict[str, np.ndarray]:
        """All per-tick arrays by their :data:`TRACE_FIELDS` key (the agent arrays only when the
        trace has agents), for byte-level comparisons and recordings."""
        agents = self.agents
        return {
            f.key: getattr(agents, f.name) if f.agent else getattr(self, f.key)
            for f in TRACE_FIELDS
            if agents is not None or not f.agent
        }
