"""The solver stack loads and solves in one process (highspy 1.15.x and ortools 9.15 cannot:
undefined symbol; highspy is pinned to 1.14.x in pyproject.toml)."""

from __future__ import annotations

import numpy as np


def test_ortools_and_cvxpy_highs_solve_in_one_process():
    """OR-Tools CP-SAT and MathOpt, and cvxpy through HiGHS, all solve a small MILP in the same
    process and agree on its optimum."""
    import cvxpy as cp
    import highspy
    from ortools.math_opt.python import mathopt
    from ortools.sat.python import cp_model

    # max 3x + 2y  s.t.  x + y <= 4, x + 3y <= 6, x <= 3, integers >= 0   -> optimum 11 (3, 1)
    m = cp_model.CpModel()
    x, y = m.new_int_var(0, 3, "x"), m.new_int_var(0, 10, "y")
    m.add(x + y <= 4)
    m.add(x + 3 * y <= 6)
    m.maximize(3 * x + 2 * y)
    solver = cp_model.CpSolver()
    assert solver.solve(m) == cp_model.OPTIMAL
    assert solver.objective_value == 11

    model = mathopt.Model()
    mx = model.add_integer_variable(lb=0, ub=3)
    my = model.add_integer_variable(lb=0, ub=10)
    model.add_linear_constraint(mx + my <= 4)
    model.add_linear_constraint(mx + 3 * my <= 6)
    model.maximize(3 * mx + 2 * my)
    res = mathopt.solve(model, mathopt.SolverType.CP_SAT)
    assert res.termination.reason == mathopt.TerminationReason.OPTIMAL
    assert abs(res.objective_value() - 11) < 1e-9

    v = cp.Variable(2, integer=True)
    prob = cp.Problem(
        cp.Maximize(np.array([3, 2]) @ v),
        [v >= 0, v[0] <= 3, v[0] + v[1] <= 4, v[0] + 3 * v[1] <= 6],
    )
    prob.solve(solver=cp.HIGHS)
    assert abs(prob.value - 11) < 1e-6
    assert highspy.Highs().version().startswith("1.14")
