"""Benchmark the MILP schedulers: per-replan solve time, optimality share, model sizes, scores.

Runs whole episodes (seed 0) in a process pool and prints:

* ``milp`` over scenarios 1-24: per-replan wall time of the scheduler call (as measured by
  :func:`fcplan.scheduling.solve`, validation included) p50 / p95 / max, the share of replans
  solved to proven optimality (status ``optimal``, gap 0), status counts, fallbacks, and model
  sizes (variables, constraints, nonzeros) p50 / p95 / max;
* the same for ``milp-cvxpy`` on a few scenarios;
* the mean manual final score of ``milp`` against ``greedy`` over the same scenarios, per
  scenario and on average;
* with ``--backends``: the OR-Tools backends (CP-SAT directly; MathOpt with HiGHS, SCIP and
  CP-SAT) on models captured from the ``milp`` episodes (every 4th replan), single thread,
  transfer + solve wall time, share optimal and the largest objective difference.

Usage::

    python bench/bench_milp.py                  # scenarios 1-24, pool of 2 (a few minutes)
    python bench/bench_milp.py --backends       # also compare the OR-Tools backends
    python bench/bench_milp.py --scenarios 1 2 3 --cvxpy-scenarios 1
"""

from __future__ import annotations

import argparse
import datetime
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor

import numpy as np

import fcplan
from fcplan.scheduling import make_scheduler
from solvers.milp_model import MilpModel, build_milp_model


class _Capture:
    """Wraps a MILP scheduler and keeps every ``every``-th model it builds."""

    def __init__(self, inner, every: int) -> None:
        self.inner, self.every, self.models, self.calls = inner, every, [], 0
        self.name = inner.name

    def plan(self, graph, *, time_limit=None, rng=None):
        if self.calls % self.every == 0:
            self.models.append(build_milp_model(graph, self.inner.params))
        self.calls += 1
        return self.inner.plan(graph, time_limit=time_limit, rng=rng)


def _episode(job):
    scenario, name, capture = job
    sched = make_scheduler(name)
    if capture:
        sched = _Capture(sched, every=4)
    r = fcplan.run_episode(scenario, sched, seed=0)
    return {
        "scenario": scenario,
        "scheduler": name,
        "final": r.metrics["manual"].final_score,
        "times": r.solve_times_s,
        "status": [s.status for s in r.solves],
        "sizes": [s.size for s in r.solves if s.status != "fallback"],
        "models": sched.models if capture else [],
    }


def _pct(a, q) -> float:
    return float(np.percentile(a, q)) if len(a) else float("nan")


def report(rows, label: str) -> None:
    t = np.concatenate([r["times"] for r in rows]) * 1e3
    st = Counter(s for r in rows for s in r["status"])
    n = sum(st.values())
    print(f"## {label}: {len(rows)} episodes, {n} replans")
    print(
        f"solve ms  p50 {_pct(t, 50):.2f}  p95 {_pct(t, 95):.2f}  max {t.max():.1f};  "
        f"optimal {st['optimal'] / n:.1%};  statuses {dict(st)}"
    )
    for key in ("variables", "constraints", "nonzeros"):
        v = [s.get(key, 0) for r in rows for s in r["sizes"]]
        print(f"{key:<12} p50 {_pct(v, 50):.0f}  p95 {_pct(v, 95):.0f}  max {max(v)}")
    print()


