"""What both MILP schedulers share: settings, the two limit modes, the warm start, and the check
that a plan cut short by a limit does not leave agents idle.

A scheduler keeps two things between the replans of an episode (forgotten when a graph comes
from an earlier time than the last one): its last plan, the warm start of the next solve, and
the fire tasks of the last ``recent_fire_s`` seconds, which value the search blocks near fire
that has just been put out.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp import MilpScheduler
>>> g = synthetic_task_graph(30, 60, np.random.default_rng(0))
>>> s = MilpScheduler(exact_routes=200, lns_routes=200)
>>> plan = s.plan(g)
>>> plan.stats.status, plan.stats.size["parts"], plan.stats.bound >= plan.stats.objective
('feasible', 1, True)
"""

from __future__ import annotations

import math
import time
from dataclasses import fields, replace
from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import (
    SettingError,
    SolveStats,
    bool_setting,
    float_setting,
    int_setting,
)
from fcplan.taskgraph import TaskGraph
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.decode import decode_plan
from solvers.milp_model.solve import LnsSettings, SolverLimits, solve_model
from solvers.milp_model.start import idle_agents, initial_solution
from solvers.milp_model.types import IncompletePlanError, MilpModel, MilpParams

__all__ = ["MilpSchedulerBase"]


_LNS = ("exact_routes", "lns_routes", "lns_rounds")


class MilpSchedulerBase:
    """What both MILP schedulers share (see :mod:`solvers.milp` for the settings' meaning).

    Subclasses set ``name``, ``default_work_limit`` and ``work_limit_kind`` (``float`` or
    ``int``) and implement :meth:`_solve` (one backend).

    Parameters
    ----------
    deterministic : bool
        When the caller gives no ``time_limit``: stop on ``work_limit`` only (True, default:
        identical plans under any load) or on the wall-clock ``time_limit`` setting (False).
    time_limit : float
        Wall-clock seconds per replan in non-deterministic mode when the caller gives none.
    work_limit : float or int
        The backend's deterministic work limit (CP-SAT: deterministic seconds; HiGHS: nodes).
    seed : int
        The backend's random seed (one worker / thread) and the search's seed.
    exact_routes, lns_routes, lns_rounds : int
        Parts of the model with at most ``exact_routes`` routes are solved at once; larger ones
        by large-neighbourhood search, at most ``lns_rounds`` rounds freeing at most
        ``lns_routes`` routes each (:mod:`solvers.milp_model.solve`).
    **model_settings
        Fields of :class:`MilpParams`.
    """

    name = "milp-base"
    solver_name = "none"
    #: the ``deterministic`` parameter sits beside ``**model_settings``, which hides it from the
    #: signature check of :func:`fcplan.scheduling.supports_deterministic`
    supports_deterministic = True
    default_work_limit: float = 1.0
    work_limit_kind: type = float
    #: share of the wall-clock limit kept back for what follows the solve: completing the
    #: solution, the idle check, decoding and the caller's validation. Measured on the manual's
    #: suite at 0.1 s (bench/README.md, "Time limits"): the solve ends up to 14 ms after its
    #: deadline (CP-SAT overshoots by up to 5 ms, then the completion) and 4-5 ms more follow;
    #: 5 % left p99 at 109-117 ms against the 115 ms bound.
    reserve_share = 0.15

    def __init__(
        self,
        deterministic: bool = True,
        time_limit: float = 0.2,
        work_limit: float | None = None,
        seed: int = 0,
        exact_routes: int = LnsSettings.exact_routes,
        lns_routes: int = LnsSettings.lns_routes,
        lns_rounds: int = LnsSettings.lns_rounds,
        **model_settings: Any,
    ) -> None:
        self.deterministic = bool_setting("deterministic", deterministic)
        self.time_limit = float_setting("time_limit", time_limit, 0.0, lo_open=True, unit=" s")
        work = self.default_work_limit if work_limit is None else work_limit
        if self.work_limit_kind is int:
            self.work_limit: float = int_setting("work_limit", work, 1)
        else:
            self.work_limit = float_setting("work_limit", work, 0.0, lo_open=True)
        self.seed = int_setting("seed", seed, 0, 2**31 - 1)
        self.lns = LnsSettings(exact_routes, lns_routes, lns_rounds)
        known = [f.name for f in fields(MilpParams)]
        for key, value in model_settings.items():
            if key not in known:
                own = ["deterministic", "time_limit", "work_limit", "seed", *_LNS]
                takes = ", ".join([*own, *known])
                raise SettingError(key, f"unknown setting; {self.name} takes: {takes}", value=value)
        self.params = MilpParams(**model_settings)
        self._previous: dict[str, tuple[str, ...]] = {}
        self._previous_time = -math.inf
        self._recent: list[tuple[float, np.ndarray, np.ndarray]] = []

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Build the model of ``graph``, solve it and decode the plan.

        A given ``time_limit`` (s) is a wall-clock limit for the whole call (model building
        included, about 15 % kept back for what follows the solve); without one the call stops on the work
        limit only (``deterministic=True``) or on the ``time_limit`` setting.

        Raises
        ------
        TimeoutError
            If building the model used up the wall-clock limit (checked between agents).
        IncompletePlanError
            If a limit stopped the solver with no plan, or with agents left idle that a route
            would have improved (the plan came from the limit, not from a decision).
        """
        t0 = time.perf_counter()
        if time_limit is not None:
            float_setting("time_limit", time_limit, 0.0, unit=" s")
        limit = (
            time_limit
            if time_limit is not None
            else None
            if self.deterministic
            else self.time_limit
        )
        deadline = None if limit is None else t0 + float(limit) * (1.0 - self.reserve_share)
        if graph.time_s <= self._previous_time:  # a new episode: forget the last plans
            self._previous, self._recent = {}, []
        keep = graph.time_s - self.params.recent_fire_s
        recent = [(pos, cells) for t, pos, cells in self._recent if t >= keep]
        model = build_milp_model(graph, self.params, recent_fire=recent, deadline=deadline)
        limits = SolverLimits(deadline, self.work_limit)
        left = limits.seconds_left()
        if left is not None and left <= 0:
            raise TimeoutError(
                f"building the model took {time.perf_counter() - t0:.4f} s of {limit} s"
            )
        hint = initial_solution(model, graph, self._previous, deadline=deadline)
        x, stats = solve_model(
            model,
            hint,
            graph.agent_start_pos,
            self._solve,
            limits=limits,
            seed=self.seed,
            settings=self.lns,
        )
        idle = idle_agents(model, x)
        if idle.size:  # only when the deadline passed before the warm start was complete
            names = ", ".join(graph.agent_ids[a] for a in idle.tolist())
            raise IncompletePlanError(
                f"the wall-clock limit left agents {names} idle with routes to fly"
            )
        stats = replace(stats, size=dict(stats.size, solver=self.solver_name))
        plan = decode_plan(model, x, graph, stats)
        self._previous = dict(plan.routes)
        self._previous_time = graph.time_s
        fires = graph.fire_tasks
        self._recent = [r for r in self._recent if r[0] >= keep]
        if fires.size:
            self._recent.append((graph.time_s, graph.task_pos[fires], graph.task_cells[fires]))
        return plan

    def _solve(
        self, model: MilpModel, *, limits: SolverLimits, seed: int, hint: np.ndarray
    ) -> tuple[np.ndarray, SolveStats]:  # pragma: no cover
        raise NotImplementedError
