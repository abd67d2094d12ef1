"""Solving a route model of any size with one exact backend: independent parts, exact solves of
the small ones, large-neighbourhood search on the large ones, and an honest report.

:func:`solve_model` splits the model into its independent parts
(:func:`~solvers.milp_model.decompose.components`) and, for each part in order:

* up to ``exact_routes`` routes: one exact solve by the backend (CP-SAT or HiGHS), started from
  the warm start where the backend takes one; the backend's status and bound are the part's;
* larger: :func:`~solvers.milp_model.lns.large_neighbourhood_search` from the warm start, each
  round an exact solve of at most ``lns_routes`` routes with a tenth of the work limit; the part's
  bound is :func:`~solvers.milp_model.decompose.gain_bound` (no solver proves more).

Under a wall-clock deadline each part gets a share of the time left in proportion to its routes.
A part whose solve finds nothing within its limit keeps the warm start, and so does every part
left when the deadline has passed (counted in ``size["parts_skipped"]``; the bound then adds
:func:`~solvers.milp_model.decompose.loose_bound`, which costs one pass, for them). The solution is then
completed (:func:`~solvers.milp_model.start.complete`): routes of positive gain are added to
agents left without one, so a limit never leaves an agent idle that has work (unless the
deadline passed before the warm start itself was complete; the scheduler then raises).

The report (:class:`fcplan.scheduling.SolveStats`): ``optimal`` when every part was proved
optimal; ``time_limit`` when a limit stopped a solve or the search; ``feasible`` when a search
converged without a proof. ``objective`` is the solution's, ``bound`` the sum of the parts'
bounds and ``gap = (bound - objective) / |objective|``; ``size`` adds ``parts``,
``lns_rounds``, ``lns_improved`` and the backends' summed work.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp import solve_cpsat
>>> from solvers.milp_model import build_milp_model
>>> from solvers.milp_model.start import initial_solution
>>> g = synthetic_task_graph(12, 40, np.random.default_rng(0))
>>> m = build_milp_model(g)
>>> x0 = initial_solution(m, g, {})
>>> settings = LnsSettings(exact_routes=100, lns_routes=150, lns_rounds=20)
>>> x, stats = solve_model(m, x0, g.agent_start_pos, solve_cpsat, limits=None, seed=0,
...                        settings=settings)
>>> bool(m.is_feasible(x)), stats.status, stats.bound >= stats.objective >= m.objective(x0)
(True, 'feasible', True)
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan.scheduling import SolveStats, int_setting
from solvers.milp_model.decompose import components, gain_bound, loose_bound, restrict
from solvers.milp_model.lns import large_neighbourhood_search
from solvers.milp_model.start import complete
from solvers.milp_model.types import IncompletePlanError, MilpModel

__all__ = ["Backend", "LnsSettings", "SolverLimits", "solve_model"]

#: ``backend(model, *, limits, seed, hint) -> (x, stats)``: an exact solve (raises
#: :class:`~solvers.milp_model.types.IncompletePlanError` when it finds nothing in its limits).
Backend = Callable[..., tuple[np.ndarray, SolveStats]]


class SolverLimits:
    """The limits of one solve: a wall-clock deadline (``perf_counter`` seconds, or None) and a
    deterministic work limit (the backend's unit).

    Examples
    --------
    >>> limits = SolverLimits(deadline=time.perf_counter() + 1.0, work=5.0)
    >>> 0.0 < limits.seconds_left() <= 1.0, SolverLimits(None, 5.0).seconds_left()
    (True, None)
    """

    __slots__ = ("deadline", "work")

    def __init__(self, deadline: float | None, work: float) -> None:
        self.deadline, self.work = deadline, work

    def seconds_left(self, reserve: float = 0.0) -> float | None:
        """Wall seconds left before the deadline minus ``reserve`` (None: no deadline)."""
        if self.deadline is None:
            return None
        return self.deadline - time.perf_counter() - reserve


@dataclass(frozen=True)
class LnsSettings:
    """When a part is solved at once and how the search runs (see the module docstring)."""

    exact_routes: int = 3000  # largest part (routes) solved at once
    lns_routes: int = 600  # most routes freed per search round
    lns_rounds: int = 60  # most search rounds per part

    def __post_init__(self) -> None:
        int_setting("exact_routes", self.exact_routes, 1)
        int_setting("lns_routes", self.lns_routes, 1)
        int_setting("lns_rounds", self.lns_rounds, 1)


def _part_limits(limits: SolverLimits, share: float) -> SolverLimits:
    left = limits.seconds_left()
    if left is None:
        return limits
    return SolverLimits(time.perf_counter() + max(left, 0.0) * share, limits.work)


def _solve_part(
    sub: MilpModel,
    hint: np.ndarray,
    positions: np.ndarray,
    backend: Backend,
    limits: SolverLimits,
    seed: int,
    settings: LnsSettings,
) -> tuple[np.ndarray, str, float, dict[str, Any]]:
    """One part: (x, status, bound, counters)."""
    if sub.n_routes <= settings.exact_routes:
        try:
            x, st = backend(sub, limits=limits, seed=seed, hint=hint)
        except IncompletePlanError as exc:  # out of time: the cheap bound
            return hint, "time_limit", loose_bound(sub), {"message": str(exc)}
        if st.status != "optimal" and sub.objective(x) < sub.objective(hint):
            # a limit stopped a backend that takes no hint (HiGHS through cvxpy) at a worse
            # point than the warm start: keep the better of the two (an anytime incumbent)
            x = hint
        work = float(st.size.get("deterministic_time", 0.0))
        bound = float(st.bound) if np.isfinite(st.bound) else gain_bound(sub)
        return x, st.status, bound, {"work": work}
    per_round = SolverLimits(limits.deadline, limits.work / 10.0)

    def round_solve(model: MilpModel, h: np.ndarray) -> tuple[np.ndarray, SolveStats]:
        return backend(model, limits=per_round, seed=seed, hint=h)

    res = large_neighbourhood_search(
        sub,
        hint,
        positions,
        round_solve,
        max_routes=settings.lns_routes,
        rounds=settings.lns_rounds,
        seed=seed,
        deadline=limits.deadline,
    )
    status = "time_limit" if res.stopped == "deadline" else "feasible"
    counters = {"work": res.work, "lns_rounds": res.rounds, "lns_improved": res.improved}
    return res.x, status, gain_bound(sub), counters


def solve_model(
    model: MilpModel,
    hint: np.ndarray,
    positions: np.ndarray,
    backend: Backend,
    *,
    limits: SolverLimits | None,
    seed: int,
    settings: LnsSettings | None = None,
) -> tuple[np.ndarray, SolveStats]:
    """Solve ``model`` from the complete feasible ``hint`` (module docstring); ``positions``
    (A, 2) are the agents' start positions (neighbourhoods of the search)."""
    settings = settings or LnsSettings()
    limits = limits or SolverLimits(None, 5.0)
    parts = components(model)
    x = np.asarray(hint, dtype=np.float64).copy()
    statuses: list[str] = []
    bound = 0.0
    counters: dict[str, Any] = {"parts": len(parts), "work": 0.0, "lns_rounds": 0,
                                "lns_improved": 0}  # fmt: skip
    messages = []
    left_routes = float(model.n_routes)
    skipped = 0
    for part in parts:
        if limits.deadline is not None and time.perf_counter() >= limits.deadline:
            skipped += 1  # out of time: the part keeps the warm start
            continue
        sub = restrict(model, part, x) if len(parts) > 1 else None
        sub_model = sub.model if sub is not None else model
        cols = sub.cols if sub is not None else np.arange(model.n_vars)
        part_limits = _part_limits(limits, part.size / max(left_routes, 1.0))
        left_routes -= part.size
        xs, status, b, extra = _solve_part(
            sub_model, x[cols], positions, backend, part_limits, seed, settings
        )
        x[cols] = xs
        statuses.append(status)
        bound += b
        if "message" in extra:
            messages.append(extra.pop("message"))
        for key, v in extra.items():
            counters[key] += v
    if skipped:
        statuses.append("time_limit")
        bound += loose_bound(model)  # covers the skipped parts (and more)
        messages.append(f"the deadline passed before {skipped} of {len(parts)} parts")
    counters["parts_skipped"] = skipped
    x = complete(model, x, limits.deadline)
    obj = model.objective(x)
    if all(s == "optimal" for s in statuses):
        name = "optimal"
    elif "time_limit" in statuses:
        name = "time_limit"
    else:
        name = "feasible"
    bound = max(bound, obj)
    gap = 0.0 if name == "optimal" else (bound - obj) / max(abs(obj), 1e-9)
    size = dict(model.size, **counters)
    stats = SolveStats(
        status=name, objective=obj, bound=bound, gap=gap, size=size, message="; ".join(messages)
    )
    return x, stats
