"""The route model both MILP schedulers solve: team orienteering over enumerated short routes.

Both MILP schedulers (:mod:`solvers.milp`, OR-Tools CP-SAT; :mod:`solvers.milp_cvxpy`, cvxpy +
HiGHS) solve the model built here, from the same arrays, so they solve the *identical* problem.
This package also decodes a solution into a :class:`fcplan.plan.Plan`, scores any plan on the
model (:func:`plan_objective`) and holds a brute-force enumerator for tiny models (the tests'
ground truth).

What is optimised
-----------------
The manual scores an episode by its negative reward, the integral of ``0.1 |A(t)| + sum_f PC_f
n_f(t)`` (active cells, active cells inside facility ``f``; :mod:`fcplan.metrics`). The model
maximises the part of it a replan's routes avoid over a rolling horizon ``H`` (``horizon_s``):
a cell put out or found ``t`` seconds from now stops costing (or can be put out) for the
``H - t`` seconds left of it. All values below are in those penalty units.

Routes (set partitioning)
-------------------------
For every agent, every route of at most ``slots`` fire tasks (dumps, capped by the tank; a
hybrid flies them at ``dump_altitude``, by default the top of its bounds: a dump puts out every
sensed burning cell in view, and the view grows with the altitude), of one fire task to **watch** (a camera agent without water hovers over it at ``watch_altitude``), or of
at most ``search_slots`` search blocks (flown at the altitude of best detection rate,
:func:`~solvers.milp_model.sensing.best_search_altitude`) is enumerated over the agent's best
``fire_candidates`` / ``watch_candidates`` / ``search_candidates`` tasks
(:mod:`~solvers.milp_model.routes`). Each route has **exact** arrival times ``t_j`` from the
agent's start and own speed, and is kept only if the whole flight, the way home included, fits
the agent's budget (:meth:`fcplan.taskgraph.TaskGraph.route_ok`). Agents on a forced return
start from their depot slot once they get there; agents sent home may be given a route again.

Variables: ``y_r`` (binary) chooses route ``r``; ``x_b`` (integer ``0..L``) is the detected
share of search block ``b`` in steps of ``1 / L`` (``L = cover_levels``); ``u_c`` (binary) marks a connected fire ``c`` that is
both dumped on and watched.

Objective (maximise)::

    sum_r D_r y_r  +  sum_b (V_b / L) x_b  +  sum_c F_c u_c

* **dumps**: ``D_r = sum_{j: fire} q n_k w_k (H - t_j)+`` with ``q`` the prune confidence
  (``prune_confidence``), ``n_k`` the task's known (sensed, hence prunable) cells and
  ``w_k = 0.1 + theta sum_f PC_f (1 - tau_kf / H)+`` the penalty rate of one of its cells:
  ``tau_kf`` is the graph's estimated time for fire ``k`` to reach facility ``f``
  (``threat_time_s``, the ``threatens`` edges), ``theta`` is ``threat_weight``;
* **search** (expected detection): block ``b`` is taken to hide ``E_b`` undiscovered burning
  cells, ``E_b = kappa 60 (A_b / 60) ** alpha (1 + min(n_b, 50) / 10)`` with ``A_b`` its
  coverage age (``task_staleness``, capped at ``search_age_cap_s``) and ``n_b`` the known
  cells in the 3 x 3 blocks around it (``kappa = search_weight``,
  ``alpha = search_age_exponent``; :func:`~solvers.milp_model.objective.hidden_cells`); found
  now they are worth ``V_b = 0.1 E_b H``. A route sweeping ``b`` ``t`` seconds from now finds
  them with probability ``s_rb`` = covered share x sensing probability at the route's altitude
  (:mod:`~solvers.milp_model.sensing`) x ``(H_s - t)+ / H_s``, the best of the route's legs
  (``H_s = search_horizon_s``: the agent replans long before a far sweep would happen);
* **growth stopped**: fronts move on into unsensed cells, and only sensed cells can be put out,
  so a connected fire stops growing only when it is watched (by a watch route or a dumping agent
  with a camera) *and* dumped on: ``F_c = 0.1 q gamma (H - t_c)+^2 / 2`` for ``gamma``
  (``growth_cells_s``) cells per second stopped from ``t_c``, the earliest arrival of an agent
  with water at a task of ``c`` (straight from its start: a property of the graph).

Constraints (all ``A_ub [y; x; u] <= b_ub``, integral)::

    sum_{r of agent a} y_r <= 1                      (agent: one route each)
    sum_{r dumps on k} y_r <= 1                      (dump_once: one dump per fire task)
    sum_{r watches c} y_r <= 1                       (watch_once: one watcher per fire)
    sum_{r searches b first} y_r <= 1                (search_once: one searcher heads for b)
    x_b - sum_r round(L s_rb) y_r <= 0,  x_b <= L     (cover: a block is found once)
    u_c - sum_{r dumps in c} y_r <= 0                (freeze_dump)
    u_c - sum_{r senses c} y_r <= 0                  (freeze_watch)

Battery, tank, roles and the round-trip rule hold route by route, so they need no rows. The
cover rows make overlapping sweeps count once (a share above 100 % is worth 100 %), which
spreads the searchers without any spacing rule. Shares are rounded to ``1 / L``: a sweep that
finds less than half a step of a block does not count for it.

Modules: :mod:`~solvers.milp_model.types` (settings and the model's arrays),
:mod:`~solvers.milp_model.sensing` (field of view, detection, swept blocks),
:mod:`~solvers.milp_model.routes` (roles, candidates, enumeration),
:mod:`~solvers.milp_model.objective` (values), :mod:`~solvers.milp_model.constraints` (rows),
:mod:`~solvers.milp_model.build` (the model), :mod:`~solvers.milp_model.decode` (plans from
solutions, any plan's objective), :mod:`~solvers.milp_model.start` (warm start, idle agents),
:mod:`~solvers.milp_model.brute_force` (exact optimum of tiny models) and
:mod:`~solvers.milp_model.scheduler` (what both schedulers share). Tuning history and measured
tables are in ``bench/README.md``.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> m = build_milp_model(g, MilpParams(search_candidates=3))
>>> m.n_vars == m.c.size == m.A_ub.shape[1]
True
>>> x, obj = brute_force_optimum(m)
>>> bool(m.is_feasible(x)) and bool(np.isclose(m.objective(x), obj))
True
>>> sorted(decode_plan(m, x, g).routes)
['A3', 'P1', 'P2']
"""

from solvers.milp_model.brute_force import brute_force_optimum
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.decode import decode_plan, plan_objective
from solvers.milp_model.scheduler import MilpSchedulerBase
from solvers.milp_model.solve import SolverLimits
from solvers.milp_model.types import (
    COVER,
    DUMP,
    FREEZE,
    KIND_NAMES,
    ROUTE,
    SEARCH,
    WATCH,
    IncompletePlanError,
    MilpModel,
    MilpParams,
)

__all__ = [
    "ROUTE",
    "COVER",
    "FREEZE",
    "DUMP",
    "WATCH",
    "SEARCH",
    "KIND_NAMES",
    "MilpParams",
    "MilpModel",
    "build_milp_model",
    "decode_plan",
    "brute_force_optimum",
    "plan_objective",
    "MilpSchedulerBase",
    "SolverLimits",
    "IncompletePlanError",
]
