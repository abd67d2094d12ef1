"""MILP scheduler (``milp``): the route model of :mod:`solvers.milp_model`, solved exactly by CP-SAT.

The model (every short route of every agent with exact arrival times and battery, valued by the
manual's negative reward it avoids over a horizon; search blocks' expected detection; one route
per agent, one dump per fire, one watcher per connected fire) is built as numpy / scipy arrays
by :func:`solvers.milp_model.build_milp_model`; read that package's docstring for the
formulation. This module hands the arrays to OR-Tools CP-SAT, decodes the solution into a plan
and reports the solve: ``status`` (``optimal``; ``time_limit`` when a limit stopped the search
with a plan in hand), objective, best bound, relative gap and the model size.

Limits and determinism
----------------------
* **Deterministic mode** (default, ``deterministic=True``, when the caller passes no
  ``time_limit``): one worker, ``random_seed=seed``, and the search stops on CP-SAT's
  deterministic work clock, ``max_deterministic_time=work_limit`` (default 5 deterministic
  seconds, a count of work, not of wall time), never on the wall clock: the same graph (and the
  same previous plan, the warm start) gives the same plan in any process and under any load.
* **Wall-clock mode** (a ``time_limit`` given to :meth:`plan`, or ``deterministic=False`` with
  the ``time_limit`` setting): the limit covers the whole call. About 15 % of it is kept back
  for what follows the solve (completing, checking and decoding the plan). The model is the
  largest of :data:`solvers.milp_model.scheduler.MODEL_STEPS` whose build is predicted to fit
  35 % of the time (the configured model at the manual's team sizes; fewer candidates at the
  ``scale`` tier's); CP-SAT gets what is left after building it and its own arrays
  (``max_time_in_seconds``). If building used it all, or is projected to (from the segments
  valued so far), the solve is skipped and the plan finished past the deadline from the
  smallest model (``finish_late``, below).
* **No idle team**: the search starts from a complete first solution (the previous plan's
  routes still in the model, then routes of largest gain, :mod:`solvers.milp_model.start`) given
  as a hint; a part CP-SAT leaves without a solution keeps it. If the clock ran out before that
  first solution was complete, :meth:`plan` completes it past the deadline and says so
  (``finish_late=True``, the default: ``size["late"] = 1``,
  :mod:`solvers.milp_model.scheduler`); with ``finish_late=False`` it raises
  (``TimeoutError`` or :class:`solvers.milp_model.IncompletePlanError`), so
  :func:`fcplan.scheduling.solve` falls back to greedy for that replan (``status="fallback"``).

CP-SAT needs integral rows, which the model has, and gets the objective as integers: the
model's coefficients are whole multiples of ``1 / OBJECTIVE_SCALE`` (1e-4 penalty units), so
CP-SAT, HiGHS and the brute force optimise the very same objective exactly.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> plan = MilpScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
>>> plan.stats.status
'optimal'
>>> MilpScheduler(slots=0)
Traceback (most recent call last):
...
fcplan.settings.SettingError: bad setting slots=0: must be an integer in 1..4
"""

from __future__ import annotations

import numpy as np
from ortools.sat.python import cp_model

from fcplan.scheduling import SolveStats
from solvers.milp_model import IncompletePlanError, MilpModel, MilpSchedulerBase, SolverLimits
from solvers.milp_model.types import OBJECTIVE_SCALE

__all__ = ["MilpScheduler", "solve_cpsat"]

#: CP-SAT's lower end of an unbounded domain.
_INT_MIN = -(2**62)


class MilpScheduler(MilpSchedulerBase):
    """The route model solved by CP-SAT (see the module docstring).

    Parameters
    ----------
    deterministic : bool
        Without a caller's ``time_limit``, stop on ``work_limit`` only (default True).
    time_limit : float
        Wall-clock seconds per replan when ``deterministic=False`` and the caller gives none.
    work_limit : float
        CP-SAT ``max_deterministic_time`` (deterministic seconds) per replan.
    seed : int
        CP-SAT's random seed (one worker).
    finish_late : bool
        Finish a plan the wall clock cut short past the deadline (default True) instead of
        raising so that the caller falls back (:mod:`solvers.milp_model.scheduler`).
    **model_settings
        Fields of :class:`solvers.milp_model.MilpParams` (``slots``, ``search_slots``,
        ``horizon_s``, ``fire_candidates``, ``search_candidates``, ``watch_candidates``,
        ``prune_confidence``, ``threat_weight``, ``growth_cells_s``, ``search_weight``,
        ``search_block_px``, ``watch_altitude``, ``search_altitude``, ``max_routes``).
    """

    name = "milp"
    solver_name = "cp-sat"
    default_work_limit = 5.0

    def _solve(
        self, model: MilpModel, *, limits: SolverLimits, seed: int, hint: np.ndarray
    ) -> tuple[np.ndarray, SolveStats]:
        return solve_cpsat(model, limits=limits, seed=seed, hint=hint)


