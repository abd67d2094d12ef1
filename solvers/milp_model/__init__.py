"""
Both MILP schedulers (:mod:`solvers.milp`, OR-Tools; :mod:`solvers.milp_cvxpy`, cvxpy + HiGHS) solve
the model built here, from the same arrays, so they solve the *identical* problem. This package also
decodes a solution vector into a :class:`fcplan.plan.Plan` and holds a brute-force enumerator for
tiny models (used by the tests as ground truth).

The model
---------
Every agent that is not sent home (``HOMING``) gets ``S`` ordered **slots** (``slots``, default 2);
each slot holds at most one task. A binary variable ``x[a, k, s]`` says that agent ``a`` serves task
``k`` in slot ``s``, in one of three **kinds** fixed by the agent's role and the task:

* ``DUMP``: an action or hybrid agent with water (on a forced return: a full tank, it refills first)
  dumps on fire task ``k``;
* ``WATCH``: a perception agent (or a hybrid with an empty tank) hovers over fire task ``k`` at a low
  altitude, keeping its connected fire freshly sensed;
* ``SEARCH``: an agent with a camera (re)explores search block ``k``.

Auxiliary binaries ``z[k, s]`` (kind ``AUX``) mark a fire task ``k`` dumped in slot ``s`` while
its connected fire is sensed (see the coupling below).

Objective (maximise)::

    sum  search_weight * v_k * disc[a,k,s] * x      (SEARCH: v_k = coverage-age value of the block)
  + sum  watch_weight  * v_k * disc[a,k,s] * x      (WATCH: a watched fire's new cells get sensed)
  + sum  v_k * disc[a,k,s] * x                      (DUMP on a fresh fire)
  - sum  v_k * (1 - disc[a,k,s]) * x                (DUMP on a stale fire ...)
  + sum  v_k * z[k,s]                               (... worth v_k * disc only when sensed)
  + sum  support_weight * v_k * z[k,s]              (fresh fire dumped *and* watched)

``v_k`` is the task graph's ``task_value``: for fires ``cells * (1 + threat)``, so the facility
threat weights are already in it; for search blocks the capped coverage age times a bonus near
known fire (``search_weight`` puts it on the fire scale). The **travel-time discount** is
``disc = 1 / (1 + eta / tau_s)`` with ``eta`` the estimated arrival time: ``d(start, k) / speed``
for slot 0 (exact, straight line), and the same plus ``s * slot_delay_s`` for slot ``s >= 1`` (an
estimate: the previous task is not known when the coefficient is fixed; ``d(start, k) / speed`` is
a lower bound on the arrival time by the triangle inequality and ``slot_delay_s`` stands for
serving the earlier tasks and the detour). Later slots are therefore worth less, and the solver
puts the better task first.

**Coupling** (only sensed cells can be pruned): a dump is worth its value only if its fire is
freshly sensed, either already (``task_staleness <= fresh_s``) or because a sensor is assigned to
that fire's connected fire (``task_cluster``) in the same or an earlier slot. For a fire task ``k``
with a dump candidate in slot ``s``::

    z[k, s] <= sum_a x_DUMP[a, k, s]
    z[k, s] <= sum { x[a', k', s'] : WATCH, or DUMP by a hybrid (it senses before it dumps),
                     cluster(k') = cluster(k), s' <= s }

For a *stale* fire, a dump nets ``v_k * disc`` when ``z = 1`` and ``-v_k * (1 - disc) <= 0``
otherwise: a stale fire that nobody watches is worth nothing (the spec's ``z <= fresh + watch``,
``z <= dump``, objective ``value * discount * z``, written with one ``z`` per (fire, slot) and the
discount moved into a travel penalty so that it can differ between agents). For a *fresh* fire the
dump is worth ``v_k * disc`` on its own, and ``z`` (only built when ``support_weight > 0``) adds
``support_weight * v_k`` when a sensor watches its connected fire too: the cells that ignite between
the last look and the dump are unsensed and cannot be pruned unless someone is watching.

Constraints (all ``A_ub x <= b_ub``, every variable binary):

* one task per agent and slot; slots filled in order (``sum_k x[a,k,s] <= sum_k x[a,k,s-1]``);
* each fire task dumped by at most one agent and watched by at most one agent over all slots;
* **spread** (search blocks): at most one search assignment (any agent, any slot) among the blocks
  within ``spread_px`` of any candidate block, so each block is taken at most once and searchers do
  not crowd (rows whose block set is contained in another row's are dropped);
* **tank**: DUMP assignments of an agent ``<=`` its tank (rows only where the tank is smaller than
  the number of slots; otherwise the row is implied by one task per slot);
* **battery** (linear, conservative): ``(d(start,k) + d(k,home)) x[a,k,0] + sum_{s>=1} 2 d(home,k)
  x[a,k,s] <= range`` with ``range`` the agent's budget,
  :attr:`fcplan.taskgraph.TaskGraph.agent_budget_px` (full battery on a forced return). By the
  triangle inequality ``d(k_i, k_{i+1}) <= d(k_i, home) + d(home, k_{i+1})``, so the true length of
  the route start -> k_1 -> ... -> k_n -> home is at most the left-hand side: a plan within the row
  is flyable without a stop at the depot. Coefficients are rounded *up* to whole px and the range
  *down*, which keeps the row conservative and integral (CP-SAT needs integer rows). Rows only where
  the agent's worst case could exceed its range.

**Pre-filtering and pruning** keep the model small: an ``(a, k, s)`` variable exists only when the
role fits, the task is within a full-battery round trip of the agent's depot slot, and the slot's
battery term fits on its own (``d(start,k) + d(k,home) <= range`` for slot 0,
``min first leg + 2 d(home,k) <= range`` for later slots). Among the remaining tasks each agent keeps
its ``fire_candidates`` best fire tasks and ``search_candidates`` best search blocks by slot-0
discounted value (ties by task order). All of it is numpy: no Python loop over tasks.

Modules: :mod:`~solvers.milp_model.types` (settings and the model's arrays),
:mod:`~solvers.milp_model.variables`, :mod:`~solvers.milp_model.objective`,
:mod:`~solvers.milp_model.constraints`, :mod:`~solvers.milp_model.build` (the model),
:mod:`~solvers.milp_model.decode` (plans from solutions, and any plan's objective),
:mod:`~solvers.milp_model.brute_force` (exact optimum of tiny models) and
:mod:`~solvers.milp_model.scheduler` (what both schedulers share).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> m = build_milp_model(g)
>>> m.n_vars == m.c.size == m.A_ub.shape[1]
True
>>> x, obj = brute_force_optimum(m)
>>> plan = decode_plan(m, x, g)
>>> bool(np.isclose(m.c @ x, obj))
True
"""

from solvers.milp_model.brute_force import brute_force_optimum
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.decode import decode_plan, plan_objective
from solvers.milp_model.scheduler import MilpSchedulerBase
from solvers.milp_model.types import AUX, DUMP, KIND_NAMES, SEARCH, WATCH, MilpModel, MilpParams

__all__ = [
    "DUMP",
    "WATCH",
    "SEARCH",
    "AUX",
    "KIND_NAMES",
    "MilpParams",
    "MilpModel",
    "build_milp_model",
    "decode_plan",
    "brute_force_optimum",
    "plan_objective",
    "MilpSchedulerBase",
]