def _mathopt_solve(model: MilpModel, solver: str, time_limit: float):
    from ortools.math_opt import model_pb2
    from ortools.math_opt.python import mathopt

    p = model_pb2.ModelProto()
    n, m = model.n_vars, model.n_rows
    p.variables.ids.extend(range(n))
    p.variables.lower_bounds.extend([0.0] * n)
    p.variables.upper_bounds.extend([1.0] * n)
    p.variables.integers.extend([True] * n)
    p.objective.maximize = True
    nz = np.flatnonzero(model.c)
    p.objective.linear_coefficients.ids.extend(nz.tolist())
    p.objective.linear_coefficients.values.extend(model.c[nz].tolist())
    p.linear_constraints.ids.extend(range(m))
    p.linear_constraints.lower_bounds.extend([-np.inf] * m)
    p.linear_constraints.upper_bounds.extend(model.b_ub.tolist())
    coo = model.A_ub.tocoo()
    o = np.lexsort((coo.col, coo.row))
    p.linear_constraint_matrix.row_ids.extend(coo.row[o].tolist())
    p.linear_constraint_matrix.column_ids.extend(coo.col[o].tolist())
    p.linear_constraint_matrix.coefficients.extend(coo.data[o].tolist())
    kind = getattr(mathopt.SolverType, solver)
    params = mathopt.SolveParameters(
        time_limit=datetime.timedelta(seconds=time_limit),
        threads=None if kind == mathopt.SolverType.HIGHS else 1,  # HiGHS: set by its globals
        random_seed=0,
        relative_gap_tolerance=0.0,
        absolute_gap_tolerance=1e-9,
    )
    mo = mathopt.Model.from_model_proto(p)
    res = mathopt.solve(mo, kind, params=params)
    ok = res.termination.reason == mathopt.TerminationReason.OPTIMAL
    return model.objective(np.array(res.variable_values(list(mo.variables())), dtype=float)), ok


def bench_backends(models, time_limit: float = 0.2) -> None:
    from solvers.milp import solve_cpsat

    def cpsat(m):
        x, st = solve_cpsat(m, time_limit=time_limit)
        return m.objective(x), st.status == "optimal"

    backends = {
        "CP-SAT (cp_model)": cpsat,
        "MathOpt + SCIP": lambda m: _mathopt_solve(m, "GSCIP", time_limit),
        "MathOpt + CP-SAT": lambda m: _mathopt_solve(m, "CP_SAT", time_limit),
        "MathOpt + HiGHS": lambda m: _mathopt_solve(m, "HIGHS", time_limit),
    }
    print(f"## OR-Tools backends on {len(models)} models from the milp episodes")
    ref = None
    for name, fn in backends.items():
        ts, objs, opt = [], [], []
        for m in models:
            t = time.perf_counter()
            o, ok = fn(m)
            ts.append(time.perf_counter() - t)
            objs.append(o)
            opt.append(ok)
        ts, objs = np.array(ts) * 1e3, np.array(objs)
        ref = objs if ref is None else ref
        print(
            f"{name:<18} optimal {np.mean(opt):.1%}  ms p50 {np.median(ts):.2f}  "
            f"p95 {_pct(ts, 95):.2f}  max {ts.max():.1f}  max |obj - CP-SAT| "
            f"{np.abs(objs - ref).max():.1e}"
        )
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", nargs="+", type=int, default=list(range(1, 25)))
    ap.add_argument("--cvxpy-scenarios", nargs="+", type=int, default=[1, 12, 24])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--backends", action="store_true")
    args = ap.parse_args()

    jobs = [(s, "milp", args.backends) for s in args.scenarios]
    jobs += [(s, "greedy", False) for s in args.scenarios]
    jobs += [(s, "milp-cvxpy", False) for s in args.cvxpy_scenarios]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as ex:
        rows = list(ex.map(_episode, jobs))
    print(f"(episodes took {time.perf_counter() - t0:.0f} s with {args.workers} workers)\n")
    by = {name: [r for r in rows if r["scheduler"] == name] for name in ("milp", "greedy")}
    report(by["milp"], "milp")
    report([r for r in rows if r["scheduler"] == "milp-cvxpy"], "milp-cvxpy")
    print("## Manual final score (seed 0)")
    print(f"{'scenario':>8} {'greedy':>8} {'milp':>8} {'diff':>8}")
    for g, m in zip(by["greedy"], by["milp"], strict=True):
        print(
            f"{g['scenario']:>8} {g['final']:>8.1f} {m['final']:>8.1f} {m['final'] - g['final']:>8.1f}"
        )
    mg = np.mean([r["final"] for r in by["greedy"]])
    mm = np.mean([r["final"] for r in by["milp"]])
    print(f"{'mean':>8} {mg:>8.1f} {mm:>8.1f} {mm - mg:>8.1f}")
    for r in rows:
        if r["scheduler"] == "milp-cvxpy":
            print(f"milp-cvxpy #{r['scenario']}: final {r['final']:.1f}")
    print()
    if args.backends:
        bench_backends([m for r in by["milp"] for m in r["models"]])


if __name__ == "__main__":
    main()
