"""MILP scheduler in cvxpy (``milp-cvxpy``): the same route model as ``milp``, solved by HiGHS.

This is the readable, hackable twin of :mod:`solvers.milp`: the model arrays come from the same
:func:`solvers.milp_model.build_milp_model` (read its docstring for the formulation), and the whole
problem is a few lines of cvxpy::

    x = cp.Variable(model.n_vars, integer=True)
    constraints = [model.A_ub @ x <= model.b_ub, x >= 0, x <= model.ub]
    problem = cp.Problem(cp.Maximize(model.c @ x), constraints)
    problem.solve(solver=cp.HIGHS, mip_rel_gap=0.0, threads=1, random_seed=0, ...)

so a user prototyping a new constraint or objective term can add a cvxpy expression next to them
(e.g. ``constraints.append(x[model.var_kind == COVER].sum() <= 300)``) and compare against ``milp``.

Limits and determinism
----------------------
cvxpy passes keyword arguments of ``solve`` for HiGHS straight to ``Highs.setOptionValue``, so the
names are HiGHS's own. One thread and ``random_seed=seed`` always; ``mip_rel_gap=0`` (prove
optimality; HiGHS's default is 1e-4).

* **Deterministic mode** (default, when the caller passes no ``time_limit``): the branch and
  bound stops after ``work_limit`` nodes (``mip_max_nodes``, default 5,000), never on the wall
  clock, so the same graph gives the same plan under any load.
* **Wall-clock mode** (a ``time_limit`` given to :meth:`plan`, or ``deterministic=False``):
  cvxpy canonicalises the model first, and HiGHS's ``time_limit`` is what is left of the call's
  limit after that (about 30 % kept back for completing, checking and decoding the plan: HiGHS
  checks its clock less often than CP-SAT). A limited solve whose point is worse than the warm
  start keeps the warm start (HiGHS takes no hint through cvxpy).
* **No idle team**: HiGHS may stop at a limit with its trivial all-zero point, or find nothing
  (:class:`solvers.milp_model.IncompletePlanError`); the part then keeps the scheduler's warm
  start (the previous plan's routes, then routes of largest gain), computed before the solve,
  and the solution is completed. If the clock ran out before even that was complete, the plan
  is finished past the deadline (``finish_late``, :mod:`solvers.milp_model.scheduler`), or,
  with ``finish_late=False``, the scheduler raises and :func:`fcplan.scheduling.solve` falls
  back to greedy (``status="fallback"``). (cvxpy passes no MIP start to HiGHS, so HiGHS itself
  starts from nothing.)

What cvxpy exposes after the solve: ``problem.status`` (``optimal``; ``user_limit`` when a limit
stopped HiGHS with a solution; ``infeasible``...), ``problem.value``, and
``problem.solver_stats.extra_stats``, which for HiGHS is the ``HighsInfo`` object:
``mip_dual_bound`` and ``mip_gap`` of the *minimisation* cvxpy hands to HiGHS (cvxpy negates a
``Maximize`` objective), so the reported bound is ``-mip_dual_bound``.

The two backends solve the same model to the same optimal value, but where several plans tie they
may return different ones, so their episodes can diverge.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> plan = MilpCvxpyScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
>>> plan.stats.status
'optimal'
"""

from __future__ import annotations

import time
import warnings

import cvxpy as cp
import numpy as np

from fcplan.scheduling import SolveStats
from solvers.milp_model import IncompletePlanError, MilpModel, MilpSchedulerBase, SolverLimits

__all__ = ["MilpCvxpyScheduler", "solve_cvxpy"]


