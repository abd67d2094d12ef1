"""The task graph: what there is to do, built from the team's belief at a replan tick.

Node kinds:

* ``agent``: every UAV, with its role, position, altitude, speed, remaining range and tank;
* ``depot``: where agents recharge and refill;
* ``fire``: a *dump-sized* cluster of known burning cells. Known cells are binned into tiles no
  larger than an action agent's field of view, so one dump at the task's position can reach every
  cell of the task. Attributes: centroid position, cell count, staleness (seconds since any of its
  cells was last sensed), threat (penalty-weighted closeness to facilities), the connected fire
  (``cluster``) it belongs to;
* ``search``: a grid block (100 px by default) to (re)explore, valued by how long ago the team's
  cameras last covered it, more when known fire is near;
* ``facility``: houses, hospitals, power stations and the depot footprint, with their penalties.

Edges: ``requires`` (fire -> the search block containing it: putting a fire out needs it sensed,
so that block must be kept fresh), ``threatens`` (fire -> facility within ``threat_radius_px``,
with an estimated time to reach it from the fastest spread rate of the scenario's fuel), and
``can_do`` (agent -> task its role can serve, with travel time).

Solvers should use the numpy views (``agent_*``, ``task_*``, :attr:`TaskGraph.agent_task_distance`,
:attr:`TaskGraph.task_distance`); the networkx view (:attr:`TaskGraph.graph`) is built on first
use, for inspection, drawing and teaching. Graphs from :func:`build_task_graph` share the arrays
that do not change between replans (the agents' roles, speeds, capacities and depot slots, the
facilities, and without known fire the search blocks' kinds, positions and depot distances):
those are read-only, so treat every graph array as read-only.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.belief import Belief
>>> from fcplan.taskgraph import build_task_graph
>>> world = World().reset(load_scenario(1), seed=0)
>>> belief = Belief(world.scenario)
>>> for _ in range(10):
...     belief.update(world.step())
>>> g = build_task_graph(world.scenario, world.team, belief)
>>> g.n_agents, g.n_tasks > 0
(4, True)
>>> sorted({d["kind"] for _, d in g.graph.nodes(data=True)})
['agent', 'depot', 'facility', 'search']
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from functools import cached_property, lru_cache

import numpy as np

from fcplan.team import DRAIN_PER_PX, Mode, fov_half_extent

__all__ = [
    "TaskKind",
    "TaskGraph",
    "TaskGraphParams",
    "build_task_graph",
    "grid_block_name",
    "synthetic_task_graph",
]


class TaskKind(IntEnum):
    """Kinds of task nodes."""

    FIRE = 0
    SEARCH = 1


_FIRE_KIND = int(TaskKind.FIRE)  # a plain int compares with arrays faster than the enum member


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


@dataclass(frozen=True, eq=False)
class TaskGraph:
    """Tasks, agents and facilities at one replan tick, as numpy arrays plus a networkx view.

    ``A`` agents, ``K`` tasks (fires first, then search blocks), ``F`` scored facilities.
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

    @cached_property
    def task_index(self) -> dict[str, int]:
        """Task id -> row."""
        return dict(zip(self.task_ids, range(len(self.task_ids)), strict=True))

    @cached_property
    def agent_index(self) -> dict[str, int]:
        """Agent id -> row."""
        return dict(zip(self.agent_ids, range(len(self.agent_ids)), strict=True))

    # ------------------------------------------------------------------ distances
    @cached_property
    def agent_task_distance(self) -> np.ndarray:
        """(A, K) straight-line px from each agent to each task."""
        return self._agent_distances()[0]

    @cached_property
    def task_distance(self) -> np.ndarray:
        """(K, K) px between tasks."""
        return _pairwise(self.task_pos, self.task_pos)

    @cached_property
    def task_home_distance(self) -> np.ndarray:
        """(A, K) px from each task back to each agent's depot slot."""
        return self._agent_distances()[1]

    def _agent_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """Both (A, K) distance tables in one pass (their first use is usually together); each
        one already cached is kept."""
        n_a = len(self.agent_pos)
        both = _pairwise(np.concatenate([self.agent_pos, self.agent_home]), self.task_pos)
        d = self.__dict__
        return (
            d.setdefault("agent_task_distance", both[:n_a]),
            d.setdefault("task_home_distance", both[n_a:]),
        )

    @cached_property
    def agent_task_time(self) -> np.ndarray:
        """(A, K) seconds of flight from each agent to each task."""
        return self.agent_task_distance / self.agent_speed[:, None]

    @cached_property
    def can_do(self) -> np.ndarray:
        """(A, K) bool: the agent's role can serve the task (fires: anyone; search: sensors)."""
        return (self.task_kind == _FIRE_KIND)[None, :] | self.agent_can_sense[:, None]

    @cached_property
    def node_ids(self) -> tuple[str, ...]:
        """All node ids in the order of :attr:`positions`: agents, depot, tasks, facilities."""
        fac = tuple(f"facility:{i}:{k}" for i, k in enumerate(self.facility_kinds))
        return self.agent_ids + ("depot",) + self.task_ids + fac

    @cached_property
    def positions(self) -> np.ndarray:
        """(N, 2) positions of all nodes in :attr:`node_ids` order."""
        return np.concatenate(
            [self.agent_pos, self.depot_pos[None, :], self.task_pos, self.facility_pos]
        )

    @cached_property
    def distance(self) -> np.ndarray:
        """(N, N) straight-line travel distance between all nodes (px)."""
        return _pairwise(self.positions, self.positions)

    # ------------------------------------------------------------------ networkx
    @cached_property
    def graph(self):
        """The task graph as a :class:`networkx.DiGraph` (built on first access)."""
        import networkx as nx

        g = nx.DiGraph(tick=self.tick, time_s=self.time_s, world_size=self.world_size)
        from fcplan.scenario import Role

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
        for k in self.fire_tasks:
            t = self.task_ids[k]
            b = int(self.task_block[k])
            if b >= 0:
                g.add_edge(t, self.task_ids[b], kind="requires")
            for f in np.flatnonzero(np.isfinite(self.threat_time_s[k])):
                g.add_edge(t, fac_ids[f], kind="threatens", time_s=float(self.threat_time_s[k, f]))
        times = self.agent_task_time
        can = self.can_do
        for i, a in enumerate(self.agent_ids):
            for k in np.flatnonzero(can[i]):
                g.add_edge(a, self.task_ids[k], kind="can_do", time_s=float(times[i, k]))
        return g


