"""The route model's settings (:class:`MilpParams`), variable kinds and arrays (:class:`MilpModel`)."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
import scipy.sparse as sp

from fcplan.scheduling import float_setting, int_setting
from fcplan.settings import altitude_setting

__all__ = [
    "COVER",
    "FREEZE",
    "IncompletePlanError",
    "KIND_NAMES",
    "OBJECTIVE_SCALE",
    "ROUTE",
    "DUMP",
    "SEARCH",
    "WATCH",
    "MilpModel",
    "MilpParams",
]

#: Variable kinds (:attr:`MilpModel.var_kind`): one route of one agent, a search block's detected
#: share (integer percent), a connected fire both watched and dumped on.
ROUTE, COVER, FREEZE = 0, 1, 2
KIND_NAMES = ("route", "cover", "freeze")
#: Route kinds (:attr:`MilpModel.route_kind`): fire dumps, a watch (hover over a fire), search.
DUMP, WATCH, SEARCH = 0, 1, 2
#: Objective coefficients are whole multiples of ``1 / OBJECTIVE_SCALE`` penalty units, so every
#: backend (and the brute force) optimises the very same integral objective, exactly.
OBJECTIVE_SCALE = 1e4


class IncompletePlanError(RuntimeError):
    """A limit stopped the solver before it had a plan for every agent that has work."""


@dataclass(frozen=True, slots=True)
class MilpParams:
    """Settings of the route model (shared by both MILP schedulers; see :mod:`solvers.milp_model`).

    Parameters
    ----------
    slots : int
        Most fire tasks per dump route (1..4; also capped by the tank).
    search_slots : int
        Most search blocks per search route (1..4).
    horizon_s : float
        Planning horizon ``H`` (s): a cell put out (or found) at ``t`` stops costing for
        ``H - t`` seconds of it.
    search_horizon_s : float
        Look-ahead ``H_s`` (s) of a sweep: a block passed ``t`` seconds from now counts with
        weight ``(H_s - t)+ / H_s`` (the agent replans long before a far sweep happens).
    search_reach_s : float
        A search route starts at a block the agent reaches within this many seconds (>= 0):
        the first leg is the step taken before the next replan, the later legs the look-ahead
        (any of the best ``search_candidates`` blocks).
    fire_candidates, search_candidates, watch_candidates : int
        Per agent, the fire tasks it may dump on, the search blocks and the fire tasks it may
        watch, best single-task value first (1..64 each).
    prune_confidence : float
        Share of the sensed cells in view a dump puts out (0..1; 0.9 for the manual's action
        agents).
    threat_weight : float
        Weight of the facility penalties a fire threatens (>= 0).
    growth_cells_s : float
        Cells per second a connected fire adds while fronts run on (>= 0): what a watched dump
        stops.
    search_weight : float
        Undiscovered burning cells ``kappa`` expected in a search block per second of coverage
        age at 60 s (>= 0; :func:`solvers.milp_model.objective.hidden_cells`).
    search_age_exponent : float
        How the undiscovered cells grow with the coverage age ``A``: ``(A / 60) ** alpha``
        (0..4; 1: as the age, 2: fires both start and grow while nobody looks).
    search_age_cap_s : float
        Coverage ages beyond this count as this (s, > 0).
    recent_fire_s : float
        The schedulers remember the fire tasks of the graphs of the last this many seconds:
        blocks near fire known then count as near fire (s, >= 0; 0: only the current graph).
    search_block_px : float
        Side of the square search blocks (px, > 0; the task graph's ``search_block_px``).
    cover_levels : int
        Steps of a block's detected share in the cover variables (1..1000; 100: percent).
    watch_altitude : float
        Altitude (m) of an agent watching a fire (clipped to its bounds).
    dump_altitude : float or None
        Altitude (m) of a camera agent with water (a hybrid) on a dump route, clipped to its
        bounds. A dump puts out the sensed burning cells in the agent's field of view, which is
        ``2 z x 1.15 z`` px at altitude ``z``; None (default): the top of the agent's bounds, the
        widest dump.
    search_altitude : float or None
        Altitude (m) of a searching agent; None: the altitude of its best detection rate
        (:func:`solvers.milp_model.sensing.best_search_altitude`).
    max_routes : int
        Most routes in one model (>= 1): a graph that would need more raises ``ValueError``.
    max_scored_ends : int
        Search blocks scored per searcher as the end of a straight flight, to rank its search
        candidates (2..4096): every block in twice its reach up to this many, else half of this
        the nearest and half those of most value per second of flight.
    """

    slots: int = 3
    search_slots: int = 2
    horizon_s: float = 30.0
    search_horizon_s: float = 5.0
    search_reach_s: float = 0.75
    fire_candidates: int = 6
    search_candidates: int = 10
    watch_candidates: int = 3
    prune_confidence: float = 0.9
    threat_weight: float = 1.0
    growth_cells_s: float = 2.0
    search_weight: float = 0.05
    search_age_exponent: float = 2.0
    search_age_cap_s: float = 300.0
    recent_fire_s: float = 30.0
    search_block_px: float = 100.0
    cover_levels: int = 10
    watch_altitude: float = 35.0
    dump_altitude: float | None = None
    search_altitude: float | None = None
    max_routes: int = 20_000
    max_scored_ends: int = 256

    def __post_init__(self) -> None:
        int_setting("slots", self.slots, 1, 4)
        int_setting("search_slots", self.search_slots, 1, 4)
        float_setting("horizon_s", self.horizon_s, 0.0, lo_open=True, unit=" s")
        float_setting("search_horizon_s", self.search_horizon_s, 0.0, lo_open=True, unit=" s")
        float_setting("search_reach_s", self.search_reach_s, 0.0, unit=" s")
        for name in ("fire_candidates", "search_candidates", "watch_candidates"):
            int_setting(name, getattr(self, name), 1, 64)
        float_setting("prune_confidence", self.prune_confidence, 0.0, 1.0)
        float_setting("threat_weight", self.threat_weight, 0.0)
        float_setting("growth_cells_s", self.growth_cells_s, 0.0)
        float_setting("search_weight", self.search_weight, 0.0)
        float_setting("search_age_exponent", self.search_age_exponent, 0.0, 4.0)
        float_setting("search_age_cap_s", self.search_age_cap_s, 0.0, lo_open=True, unit=" s")
        float_setting("recent_fire_s", self.recent_fire_s, 0.0, unit=" s")
        float_setting("search_block_px", self.search_block_px, 0.0, lo_open=True, unit=" px")
        int_setting("cover_levels", self.cover_levels, 1, 1000)
        altitude_setting("watch_altitude", self.watch_altitude)
        if self.dump_altitude is not None:
            altitude_setting("dump_altitude", self.dump_altitude)
        if self.search_altitude is not None:
            altitude_setting("search_altitude", self.search_altitude)
        int_setting("max_routes", self.max_routes, 1)
        int_setting("max_scored_ends", self.max_scored_ends, 2, 4096)

    def replace(self, **changes: Any) -> MilpParams:
        """A copy with ``changes`` (validated)."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        values.update(changes)
        return MilpParams(**values)


@dataclass(frozen=True, eq=False)
class MilpModel:
    """``max c @ x  s.t.  A_ub @ x <= b_ub,  x integer in [0, ub]`` plus what each variable means.

    Variables come in three blocks, in this order: ``R`` route variables (binary), ``B`` cover
    variables (integers ``0..cover_levels``, one per search block some route sweeps), ``Z`` freeze
    variables (binary, one per connected fire with a dump and a watch candidate).

    Attributes
    ----------
    c : ndarray, (n,) float64
        Objective coefficients (maximised), whole multiples of ``1 / OBJECTIVE_SCALE``.
    A_ub : scipy.sparse.csr_array, (m, n) float64
        Constraint matrix; every entry is integral.
    b_ub : ndarray, (m,) float64
        Right-hand sides (integral).
    ub : ndarray, (n,) float64
        Upper bounds (1, or ``cover_levels`` for cover variables); every lower bound is 0.
    var_kind : ndarray, (n,) int8
        ``ROUTE``, ``COVER`` or ``FREEZE``.
    var_ref : ndarray, (n,) int64
        Route row (``ROUTE``), search task row (``COVER``) or connected-fire label (``FREEZE``).
    route_agent : ndarray, (R,) int64
        Agent row of each route.
    route_kind : ndarray, (R,) int8
        ``DUMP``, ``WATCH`` or ``SEARCH``.
    route_tasks : ndarray, (R, L) int64
        Task rows of each route in visiting order, padded with -1.
    route_arrival : ndarray, (R, L) float64
        Arrival time (s from now) at each task, NaN on padding.
    route_length : ndarray, (R,) float64
        Px of the whole route, the way home included.
    route_value : ndarray, (R,) float64
        The route's own objective coefficient (dumps; search and watch routes: 0).
    altitude : ndarray, (R,) float64
        Altitude to fly the route at (NaN: agents without a camera).
    row_kind : tuple of str
        Constraint family of each row (``agent``, ``dump_once``, ``watch_once``,
        ``search_once``, ``cover``, ``freeze_dump``, ``freeze_watch``).
    agent_ids, task_ids : tuple of str
        Of the graph the model was built for.
    params : MilpParams
    size : dict
        Sizes for :class:`fcplan.scheduling.SolveStats` (variables, constraints, routes...).
    """

    c: np.ndarray
    A_ub: sp.csr_array
    b_ub: np.ndarray
    ub: np.ndarray
    var_kind: np.ndarray
    var_ref: np.ndarray
    route_agent: np.ndarray
    route_kind: np.ndarray
    route_tasks: np.ndarray
    route_arrival: np.ndarray
    route_length: np.ndarray
    route_value: np.ndarray
    altitude: np.ndarray
    row_kind: tuple[str, ...]
    agent_ids: tuple[str, ...]
    task_ids: tuple[str, ...]
    params: MilpParams
    size: dict[str, Any] = field(default_factory=dict)

    @property
    def n_vars(self) -> int:
        """Number of variables ``n``."""
        return int(self.c.size)

    @property
    def n_rows(self) -> int:
        """Number of constraints ``m``."""
        return int(self.b_ub.size)

    @property
    def n_routes(self) -> int:
        """Number of route variables ``R`` (the first ``R`` variables)."""
        return int(self.route_agent.size)

    @property
    def lb(self) -> np.ndarray:
        """(n,) lower bounds (0)."""
        return np.zeros(self.n_vars)

    @property
    def integrality(self) -> np.ndarray:
        """(n,) int8: 1 for every variable (all are integers)."""
        return np.ones(self.n_vars, dtype=np.int8)

    def objective(self, x: np.ndarray) -> float:
        """``c @ x``."""
        return float(self.c @ np.asarray(x, dtype=np.float64))

    def is_feasible(self, x: np.ndarray, tol: float = 1e-6) -> bool:
        """``x`` is integral within its bounds (within ``tol``) and satisfies every row."""
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.n_vars,):
            return False
        if np.any(np.abs(x - np.round(x)) > tol) or np.any(x < -tol) or np.any(x > self.ub + tol):
            return False
        return bool(np.all(self.A_ub @ np.round(x) <= self.b_ub + tol))

    def best_auxiliaries(self, x: np.ndarray) -> np.ndarray:
        """``x`` with every cover and freeze variable set to its best value for the routes chosen
        in ``x`` (the largest its rows allow: their objective coefficients are non-negative)."""
        x = np.asarray(x, dtype=np.float64).copy()
        aux = np.flatnonzero(self.var_kind != ROUTE)
        x[aux] = 0.0
        if aux.size == 0:
            return x
        slack = self.b_ub - self.A_ub @ x
        sub = self.A_ub[:, aux].tocoo()
        limit = self.ub[aux].copy()
        pos = sub.data > 0
        np.minimum.at(limit, sub.col[pos], np.floor(slack[sub.row[pos]] / sub.data[pos] + 1e-9))
        x[aux] = np.maximum(limit, 0.0)
        return x