class MilpCvxpyScheduler(MilpSchedulerBase):
    """The route model in cvxpy, solved by HiGHS.

    Parameters
    ----------
    deterministic : bool
        Without a caller's ``time_limit``, stop on ``work_limit`` only (default True).
    time_limit : float
        Wall-clock seconds per replan when ``deterministic=False`` and the caller gives none.
    work_limit : int
        HiGHS ``mip_max_nodes`` per replan.
    seed : int
        HiGHS's ``random_seed`` (one thread).
    finish_late : bool
        Finish a plan the wall clock cut short past the deadline (default True) instead of
        raising so that the caller falls back (:mod:`solvers.milp_model.scheduler`).
    **model_settings
        Fields of :class:`solvers.milp_model.MilpParams`, as for ``milp``.
    """

    name = "milp-cvxpy"
    solver_name = "highs (cvxpy)"
    default_work_limit = 5000
    work_limit_kind = int
    #: HiGHS checks its clock less often than CP-SAT: on the manual's suite at 0.1 s it ended up
    #: to 29 ms (p99) past its ``time_limit``, so this backend keeps 30 % of the limit back
    #: (bench/README.md, "Time limits")
    reserve_share = 0.3

    def _solve(
        self, model: MilpModel, *, limits: SolverLimits, seed: int, hint: np.ndarray
    ) -> tuple[np.ndarray, SolveStats]:
        return solve_cvxpy(model, limits=limits, seed=seed)


def solve_cvxpy(
    model: MilpModel, *, limits: SolverLimits | None = None, seed: int = 0
) -> tuple[np.ndarray, SolveStats]:
    """Solve ``model`` with cvxpy + HiGHS (one thread, fixed seed, ``mip_rel_gap=0``).

    Returns
    -------
    x : ndarray, (n,) float64
    stats : SolveStats
        Status, objective, bound (``-mip_dual_bound``), gap (HiGHS ``mip_gap``) and size.

    Raises
    ------
    IncompletePlanError
        If no solution was found within the limits.
    """
    limits = limits or SolverLimits(None, 5000)
    n = model.n_vars
    if n == 0:
        return np.zeros(0), SolveStats(
            status="optimal", objective=0.0, bound=0.0, gap=0.0, size=dict(model.size)
        )
    x = cp.Variable(n, integer=True)
    constraints = [x >= 0, x <= model.ub]
    if model.n_rows:
        constraints.append(model.A_ub @ x <= model.b_ub)
    problem = cp.Problem(cp.Maximize(model.c @ x), constraints)
    options = {"mip_rel_gap": 0.0, "threads": 1, "random_seed": int(seed)}
    options["mip_max_nodes"] = int(limits.work)
    t_build = time.perf_counter()
    # cvxpy's canonicalisation first, so that HiGHS's limit is what is left after it (on the
    # manual's scenarios it costs tens of ms of a 100 ms replan)
    data, chain, inverse = problem.get_problem_data(cp.HIGHS)
    left = limits.seconds_left()
    if left is not None:
        if left <= 0:
            raise IncompletePlanError("no time left for HiGHS after building the model")
        options["time_limit"] = left
    try:
        with warnings.catch_warnings():
            # cvxpy warns "Solution may be inaccurate" when a limit stops HiGHS; the status says so
            warnings.simplefilter("ignore", UserWarning)
            solution = chain.solve_via_data(problem, data, solver_opts=options)
            problem.unpack_results(solution, chain, inverse)
    except cp.error.SolverError as exc:
        raise IncompletePlanError(f"HiGHS (via cvxpy) failed: {exc}") from None
    ok = (cp.OPTIMAL, cp.OPTIMAL_INACCURATE, cp.USER_LIMIT)
    if problem.status not in ok or x.value is None:
        raise IncompletePlanError(f"HiGHS (via cvxpy) found no solution: status {problem.status}")
    values = np.asarray(x.value, dtype=np.float64)
    if not model.is_feasible(values, tol=1e-5):
        # e.g. the limit hit before HiGHS found an integer point: x holds no usable solution
        raise IncompletePlanError(
            f"HiGHS (via cvxpy) returned no feasible point ({problem.status})"
        )
    values = np.clip(np.rint(values), 0.0, model.ub)
    obj = model.objective(values)
    info = problem.solver_stats.extra_stats
    bound = -float(getattr(info, "mip_dual_bound", np.nan))
    gap = float(getattr(info, "mip_gap", np.nan))
    if problem.status == cp.OPTIMAL:
        name, gap = "optimal", 0.0 if not np.isfinite(gap) else gap
    else:
        name = "time_limit"
    if not np.isfinite(bound):
        bound = obj if name == "optimal" else float("nan")
    size = dict(model.size, solver="highs (cvxpy)", solve_s=time.perf_counter() - t_build)
    return values, SolveStats(status=name, objective=obj, bound=bound, gap=gap, size=size)
