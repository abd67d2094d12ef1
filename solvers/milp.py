"""MILP scheduler (``milp``): the joint perception-action assignment model, solved by OR-Tools CP-SAT.

The model (variables, objective, coupling of dumps to fresh sensing, tank and battery rows,
candidate pruning) is built once as numpy / scipy arrays by
:func:`solvers.milp_model.build_milp_model`; read that module's docstring for the formulation. This
module hands the arrays to CP-SAT, decodes the solution into a plan
(:func:`solvers.milp_model.decode_plan`) and reports the solve: ``status`` (``optimal``,
``feasible``, or ``time_limit`` when the limit stopped the search with a plan in hand), objective,
best bound, relative gap and the model size. If CP-SAT finds no solution (e.g. a tiny time limit)
the scheduler raises, and :func:`fcplan.scheduling.solve` falls back to greedy for that replan and
records it (``status="fallback"``).

CP-SAT
------
One worker and a fixed seed (``num_workers=1``, ``random_seed``) make the solve deterministic;
``linearization_level=2`` adds the full LP relaxation of the rows. CP-SAT needs integral rows,
which the model provides (battery terms are whole px, rounded conservatively); the real objective
coefficients are scaled by CP-SAT itself (its reported bound can be loose by its working
precision, about 1e-5 relative).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> plan = MilpScheduler().plan(g, time_limit=1.0, rng=np.random.default_rng(0))
>>> plan.stats.status
'optimal'
"""

from __future__ import annotations

import numpy as np
from ortools.sat.python import cp_model

from fcplan.scheduling import SolveStats
from solvers.milp_model import MilpModel, MilpSchedulerBase

__all__ = ["MilpScheduler", "solve_cpsat"]


class MilpScheduler(MilpSchedulerBase):
    """Joint perception-action assignment MILP solved by CP-SAT (see the module docstring).

    Parameters
    ----------
    time_limit : float
        Seconds per replan when the caller gives no limit (a given ``time_limit`` overrides it).
    seed : int
        CP-SAT's random seed (single worker, so results are deterministic).
    **model_settings
        Fields of :class:`solvers.milp_model.MilpParams` (``slots``, ``fresh_s``, ``tau_s``,
        ``slot_delay_s``, ``search_weight``, ``watch_weight``, ``fire_candidates``,
        ``search_candidates``, ``watch_altitude``, ``search_altitude``).
    """

    name = "milp"
    default_time_limit = 0.2

    def _solve(
        self, model: MilpModel, *, time_limit: float, seed: int
    ) -> tuple[np.ndarray, SolveStats]:
        return solve_cpsat(model, time_limit=time_limit, seed=seed)


def solve_cpsat(
    model: MilpModel, *, time_limit: float, seed: int = 0
) -> tuple[np.ndarray, SolveStats]:
    """Solve ``model`` with CP-SAT (one worker, fixed seed).

    Returns
    -------
    x : ndarray, (n,) float64
        The solution (0/1).
    stats : SolveStats
        Status, objective, bound, gap and size.

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
    md = cp_model.CpModel()
    x = [md.new_bool_var(f"x{j}") for j in range(n)]
    mat = model.A_ub.tocsr()
    ind, ptr = mat.indices, mat.indptr
    coef = np.rint(mat.data).astype(np.int64)
    rhs = np.floor(model.b_ub + 1e-9).astype(np.int64)
    for r in range(model.n_rows):
        lo, hi = ptr[r], ptr[r + 1]
        md.add(
            cp_model.LinearExpr.weighted_sum([x[j] for j in ind[lo:hi]], coef[lo:hi].tolist())
            <= int(rhs[r])
        )
    md.maximize(cp_model.LinearExpr.weighted_sum(x, model.c.tolist()))
    solver = cp_model.CpSolver()
    solver.parameters.num_workers = 1
    solver.parameters.random_seed = int(seed)
    solver.parameters.max_time_in_seconds = float(time_limit)
    # full LP relaxation of the linear rows (it proves optimality within the replan's limit
    # where the single-worker default may not)
    solver.parameters.linearization_level = 2
    status = solver.solve(md)
    if status not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        raise RuntimeError(
            f"CP-SAT found no solution ({solver.status_name(status)}) within {time_limit:.4f} s"
        )
    values = np.asarray(solver.response_proto.solution, dtype=np.float64)[:n]
    if not model.is_feasible(values):  # pragma: no cover - CP-SAT's solutions are feasible
        raise RuntimeError("CP-SAT returned an infeasible point")
    obj = model.objective(values)
    bound = float(solver.best_objective_bound)
    if status == cp_model.OPTIMAL:
        name, gap, bound = "optimal", 0.0, max(bound, obj)
    else:
        gap = max(bound - obj, 0.0) / max(abs(obj), 1e-9)
        hit = solver.wall_time >= 0.95 * time_limit
        name = "time_limit" if hit else "feasible"
    size = dict(model.size, solver="cp-sat")
    return values, SolveStats(status=name, objective=obj, bound=bound, gap=gap, size=size)
