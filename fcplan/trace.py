"""Per-tick episode trace: the record every metric is computed from.

A :class:`Trace` holds one row per simulated tick (after that tick's step) plus the few static
facts the metrics need (tick rate, scoring weights, facility penalties, region delays). Metrics are
pure functions of a trace (:mod:`fcplan.metrics`), so a recording, a replay or a hand-written test
array gives the same scores as the live episode.

Row ``k`` (0-based) describes the world at simulated time ``(k + 1) / ticks_per_second`` seconds.

Examples
--------
>>> import numpy as np
>>> from fcplan.trace import Trace
>>> tr = Trace.from_counts(ticks_per_second=10, active=[1, 2, 2], pruned=[0, 0, 1],
...                        sensed_active=[0, 1, 1], sensed_ever=[0, 1, 2])
>>> tr.n_ticks, tr.duration_s
(3, 0.3)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Trace", "AgentTrace"]

FACILITY_KINDS = ("house", "hospital", "power_station", "depot")


@dataclass(frozen=True, eq=False)
class AgentTrace:
    """Agent states per tick. ``N`` agents in scenario order (perception, action, hybrid)."""

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
    facility_burning: np.ndarray = field(default=None)  # (T, F) int64 active cells in footprint f
    facility_pruned: np.ndarray = field(default=None)  # (T, F) int64 cumulative pruned cells in f
    facility_kinds: tuple[str, ...] = ()  # (F,) house | hospital | power_station | depot
    facility_penalties: np.ndarray = field(default=None)  # (F,) float64 penalty coefficient PC_f
    region_delays_s: np.ndarray = field(default=None)  # (R,) float64 fire region delays
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
    def from_rows(cls, scenario, rows, agent_ids, *, agent_prefix: str = "") -> Trace:
        """Build a trace from per-tick row arrays and the scenario's constants.

        ``rows`` maps ``active``, ``pruned``, ``sensed_active``, ``sensed_ever``,
        ``facility_burning``, ``facility_pruned`` and, after ``agent_prefix``, ``xyz``,
        ``battery``, ``tank``, ``mode`` and ``dumps`` to arrays with one row per tick (the world's
        trace rows, or a recording's arrays with ``agent_prefix="agent_"``). The arrays are used
        as given, not copied.
        """
        p = agent_prefix
        agents = AgentTrace(
            ids=tuple(agent_ids),
            xyz=rows[p + "xyz"],
            battery=rows[p + "battery"],
            tank=rows[p + "tank"],
            mode=rows[p + "mode"],
            dumps=rows[p + "dumps"],
        )
        facilities = scenario.scored_facilities
        return cls(
            ticks_per_second=scenario.ticks_per_second,
            active=rows["active"],
            pruned=rows["pruned"],
            sensed_active=rows["sensed_active"],
            sensed_ever=rows["sensed_ever"],
            facility_burning=rows["facility_burning"],
            facility_pruned=rows["facility_pruned"],
            facility_kinds=tuple(f.kind for f in facilities),
            facility_penalties=np.array([f.penalty for f in facilities], np.float64),
            region_delays_s=np.array([r.delay_s for r in scenario.regions], np.float64),
            fire_mode=scenario.fire_mode,
            propagation_weight=scenario.scoring.propagation_weight,
            temporal_exponent=scenario.scoring.temporal_exponent,
            agents=agents,
        )

    @classmethod
    def from_counts(
        cls,
        *,
        ticks_per_second: int,
        active,
        pruned,
        sensed_active,
        sensed_ever,
        facility_burning=None,
        facility_pruned=None,
        facility_kinds: tuple[str, ...] = (),
        facility_penalties=None,
        region_delays_s=None,
        fire_mode: str = "uniform",
        propagation_weight: float = 0.1,
        temporal_exponent: float = 1.25,
    ) -> Trace:
        """Build a trace from plain sequences (handy for tests and hand-computed examples)."""

        def arr(x, dtype=np.int64):
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
        """All per-tick arrays by name (for byte-level comparisons and recordings)."""
        out = {
            "active": self.active,
            "pruned": self.pruned,
            "sensed_active": self.sensed_active,
            "sensed_ever": self.sensed_ever,
            "facility_burning": self.facility_burning,
            "facility_pruned": self.facility_pruned,
        }
        if self.agents is not None:
            for name in ("xyz", "battery", "tank", "mode", "dumps"):
                out[f"agent_{name}"] = getattr(self.agents, name)
        return out