def _pairwise(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(len(a), len(b)) Euclidean distances between 2-D points: ``sqrt(dx * dx + dy * dy)``."""
    dx = a[:, 0, None] - b[:, 0]
    dy = a[:, 1, None] - b[:, 1]
    dx *= dx
    dy *= dy
    dx += dy
    return np.sqrt(dx, out=dx)


def _rect_distance(points: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(P, F) distance from points to axis-aligned rectangles (0 inside)."""
    x, y = points[:, 0, None], points[:, 1, None]
    # per axis max(lo - p, p - hi, 0): the gap to the rectangle's span (0 inside it)
    dx = np.maximum(rects[:, 0] - x, x - rects[:, 1])
    np.maximum(dx, 0.0, out=dx)
    dy = np.maximum(rects[:, 2] - y, y - rects[:, 3])
    np.maximum(dy, 0.0, out=dy)
    return np.hypot(dx, dy, out=dx)


def default_tile(team) -> tuple[float, float]:
    """90 % of the smallest dump field of view among action/hybrid agents."""
    return _default_tile(team.can_act.tobytes(), team.role.tobytes(), team.alt_lo.tobytes())


@lru_cache(maxsize=64)
def _default_tile(can_act: bytes, role: bytes, alt_lo: bytes) -> tuple[float, float]:
    from fcplan.team import ACTION_ALTITUDE

    acting = np.flatnonzero(np.frombuffer(can_act, dtype=bool))
    if acting.size == 0:
        return (54.0, 31.0)
    role_a = np.frombuffer(role, dtype=np.int8)[acting]
    z = np.where(role_a == 1, ACTION_ALTITUDE, np.frombuffer(alt_lo, dtype=np.float64)[acting])
    hx, hy = fov_half_extent(z.min())
    return (float(np.floor(1.8 * hx)), float(np.floor(1.8 * hy)))


@dataclass(frozen=True, eq=False)
class _ScenarioConsts:
    """What a task graph needs from a scenario that never changes during an episode (read-only
    arrays, shared by the graphs)."""

    fac_pos: np.ndarray
    fac_rect: np.ndarray
    fac_pen: np.ndarray
    fac_kinds: tuple[str, ...]
    depot_pos: np.ndarray
    max_fuel: float


_CONSTS: dict[int, tuple[object, _ScenarioConsts]] = {}


def _scenario_consts(scenario) -> _ScenarioConsts:
    """Per-scenario constants, cached by identity (scenarios are immutable)."""
    hit = _CONSTS.get(id(scenario))
    if hit is not None and hit[0] is scenario:
        return hit[1]
    facilities = scenario.scored_facilities
    consts = _ScenarioConsts(
        fac_pos=_frozen(np.array([f.center for f in facilities], dtype=np.float64).reshape(-1, 2)),
        fac_rect=_frozen(
            np.array([f.footprint for f in facilities], dtype=np.float64).reshape(-1, 4)
        ),
        fac_pen=_frozen(np.array([f.penalty for f in facilities], dtype=np.float64)),
        fac_kinds=tuple(f.kind for f in facilities),
        depot_pos=_frozen(np.array(scenario.depot.center, dtype=np.float64)),
        max_fuel=max((r.fuel for r in scenario.regions), default=1.0),
    )
    if len(_CONSTS) >= 32:
        _CONSTS.pop(next(iter(_CONSTS)))
    _CONSTS[id(scenario)] = (scenario, consts)
    return consts


def _frozen(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only (shared between graphs: a consumer writing to it gets an error)."""
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class _TeamConsts:
    """The agent fields of a task graph that never change during a team's life (a team's role,
    altitude bounds, speed, battery and tank capacities and depot slots are set when it is
    built and never written), as read-only arrays shared by every graph of the team, and per
    (map side, block side) the px from each depot slot to each search block and who can serve
    them."""

    tps: int
    role: np.ndarray
    alt_range: np.ndarray
    speed: np.ndarray
    full_range: np.ndarray
    tank_capacity: np.ndarray
    home: np.ndarray
    can_sense: np.ndarray
    can_act: np.ndarray
    search_home: dict


_TEAMS: dict[int, tuple[object, _TeamConsts]] = {}


def _team_consts(team, tps: int) -> _TeamConsts:
    """Per-team constants, cached by identity (the cache holds the team, so its id is not
    reused while cached)."""
    hit = _TEAMS.get(id(team))
    if hit is not None and hit[0] is team and hit[1].tps == tps:
        return hit[1]
    consts = _TeamConsts(
        tps=tps,
        role=_frozen(team.role.copy()),
        alt_range=_frozen(_columns(team.alt_lo, team.alt_hi)),
        speed=_frozen(team.speed * tps),
        full_range=_frozen(team.battery_capacity / DRAIN_PER_PX),
        tank_capacity=_frozen(team.tank_capacity.copy()),
        home=_frozen(team.home.copy()),
        can_sense=_frozen(team.can_sense.copy()),
        can_act=_frozen(team.can_act.copy()),
        search_home={},
    )
    if len(_TEAMS) >= 16:
        _TEAMS.pop(next(iter(_TEAMS)))
    _TEAMS[id(team)] = (team, consts)
    return consts


def _search_home(tc: _TeamConsts, w: int, blk: int) -> tuple[np.ndarray, np.ndarray]:
    """(A, nb * nb) px from each depot slot to each search block, and the (A, nb * nb)
    :attr:`TaskGraph.can_do` of a graph of search blocks only (read-only, cached)."""
    hit = tc.search_home.get((w, blk))
    if hit is None:
        d = _frozen(_pairwise(tc.home, _search_grid(w, blk)))
        can = _frozen(np.repeat(tc.can_sense[:, None], d.shape[1], axis=1))
        hit = tc.search_home[(w, blk)] = (d, can)
    return hit


@lru_cache(maxsize=16)
def _search_only(n_search: int, n_fac: int) -> dict[str, np.ndarray]:
    """The task fields of a graph without fire tasks that do not depend on the belief
    (read-only)."""
    minus = np.full(n_search, -1, dtype=np.int64)
    return {
        "task_kind": _frozen(np.full(n_search, int(TaskKind.SEARCH), dtype=np.int8)),
        "task_cells": _frozen(np.zeros(n_search, dtype=np.int64)),
        "task_threat": _frozen(np.zeros(n_search)),
        "task_cluster": _frozen(minus),
        "task_block": minus,
        "threat_time_s": _frozen(np.full((0, n_fac), np.inf)),
    }


@lru_cache(maxsize=16)
def _search_grid(w: int, blk: int) -> np.ndarray:
    """(nb * nb, 2) centres of the search blocks (x-major), clipped to the map (read-only)."""
    nb = -(-w // blk)
    bx, by = np.meshgrid(np.arange(nb), np.arange(nb), indexing="ij")
    bx, by = bx.ravel(), by.ravel()
    pos = np.stack(
        [np.minimum((bx + 0.5) * blk, w - 1.0), np.minimum((by + 0.5) * blk, w - 1.0)], axis=1
    )
    pos.flags.writeable = False
    return pos


def build_task_graph(scenario, team, belief, params: TaskGraphParams | None = None) -> TaskGraph:
    """Build the task graph from the scenario, the team's own state and the belief.

    The per-agent constants (role, speed, depot slots ...) and, without known fire, the
    belief-independent task fields are read-only arrays shared by the graphs of a team; the
    agent-task distance tables (:attr:`TaskGraph.agent_task_distance`,
    :attr:`TaskGraph.task_home_distance`) are filled in at once (every consumer reads them),
    and without known fire :attr:`TaskGraph.can_do` too.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    team : fcplan.team.Team
        The agents' own states (the team always knows where it is and what it has left).
    belief : fcplan.belief.Belief
        What the team knows about the fire and what it has covered.
    params : TaskGraphParams, optional
    """
    p = params or _DEFAULT_PARAMS
    w = scenario.world_size
    tps = scenario.ticks_per_second
    tick = belief.tick
    consts = _scenario_consts(scenario)
    tc = _team_consts(team, tps)

    # ---- search blocks
    blk = int(p.search_block_px)
    nb = -(-w // blk)
    search_age = belief.coverage_age_s(blk).ravel()  # (nb, nb) indexed [bx, by], raveled
    search_pos = _search_grid(w, blk)
    search_ids = _search_ids(nb, blk)
    agent_pos = team.pos.copy()

    if belief.known.size == 0:  # no known fire: search blocks only
        tile = p.tile_px or default_tile(team)
        fields = dict(_search_only(len(search_pos), len(consts.fac_pos)))
        # min(age, cap) * (1 + min(0, 50) / 10) == min(age, cap): the factor is exactly 1
        fields.update(
            task_ids=search_ids,
            task_pos=search_pos,
            task_value=np.minimum(search_age, p.search_value_cap_s),
            task_staleness=search_age,
            known_cells=0,
            agent_task_distance=_pairwise(agent_pos, search_pos),
        )
        fields["task_home_distance"], fields["can_do"] = _search_home(tc, w, blk)
        return _finish(scenario, team, consts, tc, tick, agent_pos, (tile[0], tile[1]), fields)

    tile = p.tile_px or default_tile(team)
    tw, th = float(tile[0]), float(tile[1])
    fac_pos = consts.fac_pos

    # ---- fire tiles from known cells
    ntx = int(np.ceil(w / tw))
    nty = int(np.ceil(w / th)) + 1
    known = belief.known
    kx, ky = np.divmod(known, w)  # known = flat x * W + y
    if tw.is_integer() and th.is_integer() and tw >= 1.0 and th >= 1.0:
        # whole-px tiles (the default): integer floor division, the same as the float one
        key = kx // int(tw)
        key *= nty
        key += ky // int(th)  # tile row-major (ty < nty)
    else:
        key = (kx // tw).astype(np.int64) * nty + (ky // th).astype(np.int64)
    order = np.argsort(key, kind="stable")
    ks = key[order]
    first = np.empty(len(ks), dtype=bool)
    first[:1] = True
    np.not_equal(ks[1:], ks[:-1], out=first[1:])
    starts = first.nonzero()[0]
    xs, ys = kx[order], ky[order]
    seen = belief.last_seen.ravel()[known[order]]
    last = np.maximum.reduceat(seen, starts)
    # tile centre: the middle of the cells' bounding box ((lo + hi) / 2 of whole px: exact)
    fire_pos = np.empty((len(starts), 2))
    np.add(np.minimum.reduceat(xs, starts), np.maximum.reduceat(xs, starts), out=fire_pos[:, 0])
    np.add(np.minimum.reduceat(ys, starts), np.maximum.reduceat(ys, starts), out=fire_pos[:, 1])
    fire_pos /= 2.0
    counts = np.empty_like(starts)  # tile sizes: gaps between starts
    np.subtract(starts[1:], starts[:-1], out=counts[:-1])
    counts[-1] = len(ks) - starts[-1]
    fire_stale = (tick - last) / tps
    tile_x, tile_y = np.divmod(ks[starts], nty)
    cluster = _clusters(tile_x, tile_y, ntx, nty)

    n_fire = len(fire_pos)
    # threat: penalty-weighted closeness of each fire tile to each facility footprint
    if len(fac_pos):
        d_fac = _rect_distance(fire_pos, consts.fac_rect)
        close = np.minimum(np.maximum(1.0 - d_fac / p.threat_radius_px, 0.0), 1.0)
        threat = close @ consts.fac_pen
        fuel = consts.max_fuel
        speed = max(0.24 * fuel * 10.0, 1e-9)  # px/s, first-tick spread at wind 5 (fastest)
        threat_time = np.where(d_fac < p.threat_radius_px, d_fac / speed, np.inf)
    else:
        threat = np.zeros(n_fire)
        threat_time = np.full((n_fire, 0), np.inf)

    # search value: age (capped) times (1 + nearby known fire)
    fbxy = fire_pos // blk
    np.minimum(fbxy, nb - 1, out=fbxy)
    fb = (fbxy @ (nb, 1.0)).astype(np.int64)  # block index bx * nb + by (small whole numbers)
    # the known cells of the blocks around each block, itself included (fire grows across block
    # borders): every tile's cells counted in the 3 x 3 blocks around its own (sums of whole
    # cell counts: exact in any order)
    near_fire = np.bincount(
        _neighbours(nb)[fb].ravel(), weights=np.repeat(counts, 9), minlength=nb * nb + 1
    )[: nb * nb]
    fire_block = n_fire + fb
    search_value = np.minimum(search_age, p.search_value_cap_s) * (
        1.0 + np.minimum(near_fire, 50) / 10.0
    )

    # ids from the truncated position (astype truncates toward zero, as int() does)
    fire_ids = tuple([f"fire:{x}:{y}" for x, y in fire_pos.astype(np.int64).tolist()])
    # keep ids unique when two tiles round to the same point
    if len(set(fire_ids)) != len(fire_ids):
        fire_ids = tuple(f"{fid}#{k}" for k, fid in enumerate(fire_ids))

    n_search = len(search_pos)
    k_total = n_fire + n_search
    task_kind = np.full(k_total, int(TaskKind.SEARCH), dtype=np.int8)
    task_kind[:n_fire] = int(TaskKind.FIRE)
    minus_s = _search_only(n_search, len(fac_pos))["task_cluster"]
    task_pos = np.concatenate([fire_pos, search_pos])
    # both (A, K) distance tables in one pass, as TaskGraph._agent_distances computes them
    both = _pairwise(np.concatenate([agent_pos, tc.home]), task_pos)
    n_a = len(agent_pos)
    fields = dict(
        task_ids=fire_ids + search_ids,
        task_kind=task_kind,
        task_pos=task_pos,
        task_value=np.concatenate([counts * (1.0 + threat), search_value]),
        task_cells=_cat_int(counts, _search_only(n_search, len(fac_pos))["task_cells"]),
        task_staleness=np.concatenate([fire_stale, search_age]),
        task_threat=np.concatenate([threat, np.zeros(n_search)]),
        task_cluster=_cat_int(cluster, minus_s),
        task_block=_cat_int(fire_block, minus_s),
        threat_time_s=threat_time,
        known_cells=int(counts.sum()),
        agent_task_distance=both[:n_a],
        task_home_distance=both[n_a:],
    )
    return _finish(scenario, team, consts, tc, tick, agent_pos, (tw, th), fields)


_DEFAULT_PARAMS = TaskGraphParams()


def _finish(scenario, team, consts, tc, tick, agent_pos, tile, fields) -> TaskGraph:
    """The graph from its task fields: the agent and facility fields added."""
    tps = tc.tps
    fields.update(
        tick=tick,
        time_s=tick / tps,
        world_size=scenario.world_size,
        depot_pos=consts.depot_pos,
        agent_ids=team.ids,
        agent_role=tc.role,
        agent_pos=agent_pos,
        agent_z=team.z.copy(),
        agent_alt_range=tc.alt_range,
        agent_speed=tc.speed,
        agent_range=team.range_px(),
        agent_full_range=tc.full_range,
        agent_battery=team.battery.copy(),
        agent_tank=team.tank.copy(),
        agent_tank_capacity=tc.tank_capacity,
        agent_mode=team.mode.copy(),
        agent_home=tc.home,
        agent_can_sense=tc.can_sense,
        agent_can_act=tc.can_act,
        facility_kinds=consts.fac_kinds,
        facility_pos=consts.fac_pos,
        facility_rect=consts.fac_rect,
        facility_penalty=consts.fac_pen,
        tile_px=(float(tile[0]), float(tile[1])),
        comm_range=scenario.comm_range,
    )
    return _task_graph(**fields)


def _columns(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.stack([a, b], axis=1)`` for two 1-D arrays of the same dtype, cheaper."""
    out = np.empty((len(a), 2), dtype=a.dtype)
    out[:, 0] = a
    out[:, 1] = b
    return out


def _task_graph(**fields) -> TaskGraph:
    """``TaskGraph(**fields)`` given every field, without the frozen dataclass's per-field
    ``object.__setattr__`` calls (a graph is built every replan)."""
    graph = object.__new__(TaskGraph)
    graph.__dict__.update(fields)
    return graph


def _cat_int(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Concatenation as int64 (as ``np.r_[a, b].astype(np.int64)``)."""
    return np.concatenate([a, b]).astype(np.int64, copy=False)


@lru_cache(maxsize=16)
def _neighbours(nb: int) -> np.ndarray:
    """(nb * nb, 9) the blocks of the 3 x 3 neighbourhood of each block of an ``nb x nb`` grid
    (flat ``bx * nb + by``); neighbours off the grid are ``nb * nb`` (read-only)."""
    b = np.arange(nb)
    bx, by = np.meshgrid(b, b, indexing="ij")
    d = np.array([-1, 0, 1])
    nx_ = bx.ravel()[:, None, None] + d[None, :, None]
    ny_ = by.ravel()[:, None, None] + d[None, None, :]
    inside = (nx_ >= 0) & (nx_ < nb) & (ny_ >= 0) & (ny_ < nb)
    out = np.where(inside, nx_ * nb + ny_, nb * nb).reshape(nb * nb, 9)
    out.flags.writeable = False
    return out


@lru_cache(maxsize=16)
def _search_ids(nb: int, blk: int) -> tuple[str, ...]:
    """Ids of the ``nb x nb`` search blocks in task order (x-major): the chess name of the grid
    cell for 100-px blocks (``search:D-05``), else the block's indices (``search:3:4``)."""
    if blk == 100:
        return tuple(f"search:{grid_block_name(a, b)}" for a in range(nb) for b in range(nb))
    return tuple(f"search:{a}:{b}" for a in range(nb) for b in range(nb))


_EIGHT = np.ones((3, 3), dtype=bool)  # 8-connectivity
_SMALL_CLUSTER = 256  # up to this many tiles, label by pairwise adjacency (no scipy call)


def _clusters(tx: np.ndarray, ty: np.ndarray, nx_: int, ny_: int) -> np.ndarray:
    """Connected-fire labels of occupied tiles (8-connectivity), numbered like
    ``scipy.ndimage.label`` (by first tile in raster order; the tiles come sorted that way).

    Labels depend on the tiles only: the last few answers are kept (read-only) for tiles that
    did not change since (the fire often keeps its tiles for several replans).
    """
    n = len(tx)
    if n == 1:
        return np.zeros(1, dtype=np.int64)
    key = (tx.dtype.str, ty.dtype.str, tx.tobytes() + ty.tobytes())
    hit = _CLUSTER_MEMO.get(key)
    if hit is not None:
        return hit
    if n <= _SMALL_CLUSTER:
        adj = np.abs(tx[:, None] - tx) <= 1
        adj &= np.abs(ty[:, None] - ty) <= 1
        idx = np.arange(n)
        if n <= _CLOSURE_CLUSTER:
            # transitive closure by boolean matrix squaring (reflexive: it only grows); the
            # first tile reached from a tile is the first tile of its component
            m, count = adj, np.count_nonzero(adj)
            while True:
                m = m @ m
                c = np.count_nonzero(m)
                if c == count:
                    break
                count = c
            lab = m.argmax(axis=1)
        else:
            # min-label propagation with pointer jumping: each tile ends up pointing at the
            # first (lowest-index) tile of its component
            lab = np.where(adj, idx, n).min(axis=1)
            while True:
                nxt = np.where(adj, lab, n).min(axis=1)
                nxt = nxt[nxt]
                if np.array_equal(nxt, lab):
                    break
                lab = nxt
        # components are numbered in the order of their first tiles
        out = (np.cumsum(lab == idx) - 1)[lab]
    else:
        from scipy.ndimage import label

        grid = np.zeros((nx_ + 1, ny_ + 1), dtype=bool)
        grid[tx, ty] = True
        labels, _ = label(grid, structure=_EIGHT)
        out = labels[tx, ty].astype(np.int64) - 1
    if len(_CLUSTER_MEMO) >= 8:
        _CLUSTER_MEMO.pop(next(iter(_CLUSTER_MEMO)))
    _CLUSTER_MEMO[key] = _frozen(out)
    return out


_CLOSURE_CLUSTER = 24  # up to this many tiles, label by closure (few, cheap matrix products)
#: tiles (dtypes, then x and y coordinates as bytes; equal lengths) -> labels (read-only)
_CLUSTER_MEMO: dict[tuple[str, str, bytes], np.ndarray] = {}


def synthetic_task_graph(
    n_agents: int,
    n_tasks: int,
    rng: np.random.Generator,
    *,
    world_size: int = 1200,
    perception_share: float = 0.5,
    fire_share: float = 0.5,
    tank: int = 10,
    battery: float = 500.0,
    speed_px_s: float = 200.0,
    comm_range: float | None = None,
) -> TaskGraph:
    """A random task graph for solver tests and scaling studies (no simulation behind it).

    Agents are split into perception (the first ``round(perception_share * n_agents)``, at least
    one) and action agents (at least one), spread over the map with their depot slots on the
    left edge. Tasks are fire tiles (``fire_share``) and search blocks at uniform random positions;
    fire values are 1..60 known cells weighted by a random facility threat, search values are
    ages of 0..60 s; fires belong to random clusters.

    Examples
    --------
    >>> import numpy as np
    >>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
    >>> g.n_agents, g.n_tasks, int(g.agent_can_act.sum()) >= 1
    (3, 6, True)
    """
    if n_agents < 2:
        raise ValueError("a synthetic team needs at least 2 agents (one to sense, one to act)")
    w = float(world_size)
    n_p = min(max(int(round(perception_share * n_agents)), 1), n_agents - 1)
    role = np.r_[np.zeros(n_p), np.ones(n_agents - n_p)].astype(np.int8)
    n_fire = int(round(fire_share * n_tasks))
    kind = np.r_[np.full(n_fire, TaskKind.FIRE), np.full(n_tasks - n_fire, TaskKind.SEARCH)]
    home = np.stack([np.full(n_agents, 60.0), np.linspace(0.1 * w, 0.9 * w, n_agents)], axis=1)
    pos = rng.uniform(0.05 * w, 0.95 * w, size=(n_agents, 2))
    full = battery / DRAIN_PER_PX
    used = rng.uniform(0.0, 0.5, n_agents) * full
    task_pos = rng.uniform(0.0, w, size=(n_tasks, 2))
    cells = np.where(kind == TaskKind.FIRE, rng.integers(1, 61, n_tasks), 0)
    threat = np.where(kind == TaskKind.FIRE, rng.choice([0.0, 0.0, 1.0, 2.0, 5.0], n_tasks), 0.0)
    age = rng.uniform(0.0, 60.0, n_tasks)
    value = np.where(kind == TaskKind.FIRE, cells * (1.0 + threat), age)
    stale = np.where(kind == TaskKind.FIRE, rng.uniform(0.0, 10.0, n_tasks), age)
    n_clusters = max(n_fire // 4, 1)
    cluster = np.where(kind == TaskKind.FIRE, rng.integers(0, n_clusters, n_tasks), -1)
    battery_left = battery - used * DRAIN_PER_PX
    way_home = np.hypot(*(home - pos).T)
    fac_pos = np.array([[0.5 * w, 0.5 * w]])
    return TaskGraph(
        tick=0,
        time_s=0.0,
        world_size=int(world_size),
        depot_pos=np.array([60.0, 0.5 * w]),
        agent_ids=tuple(f"{'P' if r == 0 else 'A'}{i + 1}" for i, r in enumerate(role)),
        agent_role=role,
        agent_pos=pos,
        agent_z=np.where(role == 0, 50.0, 30.0),
        agent_alt_range=np.where(role[:, None] == 0, [[10.0, 100.0]], [[30.0, 30.0]]),
        agent_speed=np.full(n_agents, float(speed_px_s)),
        agent_range=np.maximum(battery_left / DRAIN_PER_PX - way_home, 0.0),
        agent_full_range=np.full(n_agents, full),
        agent_battery=battery_left,
        agent_tank=np.where(role == 1, tank, 0).astype(np.int64),
        agent_tank_capacity=np.where(role == 1, tank, 0).astype(np.int64),
        agent_mode=np.full(n_agents, int(Mode.ACTIVE), dtype=np.int8),
        agent_home=home,
        agent_can_sense=role == 0,
        agent_can_act=role == 1,
        task_ids=tuple(
            f"{'fire' if k == TaskKind.FIRE else 'search'}:{i}" for i, k in enumerate(kind)
        ),
        task_kind=kind.astype(np.int8),
        task_pos=task_pos,
        task_value=value.astype(np.float64),
        task_cells=cells.astype(np.int64),
        task_staleness=stale,
        task_threat=threat,
        task_cluster=cluster.astype(np.int64),
        task_block=np.full(n_tasks, -1, dtype=np.int64),
        facility_kinds=("house",),
        facility_pos=fac_pos,
        facility_rect=np.array([[0.5 * w - 60, 0.5 * w + 60, 0.5 * w - 75, 0.5 * w + 75]]),
        facility_penalty=np.array([1.0]),
        threat_time_s=np.full((n_tasks, 1), np.inf),
        tile_px=(54.0, 31.0),
        known_cells=int(cells.sum()),
        comm_range=comm_range,
    )