def _cp_model(model: MilpModel, hint: np.ndarray | None) -> cp_model.CpModel:
    """The CP-SAT model of ``model``, written straight into its proto (variables ``0..n-1``
    with domains ``[0, ub]``, one linear row each, the integral objective, the hint)."""
    md = cp_model.CpModel()
    proto = md.proto
    for u in model.ub.astype(np.int64).tolist():
        proto.variables.add().domain.extend([0, u])
    mat = model.A_ub.tocsr()
    ind = mat.indices.tolist()
    coef = np.rint(mat.data).astype(np.int64).tolist()
    ptr = mat.indptr.tolist()
    rhs = np.floor(model.b_ub + 1e-9).astype(np.int64).tolist()
    for r, b in enumerate(rhs):
        lin = proto.constraints.add().linear
        lin.vars.extend(ind[ptr[r] : ptr[r + 1]])
        lin.coeffs.extend(coef[ptr[r] : ptr[r + 1]])
        lin.domain.extend([_INT_MIN, b])
    # the integral objective: minimise -(scale c) x, reported as -(that) / scale
    nz = np.flatnonzero(model.c)
    obj = proto.objective
    obj.vars.extend(nz.tolist())
    obj.coeffs.extend((-np.rint(model.c[nz] * OBJECTIVE_SCALE)).astype(np.int64).tolist())
    obj.scaling_factor = -1.0 / OBJECTIVE_SCALE
    if hint is not None:
        on = np.flatnonzero(np.asarray(hint) > 0.5)
        proto.solution_hint.vars.extend(on.tolist())
        proto.solution_hint.values.extend(np.rint(hint[on]).astype(np.int64).tolist())
    return md


def solve_cpsat(
    model: MilpModel,
    *,
    limits: SolverLimits | None = None,
    seed: int = 0,
    hint: np.ndarray | None = None,
) -> tuple[np.ndarray, SolveStats]:
    """Solve ``model`` with CP-SAT (one worker, fixed seed).

    Parameters
    ----------
    model : MilpModel
    limits : SolverLimits, optional
        Wall-clock deadline and deterministic work limit (default: 5 deterministic seconds).
    seed : int
    hint : ndarray, (n,), optional
        A solution to start from.

    Returns
    -------
    x : ndarray, (n,) float64
    stats : SolveStats
        Status, objective, bound, gap and size.

    Raises
    ------
    IncompletePlanError
        If no solution was found within the limits.
    """
    limits = limits or SolverLimits(None, 5.0)
    n = model.n_vars
    if n == 0:
        return np.zeros(0), SolveStats(
            status="optimal", objective=0.0, bound=0.0, gap=0.0, size=dict(model.size)
        )
    md = _cp_model(model, hint)
    solver = cp_model.CpSolver()
    prm = solver.parameters
    prm.num_workers = 1
    prm.random_seed = int(seed)
    prm.max_deterministic_time = float(limits.work)
    # the full LP relaxation of the rows: the cover rows' bound is what prunes the search
    prm.linearization_level = 2
    # these small models spend most of their time in presolve: one pass, no probing
    prm.max_presolve_iterations = 1
    prm.cp_model_probing_level = 0
    left = limits.seconds_left()
    if left is not None:
        if left <= 0:
            raise IncompletePlanError("no time left for CP-SAT after building its model")
        prm.max_time_in_seconds = left
    status = solver.solve(md)
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        raise IncompletePlanError(f"CP-SAT found no solution ({solver.status_name(status)})")
    values = np.asarray(solver.response_proto.solution, dtype=np.float64)[:n]
    if not model.is_feasible(values):  # pragma: no cover - CP-SAT's solutions are feasible
        raise RuntimeError("CP-SAT returned an infeasible point")
    obj = model.objective(values)
    bound = float(solver.best_objective_bound)
    if status == cp_model.OPTIMAL:
        name, gap, bound = "optimal", 0.0, max(bound, obj)
    else:
        name, gap = "time_limit", max(bound - obj, 0.0) / max(abs(obj), 1e-9)
    size = dict(model.size, solver="cp-sat", deterministic_time=float(solver.deterministic_time))
    return values, SolveStats(status=name, objective=obj, bound=bound, gap=gap, size=size)
