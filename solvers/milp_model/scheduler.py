"""What both MILP schedulers share: settings, the two limit modes, the warm start, and the check
that a plan cut short by a limit does not leave agents idle.

A scheduler keeps two things between the replans of an episode (forgotten when a graph comes
from an earlier time than the last one): its last plan, the warm start of the next solve, and
the fire tasks of the last ``recent_fire_s`` seconds, which value the search blocks near fire
that has just been put out.

Examples
--------
>>> import time
>>> limits = SolverLimits(deadline=time.perf_counter() + 1.0, work=5.0)
>>> 0.0 < limits.seconds_left() <= 1.0, SolverLimits(None, 5.0).seconds_left()
(True, None)
"""

from __future__ import annotations

import math
import time
from dataclasses import fields
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
from solvers.milp_model.start import idle_agents, initial_solution
from solvers.milp_model.types import MilpModel, MilpParams

__all__ = ["MilpSchedulerBase", "SolverLimits", "IncompletePlanError"]


class IncompletePlanError(RuntimeError):
    """A limit stopped the solver before it had a plan for every agent that has work."""


class SolverLimits:
    """The limits of one solve: a wall-clock deadline (``perf_counter`` seconds, or None) and a
    deterministic work limit (the backend's unit)."""

    __slots__ = ("deadline", "work")

    def __init__(self, deadline: float | None, work: float) -> None:
        self.deadline, self.work = deadline, work

    def seconds_left(self, reserve: float = 0.0) -> float | None:
        """Wall seconds left before the deadline minus ``reserve`` (None: no deadline)."""
        if self.deadline is None:
            return None
        return self.deadline - time.perf_counter() - reserve


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
        The backend's random seed (one worker / thread).
    **model_settings
        Fields of :class:`MilpParams`.
    """

    name = "milp-base"
    default_work_limit: float = 1.0
    work_limit_kind: type = float
    #: share of the wall-clock limit kept back for decoding and validation
    reserve_share = 0.05

    def __init__(
        self,
        deterministic: bool = True,
        time_limit: float = 0.2,
        work_limit: float | None = None,
        seed: int = 0,
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
        known = [f.name for f in fields(MilpParams)]
        for key, value in model_settings.items():
            if key not in known:
                takes = ", ".join(["deterministic", "time_limit", "work_limit", "seed", *known])
                raise SettingError(key, f"unknown setting; {self.name} takes: {takes}", value=value)
        self.params = MilpParams(**model_settings)
        self._previous: dict[str, tuple[str, ...]] = {}
        self._previous_time = -math.inf
        self._recent: list[tuple[float, np.ndarray, np.ndarray]] = []

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Build the model of ``graph``, solve it and decode the plan.

        A given ``time_limit`` (s) is a wall-clock limit for the whole call (model building
        included, about 5 % kept back for decoding); without one the call stops on the work
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
        x, stats = self._solve(model, limits=limits, seed=self.seed, hint=hint)
        if stats.status != "optimal":
            idle = idle_agents(model, x)
            if idle.size:
                names = ", ".join(graph.agent_ids[a] for a in idle.tolist())
                raise IncompletePlanError(
                    f"the {stats.status} stop left agents {names} idle with routes to fly"
                )
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
