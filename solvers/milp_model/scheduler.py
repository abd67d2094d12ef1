"""What both MILP schedulers share: settings, the two limit modes, the warm start, and the check
that a plan cut short by a limit does not leave agents idle.

A scheduler keeps two things between the replans of an episode (forgotten when a graph comes
from an earlier time than the last one): its last plan, the warm start of the next solve, and
the fire tasks of the last ``recent_fire_s`` seconds, which value the search blocks near fire
that has just been put out (:class:`~solvers.milp_model.objective.FireSnapshot`: each counts the
known cells near the blocks once, for every model after it).

Model size under a wall-clock limit
-----------------------------------
In the deterministic mode the model is always the configured one. Under a wall-clock limit the
build may take at most ``build_share`` of the time left before the solve's deadline, so that the
warm start and the solver keep the rest: the scheduler builds the first of
:data:`MODEL_STEPS` (the configured model, then fewer candidates and scored ends, each step
capping the configured settings) whose predicted build time fits. The prediction is the step's
build time per agent measured on the ``scale`` tier (:data:`STEP_COST_S`) times the number of
agents times a factor for this machine and load, which every build in wall-clock mode updates
(the ratio of measured to prior, in logs: it rises at once to a slower build's, and falls
slowly, a fifth of the way per build; a build stopped by the deadline counts as at least its
time so far). The step a plan came from is in its stats
(``size["model_step"]``, 0: the configured model). At the manual's team sizes the configured
model fits 0.1 s; at the ``scale`` tier's 18-30 agents it does not (``bench/README.md``).

When the clock runs out first
-----------------------------
A wall-clock limit can pass before the plan is complete: the build overran (a load spike, a
prediction too low), or it left no time, or the warm start was cut short. With
``finish_late=True`` (the default) the scheduler then finishes its own plan past the deadline
instead of giving up: it builds the smallest model step without a deadline if it has no model,
and completes the warm start (the previous plan's routes, then routes of largest gain) without
one; the solve is skipped. The plan is the MILP's own construction on its own objective, so
nothing falls back to greedy, at the cost of an overrun on that replan (the smallest model's
build and the construction: a few ms on the manual's teams, some tens at the ``scale`` tier).
Such a plan says so: ``size["late"] = 1`` and a ``message`` naming what ran out. With
``finish_late=False`` it raises as before (``TimeoutError``, :class:`IncompletePlanError`) and
:func:`fcplan.scheduling.solve` falls back to greedy for that replan. The deterministic mode has
no deadline, so it never finishes late.

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
from solvers.milp_model.objective import FireSnapshot
from solvers.milp_model.solve import LnsSettings, SolverLimits, solve_model
from solvers.milp_model.start import complete, idle_agents, initial_solution
from solvers.milp_model.types import IncompletePlanError, MilpModel, MilpParams

__all__ = ["MilpSchedulerBase"]


_LNS = ("exact_routes", "lns_routes", "lns_rounds")

#: The model sizes a wall-clock limit steps down through: each caps the configured settings.
MODEL_STEPS: tuple[dict[str, int], ...] = (
    {},
    {"search_candidates": 6, "fire_candidates": 5, "max_scored_ends": 128},
    {"search_candidates": 4, "fire_candidates": 4, "max_scored_ends": 64},
    {"search_candidates": 3, "fire_candidates": 3, "watch_candidates": 2, "slots": 2,
     "search_slots": 1, "max_scored_ends": 16},
)  # fmt: skip
#: Build seconds per agent of each step at the ``scale`` tier (``python bench/bench_milp_build.py
#: --designs scale-tier --set ...``, 2026-11-29, bench/README.md): the prediction's priors.
STEP_COST_S = (3.5e-3, 2.6e-3, 1.6e-3, 0.8e-3)


def _finished_late(stats: SolveStats, objective: float, late: list[str]) -> SolveStats:
    """``stats`` of a plan finished past the deadline (module docstring): ``size["late"] = 1``,
    the reasons in the message, the objective of the completed solution."""
    bound = max(stats.bound, objective)
    gap = (bound - objective) / max(abs(objective), 1e-9)
    why = "; ".join(m for m in [*late, stats.message] if m)
    return replace(stats, size=dict(stats.size, late=1), objective=objective, bound=bound,
                   gap=gap, message=f"finished past the deadline: {why}")  # fmt: skip


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
    finish_late : bool
        Under a wall-clock limit, finish the plan past the deadline when the clock runs out
        before it is complete (default True), instead of raising so that the caller falls
        back (module docstring, "When the clock runs out first").
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
    #: share of the time before the solve's deadline that building the model may take
    build_share = 0.35
    #: share of the wall-clock limit by which the warm start must be complete (it may use part of
    #: the reserve: at the ``scale`` tier at 0.1 s a warm start cut at the solve's deadline was
    #: the commonest fallback)
    start_share = 0.95

    def __init__(
        self,
        deterministic: bool = True,
        time_limit: float = 0.2,
        work_limit: float | None = None,
        seed: int = 0,
        exact_routes: int = LnsSettings.exact_routes,
        lns_routes: int = LnsSettings.lns_routes,
        lns_rounds: int = LnsSettings.lns_rounds,
        finish_late: bool = True,
        **model_settings: Any,
    ) -> None:
        self.deterministic = bool_setting("deterministic", deterministic)
        self.finish_late = bool_setting("finish_late", finish_late)
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
                own = ["deterministic", "time_limit", "work_limit", "seed", *_LNS, "finish_late"]
                takes = ", ".join([*own, *known])
                raise SettingError(key, f"unknown setting; {self.name} takes: {takes}", value=value)
        self.params = MilpParams(**model_settings)
        self._steps = [
            self.params.replace(**{k: min(getattr(self.params, k), v) for k, v in caps.items()})
            for caps in MODEL_STEPS
        ]
        self._log_factor = 0.0  # log of measured over predicted build time, averaged
        self._previous: dict[str, tuple[str, ...]] = {}
        self._previous_time = -math.inf
        self._recent: list[tuple[float, FireSnapshot]] = []

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Build the model of ``graph``, solve it and decode the plan.

        A given ``time_limit`` (s) is a wall-clock limit for the whole call (model building
        included, about 15 % kept back for what follows the solve); without one the call stops on the work
        limit only (``deterministic=True``) or on the ``time_limit`` setting.

        If the limit passes before the plan is complete, the plan is finished past it
        (``finish_late``, module docstring: ``size["late"] = 1``).

        Raises
        ------
        TimeoutError
            With ``finish_late=False``: if building the model used up the wall-clock limit
            (checked between the build's steps and its chunks of segments).
        IncompletePlanError
            With ``finish_late=False``: if a limit stopped the solver with no plan, or with
            agents left idle that a route would have improved (the plan came from the limit,
            not from a decision).
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
        recent = [snap for t, snap in self._recent if t >= keep]
        step = 0 if deadline is None else self._step(graph.n_agents, deadline - t0)
        late: list[str] = []  # what the clock cut short (module docstring)
        try:
            model = self._build(graph, step, recent, deadline)
        except TimeoutError as exc:
            if not self.finish_late:
                raise
            late.append(str(exc))
            step = len(MODEL_STEPS) - 1
            model = self._build(graph, step, recent, None)
        limits = SolverLimits(deadline, self.work_limit)
        left = limits.seconds_left()
        if left is not None and left <= 0 and not late:
            why = f"building the model took {time.perf_counter() - t0:.4f} s of {limit} s"
            if not self.finish_late:
                raise TimeoutError(why)
            late.append(why)
        # the warm start may run into the reserve: complete past the solve's deadline it is still
        # a plan (the solve and the completion are then skipped), cut short it is finished late
        start_by = None if limit is None or late else t0 + float(limit) * self.start_share
        hint = initial_solution(model, graph, self._previous, deadline=start_by)
        x, stats = solve_model(
            model,
            hint,
            graph.agent_start_pos,
            self._solve,
            limits=limits,
            seed=self.seed,
            settings=self.lns,
        )
        # the completion of the solution (solve_model's last step) stops only at the deadline:
        # before it, the completion ran until no route gains, so no agent is idle with work
        # (a plan already finishing late had its warm start completed without a deadline)
        done = deadline is None or bool(late) or time.perf_counter() < deadline
        idle = np.zeros(0, dtype=np.int64) if done else idle_agents(model, x)
        if idle.size:  # only when the deadline passed before the warm start was complete
            names = ", ".join(graph.agent_ids[a] for a in idle.tolist())
            why = f"the wall-clock limit left agents {names} idle with routes to fly"
            if not self.finish_late:
                raise IncompletePlanError(why)
            late.append(why)
            x = complete(model, x)
        stats = replace(stats, size=dict(stats.size, solver=self.solver_name, model_step=step))
        if late:
            stats = _finished_late(stats, model.objective(x), late)
        plan = decode_plan(model, x, graph, stats)
        self._previous = dict(plan.routes)
        self._previous_time = graph.time_s
        fires = graph.fire_tasks
        self._recent = [r for r in self._recent if r[0] >= keep]
        if fires.size:
            snap = FireSnapshot(graph.task_pos[fires], graph.task_cells[fires])
            self._recent.append((graph.time_s, snap))
        return plan

    def _predicted(self, n_agents: int, step: int) -> float:
        """Predicted build seconds of ``step`` for ``n_agents`` on this machine."""
        return STEP_COST_S[step] * max(n_agents, 1) * math.exp(self._log_factor)

    def _step(self, n_agents: int, before_deadline: float) -> int:
        """The first model step whose predicted build fits ``build_share`` of the time."""
        budget = self.build_share * before_deadline
        for step in range(len(MODEL_STEPS)):
            if self._predicted(n_agents, step) <= budget:
                return step
        return len(MODEL_STEPS) - 1

    def _build(
        self,
        graph: TaskGraph,
        step: int,
        recent: list[FireSnapshot],
        deadline: float | None,
    ) -> MilpModel:
        """Build the model of ``step``; under a deadline, learn from the time it took."""
        start = time.perf_counter()
        try:
            return build_milp_model(graph, self._steps[step], recent_fire=recent, deadline=deadline)
        finally:
            if deadline is not None:
                prior = STEP_COST_S[step] * max(graph.n_agents, 1)
                ratio = (time.perf_counter() - start) / prior
                new = math.log(max(ratio, 1e-6))
                # rises at once (a slower machine or a load spike), falls slowly
                self._log_factor = float(
                    np.clip(max(new, 0.8 * self._log_factor + 0.2 * new), -3.0, 3.0)
                )

    def _solve(
        self, model: MilpModel, *, limits: SolverLimits, seed: int, hint: np.ndarray
    ) -> tuple[np.ndarray, SolveStats]:  # pragma: no cover
        raise NotImplementedError
