"""MILP scheduler in cvxpy (``milp-cvxpy``): the same assignment model as ``milp``, solved by HiGHS.

This is the readable, hackable twin of :mod:`solvers.milp`: the model arrays come from the same
:func:`solvers.milp_model.build_milp_model` (read its docstring for the formulation), and the whole
problem is three lines of cvxpy::

    x = cp.Variable(model.n_vars, boolean=True)
    problem = cp.Problem(cp.Maximize(model.c @ x), [model.A_ub @ x <= model.b_ub])
    problem.solve(solver=cp.HIGHS, time_limit=..., mip_rel_gap=0.0, threads=1, random_seed=0)

so a user prototyping a new constraint or objective term can add a cvxpy expression next to them
(e.g. ``constraints.append(x[model.var_kind == WATCH].sum() <= 1)``) and compare against ``milp``.

Solver options: cvxpy 1.9 passes keyword arguments of ``solve`` for HiGHS straight to
``Highs.setOptionValue`` (or collects them from a ``highs_options`` dict), so the names are HiGHS's
own: ``time_limit`` (seconds), ``mip_rel_gap`` (0: prove optimality; HiGHS's default is 1e-4),
``threads``, ``random_seed``. What cvxpy exposes after the solve: ``problem.status`` (``optimal``;
``user_limit`` when the time limit stopped HiGHS with a solution; ``infeasible``...),
``problem.value``, and ``problem.solver_stats.extra_stats``, which for HiGHS is the ``HighsInfo``
object: ``mip_dual_bound``, ``mip_gap`` and ``objective_function_value`` of the *minimisation* cvxpy
hands to HiGHS (cvxpy negates a ``Maximize`` objective), so the reported bound is
``-mip_dual_bound``; ``mip_gap`` is HiGHS's relative gap. ``solve_time`` is HiGHS's run time.

cvxpy's canonicalisation adds some time per replan on top of HiGHS; ``milp`` is the fast path.
The two backends solve the same model to the same optimal value, but where several plans tie they
may return different ones, so their episodes can diverge.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> plan = MilpCvxpyScheduler().plan(g, time_limit=5.0, rng=np.random.default_rng(0))
>>> plan.stats.status
'optimal'
"""

from __future__ import annotations

import warnings

import cvxpy as cp
import numpy as np

from fcplan.scheduling import SolveStats
from solvers.milp_model import MilpModel, MilpSchedulerBase

__all__ = ["MilpCvxpyScheduler", "solve_cvxpy"]


class MilpCvxpyScheduler(MilpSchedulerBase):
    """Joint perception-action assignment MILP in cvxpy, solved by HiGHS.

    Parameters
    ----------
    time_limit : float
        Seconds per replan when the caller gives no limit (a given ``time_limit`` overrides it).
    seed : int
        HiGHS's ``random_seed`` (one thread, so results are deterministic).
    **model_settings
        Fields of :class:`solvers.milp_model.MilpParams`, as for ``milp``.
    """

    name = "milp-cvxpy"
    default_time_limit = 0.5

    def _solve(
        self, model: MilpModel, *, time_limit: float, seed: int
    ) -> tuple[np.ndarray, SolveStats]:
        return solve_cvxpy(model, time_limit=time_limit, seed=seed)


def solve_cvxpy(
    model: MilpModel, *, time_limit: float, seed: int = 0
) -> tuple[np.ndarray, SolveStats]:
    """Solve ``model`` with cvxpy + HiGHS (one thread, fixed seed, ``mip_rel_gap=0``).

    Returns
    -------
    x : ndarray, (n,) float64
        The solution (0/1).
    stats : SolveStats
        Status, objective, bound (``-mip_dual_bound``), gap (HiGHS ``mip_gap``) and size.

    Raises
    ------
    RuntimeError
        If no solution was found.
    """

    n = model.n_vars
    if n == 0:
        return np.zeros(0), SolveStats(
            status="optimal", objective=0.0, bound=0.0, gap=0.0, size=dict(model.size)
        )
    x = cp.Variable(n, boolean=True)
    constraints = [model.A_ub @ x <= model.b_ub] if model.n_rows else []
    problem = cp.Problem(cp.Maximize(model.c @ x), constraints)
    try:
        with warnings.catch_warnings():
            # cvxpy warns "Solution may be inaccurate" when the limit stops HiGHS; the status says so
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(
                solver=cp.HIGHS,
                time_limit=float(time_limit),
                mip_rel_gap=0.0,
                threads=1,
                random_seed=int(seed),
            )
    except cp.error.SolverError as exc:
        raise RuntimeError(f"HiGHS (via cvxpy) failed: {exc}") from None
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE, cp.USER_LIMIT) or x.value is None:
        raise RuntimeError(f"HiGHS (via cvxpy) found no solution: status {problem.status}")
    values = np.asarray(x.value, dtype=np.float64)
    if not model.is_feasible(values, tol=1e-5):
        # e.g. the limit hit before HiGHS found an integer point: x holds no usable solution
        raise RuntimeError(f"HiGHS (via cvxpy) returned no feasible 0/1 point ({problem.status})")
    values = np.clip(np.rint(values), 0.0, 1.0)
    obj = model.objective(values)
    info = problem.solver_stats.extra_stats
    bound = -float(getattr(info, "mip_dual_bound", np.nan))
    gap = float(getattr(info, "mip_gap", np.nan))
    if problem.status == cp.OPTIMAL:
        name, gap = "optimal", 0.0 if not np.isfinite(gap) else gap
    else:
        name = "time_limit" if problem.status == cp.USER_LIMIT else "feasible"
    if not np.isfinite(bound):
        bound = obj if name == "optimal" else float("nan")
    size = dict(model.size, solver="highs (cvxpy)")
    return values, SolveStats(status=name, objective=obj, bound=bound, gap=gap, size=size)
