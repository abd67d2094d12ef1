"""Task-graph types: task kinds, the builder's settings, and :class:`TaskGraph` with its views.

A :class:`TaskGraph` holds ``A`` agents, ``K`` tasks (fire tiles first, then search blocks) and
``F`` scored facilities as numpy arrays (fields), plus views derived from them on first use:
distances, who can serve what, the **feasibility rule**, and a networkx view.

The feasibility rule
--------------------
One rule says which routes an agent can fly; plan validation
(:func:`fcplan.plan.validate_plan`), every built-in scheduler and the task-level environment's
action mask all read it from these views, so a scheduler author can use it too:

* an agent's next route starts at :attr:`TaskGraph.agent_start_pos` with
  :attr:`TaskGraph.agent_budget_px` px of flight: where it is with ``battery / DRAIN_PER_PX``,
  or, on a forced return (``Mode.RETURNING``: it recharges first), at its depot slot with a
  full battery (:attr:`TaskGraph.agent_full_range`);
* a task is only ever worth a visit if it lies within a round trip of the agent's depot slot
  on a full battery: ``2 * task_home_distance <= agent_full_range``
  (:attr:`TaskGraph.in_round_trip`);
* a plan is valid when, besides, the agent's role can serve each task of its route
  (:attr:`TaskGraph.can_do`) and the agent can reach the first task and fly home from it on
  what it has left (on a forced return it recharges first). For a one-task route that is
  :attr:`TaskGraph.reachable`;
* the built-in schedulers keep whole routes flyable without a stop at the depot:
  :meth:`TaskGraph.route_ok` (start, the tasks in order, home: at most the budget).

Every comparison allows :data:`FEASIBILITY_TOL_PX` of rounding. Perception altitudes are
clipped to the agent's bounds by :meth:`TaskGraph.clip_altitude`.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> g.reachable.shape, g.agent_budget_px.shape
((3, 6), (3,))
>>> i, k = np.argwhere(g.reachable)[0]
>>> g.route_ok(int(i), [int(k)])
True
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import IntEnum
from typing import Any, Generic, TypeVar, overload

import numpy as np

from fcplan.scenario import Role
from fcplan.team import DRAIN_PER_PX, Mode

__all__ = [
    "FEASIBILITY_TOL_PX",
    "SharedMemo",
    "TaskKind",
    "TaskGraph",
    "TaskGraphParams",
    "grid_block_name",
]

#: Slack (px) of every battery comparison of the feasibility rule: the same route length summed
#: in another order may differ in its last bits.
FEASIBILITY_TOL_PX = 1e-6

_T = TypeVar("_T")


class cached_view(Generic[_T]):  # noqa: N801 - named like functools.cached_property
    """:func:`functools.cached_property` without its lock (Python 3.11 takes one at every first
    access, a third of the cost of the cheaper views; graphs are not shared between threads
    while their views are being filled in). The value is kept in the instance's ``__dict__``,
    which also lets a builder fill views in at construction."""

    def __init__(self, func: Callable[[Any], _T]) -> None:
        self.func = func
        self.__doc__ = func.__doc__
        self.name = func.__name__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> cached_view[_T]: ...
    @overload
    def __get__(self, obj: object, owner: type | None = None) -> _T: ...
    def __get__(self, obj: object | None, owner: type | None = None) -> cached_view[_T] | _T:
        if obj is None:
            return self
        value = obj.__dict__[self.name] = self.func(obj)
        return value


class TaskKind(IntEnum):
    """Kinds of task nodes."""

    FIRE = 0
    SEARCH = 1


_FIRE_KIND = int(TaskKind.FIRE)  # a plain int compares with arrays faster than the enum member
_RETURNING = int(Mode.RETURNING)


@dataclass(frozen=True, slots=True)
class TaskGraphParams:
    """How the belief is turned into tasks.

    Parameters
    ----------
    tile_px : (float, float), optional
        Fire tile size (x, y). Default: 90 % of the smallest action/hybrid field of view at its
        working altitude, so a dump centred on a tile covers all of it.
    search_block_px : int
        Side of a search block.
    threat_radius_px : float
        Fires closer than this to a facility footprint threaten it.
    search_value_cap_s : float
        Coverage age beyond which a search block is not worth more.
    """

    tile_px: tuple[float, float] | None = None
    search_block_px: int = 100
    threat_radius_px: float = 250.0
    search_value_cap_s: float = 60.0


def grid_block_name(bx: int, by: int) -> str:
    """Chess-style name of a 100-px block, e.g. ``(3, 4) -> "D-05"``."""
    letters = ""
    n = bx + 1
    while n:
        n, r = divmod(n - 1, 26)
        letters = chr(65 + r) + letters
    return f"{letters}-{by + 1:02d}"


class SharedMemo:
    """Values derived from the read-only arrays that the graphs of one builder share.

    A :class:`fcplan.taskgraph.TaskGraphBuilder` gives the graphs it builds the same read-only
    arrays wherever nothing changed (the agents' constants; without known fire, the search
    blocks), and one memo (:attr:`TaskGraph.shared_memo`). Whoever derives something from such
    arrays at every replan (the feasibility views, the environment's feature rows) keeps it
    here: ``memo.get(key, inputs, make)`` returns the value kept under ``key`` if it was made
    from these very arrays, else ``make()``, kept only when every input is read-only (so that
    it cannot go stale; a kept array is made read-only too).

    Examples
    --------
    >>> import numpy as np
    >>> a = np.arange(3.0)
    >>> a.flags.writeable = False
    >>> memo = SharedMemo()
    >>> memo.get("total", (a,), lambda: float(a.sum()))
    3.0
    >>> memo.get("total", (a,), lambda: -1.0)  # made from the same array: kept
    3.0
    """

    __slots__ = ("_entries",)

    def __init__(self) -> None:
        self._entries: dict[str, tuple[tuple[np.ndarray, ...], Any]] = {}

    def get(self, key: str, inputs: tuple[np.ndarray, ...], make: Callable[[], _T]) -> _T:
        """The value under ``key`` made from ``inputs`` (see the class docstring)."""
        hit = self._entries.get(key)
        if hit is not None and len(hit[0]) == len(inputs):
            for a, b in zip(hit[0], inputs, strict=True):
                if a is not b:
                    break
            else:
                value: _T = hit[1]
                return value
        value = make()
        if not any(a.flags.writeable for a in inputs):
            if isinstance(value, np.ndarray):
                value.flags.writeable = False  # shared from now on
            self._entries[key] = (inputs, value)  # holds the arrays: identities stay unique
        return value


@dataclass(frozen=True, eq=False)
class TaskGraph:
    """Tasks, agents and facilities at one replan tick, as numpy arrays plus a networkx view.

    ``A`` agents, ``K`` tasks (fires first, then search blocks), ``F`` scored facilities. The
    arrays may be shared with other graphs (:class:`fcplan.taskgraph.TaskGraphBuilder`):
    treat every array of a graph, fields and views, as read-only.
    """

    tick: int
    time_s: float
    world_size: int
    depot_pos: np.ndarray  # (2,) float64
    agent_ids: tuple[str, ...]
    agent_role: np.ndarray  # (A,) int8 Role value
    agent_pos: np.ndarray  # (A, 2) float64
    agent_z: np.ndarray  # (A,) float64
    agent_alt_range: np.ndarray  # (A, 2) float64 (lo, hi)
    agent_speed: np.ndarray  # (A,) float64 px per second
    agent_range: np.ndarray  # (A,) float64 px it can still fly out and back home
    agent_full_range: np.ndarray  # (A,) float64 px of flight on a full battery
    agent_battery: np.ndarray  # (A,) float64 remaining battery
    agent_tank: np.ndarray  # (A,) int64 remaining dumps
    agent_tank_capacity: np.ndarray  # (A,) int64
    agent_mode: np.ndarray  # (A,) int8 fcplan.team.Mode value
    agent_home: np.ndarray  # (A, 2) float64 depot slot
    agent_can_sense: np.ndarray  # (A,) bool
    agent_can_act: np.ndarray  # (A,) bool
    task_ids: tuple[str, ...]
    task_kind: np.ndarray  # (K,) int8 TaskKind
    task_pos: np.ndarray  # (K, 2) float64 where to fly (tile centre / block centre)
    task_value: np.ndarray  # (K,) float64 fire: cells * (1 + threat); search: age-based
    task_cells: np.ndarray  # (K,) int64 known burning cells (0 for search)
    task_staleness: np.ndarray  # (K,) float64 s since last sensed / covered
    task_threat: np.ndarray  # (K,) float64 sum of PC_f * closeness to facility f
    task_cluster: np.ndarray  # (K,) int64 connected-fire id (-1 for search)
    task_block: np.ndarray  # (K,) int64 index (into tasks) of the search block holding the task
    facility_kinds: tuple[str, ...]
    facility_pos: np.ndarray  # (F, 2) float64
    facility_rect: np.ndarray  # (F, 4) float64 open footprint x0, x1, y0, y1
    facility_penalty: np.ndarray  # (F,) float64
    threat_time_s: np.ndarray  # (K, F) float64 estimated time for fire k to reach f (inf: none)
    tile_px: tuple[float, float]
    known_cells: int = 0
    comm_range: float | None = None  # px; agents farther apart cannot talk (None: unlimited)

    # ------------------------------------------------------------------ sizes
    @property
    def n_agents(self) -> int:
        """Number of agents ``A``."""
        return len(self.agent_ids)

    @property
    def n_tasks(self) -> int:
        """Number of tasks ``K`` (fires and search blocks)."""
        return len(self.task_ids)

    @property
    def fire_tasks(self) -> np.ndarray:
        """(k,) indices of the fire tasks."""
        return np.flatnonzero(self.task_kind == TaskKind.FIRE)

    @property
    def search_tasks(self) -> np.ndarray:
        """(k,) indices of the search tasks."""
        return np.flatnonzero(self.task_kind == TaskKind.SEARCH)

    @cached_view
    def task_index(self) -> dict[str, int]:
        """Task id -> row."""
        return dict(zip(self.task_ids, range(len(self.task_ids)), strict=True))

    @cached_view
    def agent_index(self) -> dict[str, int]:
        """Agent id -> row."""
        return dict(zip(self.agent_ids, range(len(self.agent_ids)), strict=True))

    @cached_view
    def shared_memo(self) -> SharedMemo | None:
        """The memo of the builder that made this graph (None: not made by a builder, or
        changed since, e.g. by :func:`dataclasses.replace`)."""
        return None

    # ------------------------------------------------------------------ distances
    @cached_view
    def agent_task_distance(self) -> np.ndarray:
        """(A, K) straight-line px from each agent to each task."""
        return self._agent_distances()[0]

    @cached_view
    def task_distance(self) -> np.ndarray:
        """(K, K) px between tasks."""
        return pairwise_distance(self.task_pos, self.task_pos)

    @cached_view
    def task_home_distance(self) -> np.ndarray:
        """(A, K) px from each task back to each agent's depot slot."""
        return self._agent_distances()[1]

    def _agent_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """Both (A, K) distance tables in one pass (their first use is usually together); each
        one already cached is kept."""
        n_a = len(self.agent_pos)
        both = pairwise_distance(np.concatenate([self.agent_pos, self.agent_home]), self.task_pos)
        d = self.__dict__
        return (
            d.setdefault("agent_task_distance", both[:n_a]),
            d.setdefault("task_home_distance", both[n_a:]),
        )

    @cached_view
    def agent_task_time(self) -> np.ndarray:
        """(A, K) seconds of flight from each agent to each task."""
        return self.agent_task_distance / self.agent_speed[:, None]

    @cached_view
    def can_do(self) -> np.ndarray:
        """(A, K) bool: the agent's role can serve the task (fires: anyone; search: sensors)."""
        return (self.task_kind == _FIRE_KIND)[None, :] | self.agent_can_sense[:, None]

    @cached_view
    def node_ids(self) -> tuple[str, ...]:
        """All node ids in the order of :attr:`positions`: agents, depot, tasks, facilities."""
        fac = tuple(f"facility:{i}:{k}" for i, k in enumerate(self.facility_kinds))
        return self.agent_ids + ("depot",) + self.task_ids + fac

    @cached_view
    def positions(self) -> np.ndarray:
        """(N, 2) positions of all nodes in :attr:`node_ids` order."""
        return np.concatenate(
            [self.agent_pos, self.depot_pos[None, :], self.task_pos, self.facility_pos]
        )

    @cached_view
    def distance(self) -> np.ndarray:
        """(N, N) straight-line travel distance between all nodes (px)."""
        return pairwise_distance(self.positions, self.positions)

    # ------------------------------------------------------------------ feasibility
    @cached_view
    def _returning(self) -> list[bool]:
        """Per agent, is it on a forced return (it recharges at its depot slot before its next
        route)? A list: a handful of agents, and Python's any/all beat numpy's."""
        return [m == _RETURNING for m in self.agent_mode.tolist()]

    @cached_view
    def agent_start_pos(self) -> np.ndarray:
        """(A, 2) where each agent's next route starts: its depot slot on a forced return,
        else where it is."""
        forced = np.array(self._returning, dtype=bool).reshape(-1)
        return np.where(forced[:, None], self.agent_home, self.agent_pos)

    @cached_view
    def agent_budget_px(self) -> np.ndarray:
        """(A,) px of flight each agent has for its next route, the way home included: a full
        battery on a forced return, else ``agent_battery / DRAIN_PER_PX``."""
        forced = np.array(self._returning, dtype=bool).reshape(-1)
        return np.where(forced, self.agent_full_range, self.agent_battery / DRAIN_PER_PX)

    @cached_view
    def start_task_distance(self) -> np.ndarray:
        """(A, K) px from each agent's :attr:`agent_start_pos` to each task."""
        forced = self._returning
        if True not in forced:
            return self.agent_task_distance
        return np.where(
            np.array(forced)[:, None], self.task_home_distance, self.agent_task_distance
        )

    @cached_view
    def in_round_trip(self) -> np.ndarray:
        """(A, K) bool: the task lies within a round trip of the agent's depot slot on a full
        battery, ``2 * task_home_distance <= agent_full_range`` (+ tolerance)."""
        dh, full = self.task_home_distance, self.agent_full_range
        return self._shared("in_round_trip", (dh, full), lambda: _round_trip(dh, full[:, None]))

    @cached_view
    def reachable(self) -> np.ndarray:
        """(A, K) bool: the agent can serve the task as its next route and fly home, exactly
        when :func:`fcplan.plan.validate_plan` accepts the one-task route ``(task,)``.

        The role fits (:attr:`can_do`), the task is :attr:`in_round_trip`, and the agent can
        fly there and home on the battery it has left,
        ``agent_task_distance + task_home_distance <= agent_battery / DRAIN_PER_PX`` (+
        tolerance), unless it is on a forced return (it recharges first).
        """
        dh, full, can = self.task_home_distance, self.agent_full_range, self.can_do
        memo = self.shared_memo
        if memo is None or dh.flags.writeable or full.flags.writeable or can.flags.writeable:
            ok = _serviceable(dh, full, can)  # (this graph's own arrays: nothing to share)
        else:
            ok = memo.get("serviceable", (dh, full, can), lambda: _serviceable(dh, full, can))
        forced = self._returning
        if all(forced):
            return ok
        # (rows of agents on a forced return are overwritten below)
        reach = _battery_ok(self.agent_task_distance, dh, self.agent_battery[:, None])
        if True in forced:
            reach |= np.array(forced)[:, None]
        reach &= ok
        return reach

    def in_round_trip_at(self, agents: np.ndarray, tasks: np.ndarray) -> np.ndarray:
        """:attr:`in_round_trip` at the pairs ``(agents[n], tasks[n])`` of agent and task rows
        (without computing the whole table)."""
        dh = self.task_home_distance[agents, tasks]
        return _round_trip(dh, self.agent_full_range[agents])

    def reachable_at(self, agents: np.ndarray, tasks: np.ndarray) -> np.ndarray:
        """:attr:`reachable` at the pairs ``(agents[n], tasks[n])`` of agent and task rows
        (without computing the whole table unless it is there already)."""
        table = self.__dict__.get("reachable")
        if table is not None:
            out: np.ndarray = table[agents, tasks]
            return out
        kind, sense = self.task_kind[tasks], self.agent_can_sense[agents]
        dh = self.task_home_distance[agents, tasks]
        battery = self.agent_battery[agents]
        ok = _battery_ok(self.agent_task_distance[agents, tasks], dh, battery)
        ok |= self.agent_mode[agents] == _RETURNING
        ok &= _round_trip(dh, self.agent_full_range[agents])
        ok &= (kind == _FIRE_KIND) | sense
        return ok

    def route_length_px(self, agent: int | str, route: Sequence[int] | Sequence[str]) -> float:
        """Px of flying ``route`` (task rows or ids) from the agent's :attr:`agent_start_pos`
        through its tasks in order and back to its depot slot."""
        i = self._agent_row(agent)
        rows = [k if isinstance(k, int | np.integer) else self.task_index[k] for k in route]
        pts = np.vstack([self.agent_start_pos[i], self.task_pos[rows], self.agent_home[i]])
        return float(np.hypot(*np.diff(pts, axis=0).T).sum())

    def route_ok(self, agent: int | str, route: Sequence[int] | Sequence[str]) -> bool:
        """The agent can fly the whole ``route`` and home on its :attr:`agent_budget_px`
        without a stop at the depot (:meth:`route_length_px`, + tolerance)."""
        need = self.route_length_px(agent, route)
        return need <= float(self.agent_budget_px[self._agent_row(agent)]) + FEASIBILITY_TOL_PX

    def clip_altitude(self, agent: int, z: float) -> float:
        """Altitude ``z`` clipped to agent row ``agent``'s bounds (m)."""
        lo, hi = self._alt_bounds[agent]
        return float(min(max(z, lo), hi))

    def dump_altitude(self, agent: int, z: float | None = None) -> float:
        """The altitude (m) from which agent row ``agent``, a camera agent with water (a hybrid),
        flies a route of fires it dumps on: ``z`` clipped to its bounds, or (None) the top of
        its bounds.

        A dump puts out the sensed burning cells in the agent's field of view, ``2 z x 1.15 z``
        px at altitude ``z`` (:mod:`fcplan.world`), so the top of the bounds is the widest dump.
        Every built-in scheduler places its hybrids' dumps by this one rule, with the same
        ``dump_altitude`` setting (None by default), so that comparisons between schedulers
        are about what they assign, not where their hybrids fly (``bench/README.md``, "One dump
        altitude for every scheduler").

        Examples
        --------
        >>> import numpy as np
        >>> from fcplan.taskgraph import synthetic_task_graph
        >>> g = synthetic_task_graph(2, 3, np.random.default_rng(0))
        >>> g.dump_altitude(0) == float(g.agent_alt_range[0][1])
        True
        >>> g.dump_altitude(0, 1e6) == g.dump_altitude(0)
        True
        """
        return self.clip_altitude(agent, self._alt_bounds[agent][1] if z is None else z)

    @cached_view
    def _alt_bounds(self) -> list[list[float]]:
        """:attr:`agent_alt_range` as Python floats."""
        alt = self.agent_alt_range
        bounds: list[list[float]] = self._shared("alt_bounds", (alt,), alt.tolist)
        return bounds

    def _agent_row(self, agent: int | str) -> int:
        return int(agent) if isinstance(agent, int | np.integer) else self.agent_index[agent]

    def _shared(self, key: str, inputs: tuple[np.ndarray, ...], make: Callable[[], _T]) -> _T:
        """``make()``, kept in :attr:`shared_memo` when the inputs are shared read-only arrays."""
        memo = self.shared_memo
        if memo is None:
            return make()
        for a in inputs:
            if a.flags.writeable:  # this graph's own array: nothing to share
                return make()
        return memo.get(key, inputs, make)

    # ------------------------------------------------------------------ networkx
    @cached_view
    def graph(self) -> Any:
        """The task graph as a :class:`networkx.DiGraph` (built on first access)."""
        import networkx as nx

        g = nx.DiGraph(tick=self.tick, time_s=self.time_s, world_size=self.world_size)
        for i, a in enumerate(self.agent_ids):
            g.add_node(
                a,
                kind="agent",
                role=Role(int(self.agent_role[i])).name.lower(),
                pos=tuple(self.agent_pos[i]),
                z=float(self.agent_z[i]),
                speed=float(self.agent_speed[i]),
                range_px=float(self.agent_range[i]),
                battery=float(self.agent_battery[i]),
                tank=int(self.agent_tank[i]),
                mode=Mode(int(self.agent_mode[i])).name.lower(),
            )
        g.add_node("depot", kind="depot", pos=tuple(self.depot_pos))
        for k, t in enumerate(self.task_ids):
            fire = self.task_kind[k] == TaskKind.FIRE
            g.add_node(
                t,
                kind="fire" if fire else "search",
                pos=tuple(self.task_pos[k]),
                value=float(self.task_value[k]),
                cells=int(self.task_cells[k]),
                staleness_s=float(self.task_staleness[k]),
                threat=float(self.task_threat[k]),
                cluster=int(self.task_cluster[k]),
            )
        fac_ids = self.node_ids[len(self.agent_ids) + 1 + len(self.task_ids) :]
        for f, fid in enumerate(fac_ids):
            g.add_node(
                fid,
                kind="facility",
                facility=self.facility_kinds[f],
                pos=tuple(self.facility_pos[f]),
                penalty=float(self.facility_penalty[f]),
            )
        for k in self.fire_tasks.tolist():
            t = self.task_ids[k]
            b = int(self.task_block[k])
            if b >= 0:
                g.add_edge(t, self.task_ids[b], kind="requires")
            for f in np.flatnonzero(np.isfinite(self.threat_time_s[k])).tolist():
                g.add_edge(t, fac_ids[f], kind="threatens", time_s=float(self.threat_time_s[k, f]))
        times = self.agent_task_time
        can = self.can_do
        for i, a in enumerate(self.agent_ids):
            for k in np.flatnonzero(can[i]).tolist():
                g.add_edge(a, self.task_ids[k], kind="can_do", time_s=float(times[i, k]))
        return g


def pairwise_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(len(a), len(b)) Euclidean distances between 2-D points: ``sqrt(dx * dx + dy * dy)``."""
    dx = a[:, 0, None] - b[:, 0]
    dy = a[:, 1, None] - b[:, 1]
    dx *= dx
    dy *= dy
    dx += dy
    return np.sqrt(dx, out=dx)


def _round_trip(dh: np.ndarray, full: np.ndarray) -> np.ndarray:
    """The round-trip rule, element-wise: ``2 * dh <= full`` (+ tolerance) for the px ``dh``
    from a task to the depot slot and the full-battery range ``full`` of the agent."""
    out: np.ndarray = 2.0 * dh <= full + FEASIBILITY_TOL_PX
    return out


def _serviceable(dh: np.ndarray, full: np.ndarray, can: np.ndarray) -> np.ndarray:
    """(A, K) bool: the role can serve the task and it lies within a round trip."""
    ok = _round_trip(dh, full[:, None])
    ok &= can
    return ok


def _battery_ok(d: np.ndarray, dh: np.ndarray, battery: np.ndarray) -> np.ndarray:
    """The battery rule, element-wise: an agent ``d`` px from a task that is ``dh`` px from its
    depot slot can fly there and home on ``battery``: ``d + dh <= battery / DRAIN_PER_PX`` (+
    tolerance)."""
    out: np.ndarray = d + dh <= battery / DRAIN_PER_PX + FEASIBILITY_TOL_PX
    return out
