"""The joint perception-action assignment MILP, built once as numpy / scipy arrays.

Both MILP schedulers (:mod:`solvers.milp`, OR-Tools; :mod:`solvers.milp_cvxpy`, cvxpy + HiGHS) solve
the model built here, from the same arrays, so they solve the *identical* problem. This module also
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
  x[a,k,s] <= range`` with ``range = battery / 0.1`` px (full battery on a forced return). By the
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
discounted value (ties by task order). All of it is numpy: no Python loop over tasks. On the
replans of ``milp`` episodes of scenarios 1-24 the models have 64 variables, 22 rows and 304
nonzeros at the median, 238, 88 and 1,332 at most (``python bench/bench_milp.py``).

Default settings
----------------
Chosen by whole episodes of scenarios 1-24 (mean manual final score, seeds 0-2; greedy scores
266.2 / 267.1 / 269.4): the literal reading (``fresh_s=5``, no support bonus, no spread rows, 6
search candidates, ``tau_s=2``) scored 247.8 on seed 0. Two effects dominated. (1) With 6 search
candidates per agent, all perception agents had the same few blocks next to the depot as
candidates: without spread rows they crowded there, with them one agent was left without a task,
so fires were found late; 16 candidates plus the spread rows fixed it. (2) The coupling seldom
bound, because fires counted as fresh from incidental sensing, so perception agents searched while
action agents dumped on fires whose new cells nobody had sensed; the support bonus pairs a watcher
with the dump, as greedy does by construction. With ``fresh_s=10, support_weight=3, tau_s=1,
search_weight=0.3`` the means are 265.5 / 262.8 / 263.6 (greedy: 266.2 / 267.1 / 269.4); per
scenario the two differ by up to +-40 points either way. A short ``fresh_s`` (0.5 s, so that every
dump needs a watcher) left action agents unassigned in far more replans with known fire (2,850
agent-replans against greedy's 715 on seed 0) and averaged 260.2; with it, three slots scored lower
than two (251.0 vs 260.4 on seed 0).

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

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from fcplan.plan import Plan
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode

__all__ = [
    "DUMP",
    "WATCH",
    "SEARCH",
    "AUX",
    "MilpParams",
    "MilpModel",
    "build_milp_model",
    "decode_plan",
    "brute_force_optimum",
    "plan_objective",
    "MilpSchedulerBase",
]

#: Variable kinds (:attr:`MilpModel.var_kind`).
DUMP, WATCH, SEARCH, AUX = 0, 1, 2, 3
KIND_NAMES = ("dump", "watch", "search", "aux")


@dataclass(frozen=True, slots=True)
class MilpParams:
    """Settings of the assignment model (shared by both MILP schedulers).

    Parameters
    ----------
    slots : int
        Ordered task slots per agent (the planning horizon in tasks).
    fresh_s : float
        A fire sensed within this many seconds is fresh: dumping on it needs no watcher (a stale
        one is worth nothing without one).
    tau_s : float
        Time constant of the travel-time discount ``1 / (1 + eta / tau_s)``.
    slot_delay_s : float
        Estimated extra arrival time per earlier slot (see the module docstring).
    search_weight : float
        Weight of a search block's coverage-age value against fire values.
    watch_weight : float
        Weight of a fire's value for the agent watching it (its own sensing reward; the coupling
        gives watching its main worth).
    spread_px : float
        Search assignments (all agents, all slots) at most one among the blocks within this
        distance of any candidate block (150 px: no two on neighbouring 100-px blocks); 0: only
        each block at most once.
    support_weight : float
        Bonus (times the fire's value) for a dump on a *fresh* fire whose connected fire is also
        watched in the same or an earlier slot (the watcher senses the cells that appeared since,
        so the dump can prune them). 0 turns it off (then fresh fires get no ``z``).
    fire_candidates, search_candidates : int
        Fire tasks / search blocks kept per agent (best slot-0 discounted value).
    watch_altitude, search_altitude : float
        Altitudes (m, clipped to each agent's bounds) of agents whose route starts with a fire
        task / a search block.
    """

    slots: int = 2
    fresh_s: float = 10.0
    tau_s: float = 1.0
    slot_delay_s: float = 3.0
    search_weight: float = 0.3
    watch_weight: float = 0.2
    fire_candidates: int = 6
    search_candidates: int = 16
    spread_px: float = 150.0
    support_weight: float = 3.0
    watch_altitude: float = 35.0
    search_altitude: float = 70.0

    def __post_init__(self) -> None:
        if self.slots < 1:
            raise ValueError(f"slots must be >= 1, got {self.slots}")
        if not self.tau_s > 0:
            raise ValueError(f"tau_s must be > 0, got {self.tau_s}")
        if self.fire_candidates < 0 or self.search_candidates < 0:
            raise ValueError("candidate counts must be >= 0")


@dataclass(frozen=True, eq=False)
class MilpModel:
    """``max c @ x  s.t.  A_ub @ x <= b_ub,  x in {0, 1}^n`` plus what each variable means.

    Attributes
    ----------
    c : ndarray, (n,) float64
        Objective coefficients (maximised).
    A_ub : scipy.sparse.csr_array, (m, n) float64
        Constraint matrix; every entry is integral.
    b_ub : ndarray, (m,) float64
        Right-hand sides (integral).
    integrality : ndarray, (n,) int8
        1 for integer variables (all of them: every variable is binary, bounds ``[0, 1]``).
    var_agent, var_task, var_slot : ndarray, (n,) int64
        Agent row, task row and slot of each variable (``var_agent = -1`` for ``AUX``).
    var_kind : ndarray, (n,) int8
        ``DUMP``, ``WATCH``, ``SEARCH`` or ``AUX``.
    row_kind : tuple of str
        Constraint family of each row (``slot``, ``order``, ``once``, ``spread``, ``tank``,
        ``battery``, ``couple_dump``, ``couple_watch``).
    agent_ids, task_ids : tuple of str
        Of the graph the model was built for.
    params : MilpParams
    size : dict
        Sizes for :class:`fcplan.scheduling.SolveStats` (variables, constraints, nonzeros, ...).
    """

    c: np.ndarray
    A_ub: sp.csr_array
    b_ub: np.ndarray
    integrality: np.ndarray
    var_agent: np.ndarray
    var_task: np.ndarray
    var_slot: np.ndarray
    var_kind: np.ndarray
    row_kind: tuple[str, ...]
    agent_ids: tuple[str, ...]
    task_ids: tuple[str, ...]
    params: MilpParams
    size: dict = field(default_factory=dict)

    @property
    def n_vars(self) -> int:
        """Number of variables ``n``."""
        return int(self.c.size)

    @property
    def n_rows(self) -> int:
        """Number of constraints ``m``."""
        return int(self.b_ub.size)

    @property
    def lb(self) -> np.ndarray:
        """(n,) lower bounds (0)."""
        return np.zeros(self.n_vars)

    @property
    def ub(self) -> np.ndarray:
        """(n,) upper bounds (1)."""
        return np.ones(self.n_vars)

    def objective(self, x: np.ndarray) -> float:
        """``c @ x``."""
        return float(self.c @ np.asarray(x, dtype=np.float64))

    def is_feasible(self, x: np.ndarray, tol: float = 1e-6) -> bool:
        """``x`` is 0/1 (within ``tol``) and satisfies every row."""
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.n_vars,):
            return False
        if np.any(np.abs(x - np.round(x)) > tol) or np.any(x < -tol) or np.any(x > 1 + tol):
            return False
        return bool(np.all(self.A_ub @ np.round(x) <= self.b_ub + tol))


# ---------------------------------------------------------------------------------------- build
def build_milp_model(graph: TaskGraph, params: MilpParams | None = None) -> MilpModel:
    """Build the assignment MILP of ``graph`` (see the module docstring).

    Parameters
    ----------
    graph : TaskGraph
    params : MilpParams, optional

    Returns
    -------
    MilpModel
    """
    p = params or MilpParams()
    n_slots = p.slots
    fire = graph.task_kind == TaskKind.FIRE
    mode = graph.agent_mode
    free = mode != Mode.HOMING
    tank = np.where(mode == Mode.RETURNING, graph.agent_tank_capacity, graph.agent_tank)
    act = free & graph.agent_can_act & (tank > 0)
    sense = free & graph.agent_can_sense

    # ---- kind of each (agent, task) pair, -1 if the role does not fit
    kind = np.full((graph.n_agents, graph.n_tasks), -1, dtype=np.int8)
    kind[np.ix_(sense, ~fire)] = SEARCH
    kind[np.ix_(sense & ~act, fire)] = WATCH
    kind[np.ix_(act, fire)] = DUMP

    # ---- battery terms (whole px, conservative) and feasibility pre-filter
    start = graph.agent_start_pos
    d0 = np.hypot(*(start[:, None, :] - graph.task_pos[None, :, :]).transpose(2, 0, 1))
    dh = graph.task_home_distance
    first_leg = np.ceil(d0 + dh - 1e-9)
    later_leg = np.ceil(2.0 * dh - 1e-9)
    rng_px = np.floor(graph.agent_budget_px + 1e-6)
    ok = (kind >= 0) & graph.in_round_trip
    ok0 = ok & (first_leg <= rng_px[:, None])
    min_first = np.where(ok0, first_leg, np.inf).min(axis=1, initial=np.inf)
    ok_later = ok & (min_first[:, None] + later_leg <= rng_px[:, None])

    # ---- values and discount (slot 0) for candidate pruning
    speed = np.maximum(graph.agent_speed, 1e-9)
    eta0 = d0 / speed[:, None]
    value = graph.task_value.astype(np.float64)
    score = value[None, :] / (1.0 + eta0 / p.tau_s)
    keep = np.zeros_like(ok)
    for cat_mask, n_keep in ((fire, p.fire_candidates), (~fire, p.search_candidates)):
        cand = (ok0 | ok_later) & cat_mask[None, :]
        if n_keep <= 0 or not cand.any():
            continue
        s = np.where(cand, score, -np.inf)
        order = np.argsort(-s, axis=1, kind="stable")[:, :n_keep]
        rows = np.arange(graph.n_agents)[:, None]
        keep[rows, order] |= np.isfinite(s[rows, order])

    # ---- primary variables, ordered by (agent, slot, task)
    pa, pk = np.nonzero(keep)  # row-major: agent, then task
    slot_ok = np.stack([ok0[pa, pk]] + [ok_later[pa, pk]] * (n_slots - 1), axis=0)  # (n_slots, P)
    ss, pp = np.nonzero(slot_ok)
    va, vk, vs = pa[pp], pk[pp], ss
    order = np.lexsort((vk, vs, va))
    va, vk, vs = va[order], vk[order], vs[order]
    vkind = kind[va, vk]
    n_x = va.size

    eta = eta0[va, vk] + vs * p.slot_delay_s
    disc = 1.0 / (1.0 + eta / p.tau_s)
    v = value[vk]
    stale = (graph.task_staleness > p.fresh_s) & fire
    weight = np.select(
        [vkind == SEARCH, vkind == WATCH], [p.search_weight, p.watch_weight], default=1.0
    )
    c_x = weight * v * disc
    stale_dump = (vkind == DUMP) & stale[vk]
    c_x = np.where(stale_dump, -v * (1.0 - disc), c_x)

    # ---- auxiliary z[k, s] for fires with a dump candidate in slot s: stale fires (their dump is
    # worth v_k only when sensed) and, with support_weight > 0, fresh ones (bonus for a watcher)
    zsel = stale_dump | ((vkind == DUMP) & (p.support_weight > 0))
    zkey = np.unique(vk[zsel] * n_slots + vs[zsel])
    zk, zs = zkey // n_slots, zkey % n_slots
    n_z = zk.size
    c = np.r_[c_x, value[zk] * np.where(stale[zk], 1.0, p.support_weight)]
    var_agent = np.r_[va, np.full(n_z, -1)].astype(np.int64)
    var_task = np.r_[vk, zk].astype(np.int64)
    var_slot = np.r_[vs, zs].astype(np.int64)
    var_kind = np.r_[vkind, np.full(n_z, AUX)].astype(np.int8)
    xi = np.arange(n_x)

    rows_i: list[np.ndarray] = []
    cols_j: list[np.ndarray] = []
    vals: list[np.ndarray] = []
    rhs: list[np.ndarray] = []
    fam: list[str] = []
    n_rows = 0

    def add(group: np.ndarray, cols: np.ndarray, coef: np.ndarray, b_of_group, name: str) -> None:
        """Rows from a group label per entry (entries with the same label share a row)."""
        nonlocal n_rows
        if group.size == 0:
            return
        labels, inv = np.unique(group, return_inverse=True)
        rows_i.append(n_rows + inv)
        cols_j.append(cols)
        vals.append(np.asarray(coef, dtype=np.float64))
        rhs.append(np.asarray(b_of_group(labels), dtype=np.float64))
        fam.extend([name] * labels.size)
        n_rows += labels.size

    ones = np.ones(n_x)
    # one task per (agent, slot)
    add(va * n_slots + vs, xi, ones, lambda lab: np.ones(lab.size), "slot")
    # slots in order: slot-s vars (+1) and slot-(s-1) vars (-1) of the same agent, for s >= 1
    later = vs >= 1
    ord_group = np.r_[va[later] * n_slots + vs[later], va * n_slots + vs + 1]
    ord_cols = np.r_[xi[later], xi]
    ord_coef = np.r_[np.ones(later.sum()), -np.ones(n_x)]
    has_later = np.isin(ord_group, va[later] * n_slots + vs[later])
    add(
        ord_group[has_later],
        ord_cols[has_later],
        ord_coef[has_later],
        lambda lab: np.zeros(lab.size),
        "order",
    )
    # each task at most once per kind (dump, watch, search) over all agents and slots; with
    # spread_px > 0 the search rows are replaced by the spread rows below (which imply them)
    once = (vkind != SEARCH) | (p.spread_px <= 0)
    add(vk[once] * 3 + vkind[once], xi[once], ones[once], lambda lab: np.ones(lab.size), "once")
    # spread: at most one search assignment among the blocks within spread_px of any candidate
    # block (searchers do not crowd; an agent's two slots go to blocks apart)
    srch = np.flatnonzero(vkind == SEARCH)
    if p.spread_px > 0 and srch.size:
        blocks, bidx = np.unique(vk[srch], return_inverse=True)
        near = graph.task_distance[np.ix_(blocks, blocks)] <= p.spread_px  # (U, U)
        # drop rows whose neighbourhood is contained in another's (they are implied)
        inter = near.astype(np.int64) @ near.T.astype(np.int64)
        cnt = near.sum(axis=1)
        sub = (inter == cnt[:, None]) & (
            (cnt[None, :] > cnt[:, None])
            | (
                (cnt[None, :] == cnt[:, None])
                & (np.arange(blocks.size)[None, :] < np.arange(blocks.size)[:, None])
            )
        )
        np.fill_diagonal(sub, False)
        rows_u = np.flatnonzero(~sub.any(axis=1))
        ru, rv = np.nonzero(near[np.ix_(rows_u, bidx)])
        add(ru, srch[rv], np.ones(ru.size), lambda lab: np.ones(lab.size), "spread")
    # tank (only where it binds: fewer dumps left than slots)
    tank_rows = (vkind == DUMP) & (tank[va] < n_slots)
    add(va[tank_rows], xi[tank_rows], ones[tank_rows], lambda lab: tank[lab], "tank")
    # battery (only where the worst case exceeds the range)
    coef = np.where(vs == 0, first_leg[va, vk], later_leg[va, vk])
    worst = np.zeros((graph.n_agents, n_slots))
    np.maximum.at(worst, (va, vs), coef)
    bat_rows = worst.sum(axis=1)[va] > rng_px[va]
    add(va[bat_rows], xi[bat_rows], coef[bat_rows], lambda lab: rng_px[lab], "battery")
    # coupling
    if n_z:
        zi = n_x + np.arange(n_z)
        # z[k,s] <= sum_a dump[a,k,s]
        dump = np.flatnonzero(vkind == DUMP)
        match = (vk[dump][None, :] == zk[:, None]) & (vs[dump][None, :] == zs[:, None])
        zr, dj = np.nonzero(match)
        add(
            np.r_[np.arange(n_z), zr],
            np.r_[zi, dump[dj]],
            np.r_[np.ones(n_z), -np.ones(zr.size)],
            lambda lab: np.zeros(lab.size),
            "couple_dump",
        )
        # z[k,s] <= sum of sensors on the same cluster in slots <= s
        sensor = np.flatnonzero((vkind == WATCH) | ((vkind == DUMP) & graph.agent_can_sense[va]))
        cl = graph.task_cluster
        match = (cl[vk[sensor]][None, :] == cl[zk][:, None]) & (vs[sensor][None, :] <= zs[:, None])
        zr, wj = np.nonzero(match)
        add(
            np.r_[np.arange(n_z), zr],
            np.r_[zi, sensor[wj]],
            np.r_[np.ones(n_z), -np.ones(zr.size)],
            lambda lab: np.zeros(lab.size),
            "couple_watch",
        )

    n = n_x + n_z
    if rows_i:
        mat = sp.csr_array(
            (np.concatenate(vals), (np.concatenate(rows_i), np.concatenate(cols_j))),
            shape=(n_rows, n),
        )
        mat.sum_duplicates()
        b = np.concatenate(rhs)
    else:
        mat = sp.csr_array((0, n))
        b = np.zeros(0)
    size = {
        "variables": int(n),
        "binaries": int(n),
        "aux": int(n_z),
        "constraints": int(n_rows),
        "nonzeros": int(mat.nnz),
        "agents": int(graph.n_agents),
        "tasks": int(graph.n_tasks),
        "fires": int(fire.sum()),
        "pairs": int(pa.size),
    }
    return MilpModel(
        c=c.astype(np.float64),
        A_ub=mat,
        b_ub=b,
        integrality=np.ones(n, dtype=np.int8),
        var_agent=var_agent,
        var_task=var_task,
        var_slot=var_slot,
        var_kind=var_kind,
        row_kind=tuple(fam),
        agent_ids=graph.agent_ids,
        task_ids=graph.task_ids,
        params=p,
        size=size,
    )


# ---------------------------------------------------------------------------------------- decode
def decode_plan(model: MilpModel, x: np.ndarray, graph: TaskGraph, stats=None) -> Plan:
    """Turn a solution vector into a :class:`Plan`.

    Routes list each agent's chosen tasks in slot order; agents with nothing chosen are not
    mentioned (they keep their current route). Agents with a camera fly at ``watch_altitude``
    when their route starts with a fire task and at ``search_altitude`` otherwise (clipped to
    their bounds), as greedy does.

    Parameters
    ----------
    model : MilpModel
    x : ndarray, (n,)
        A solution (values are rounded).
    graph : TaskGraph
        The graph the model was built for.
    stats : SolveStats, optional
        Attached to the plan.
    """
    x = np.asarray(x, dtype=np.float64)
    chosen = np.flatnonzero((x > 0.5) & (model.var_kind != AUX))
    chosen = chosen[np.lexsort((model.var_slot[chosen], model.var_agent[chosen]))]
    agents = model.var_agent[chosen]
    tasks = model.var_task[chosen]
    p = model.params
    routes: dict[str, tuple[str, ...]] = {}
    alts: dict[str, float] = {}
    for a in np.unique(agents):
        ks = tasks[agents == a]
        aid = graph.agent_ids[a]
        routes[aid] = tuple(graph.task_ids[k] for k in ks)
        if graph.agent_can_sense[a]:
            z = p.watch_altitude if graph.task_kind[ks[0]] == TaskKind.FIRE else p.search_altitude
            alts[aid] = graph.clip_altitude(a, z)
    return Plan(routes=routes, altitudes=alts, stats=stats)


# ---------------------------------------------------------------------------------------- brute force
def brute_force_optimum(
    model: MilpModel, max_combinations: int = 2_000_000, chunk: int = 65_536
) -> tuple[np.ndarray, float]:
    """Exact optimum of a tiny model by enumeration (ground truth for tests).

    Every agent picks, in each slot, one of its variables of that slot or nothing; all such
    combinations are enumerated (vectorised, in chunks) and checked against every row. The
    auxiliary ``z`` variables have positive objective coefficients and appear only with
    coefficient +1 in rows of their own (at most one ``z`` per row), so for fixed primary
    variables the best ``z`` is 1 exactly when each of its rows has slack >= 1: it is set that way.

    Parameters
    ----------
    model : MilpModel
    max_combinations : int
        Refuse (``ValueError``) models with more combinations than this.
    chunk : int
        Combinations checked per numpy batch.

    Returns
    -------
    x : ndarray, (n,) float64
        An optimal solution (the first in enumeration order among ties).
    objective : float
    """
    n = model.n_vars
    aux = model.var_kind == AUX
    prim = np.flatnonzero(~aux)
    auxi = np.flatnonzero(aux)
    if np.any(model.c[auxi] < 0):
        raise ValueError("auxiliary variables must have non-negative objective coefficients")
    mat = model.A_ub.tocsc()
    a_p = mat[:, prim].toarray()
    a_z = mat[:, auxi].toarray()
    if np.any((a_z != 0) & (a_z != 1)) or np.any((a_z != 0).sum(axis=1) > 1):
        raise ValueError("auxiliary variables must appear with +1, at most one per row")
    groups = [
        np.flatnonzero((model.var_agent[prim] == a) & (model.var_slot[prim] == s))
        for a, s in sorted(
            set(zip(model.var_agent[prim].tolist(), model.var_slot[prim].tolist(), strict=True))
        )
    ]
    total = int(np.prod([g.size + 1 for g in groups], dtype=np.float64)) if groups else 1
    if total > max_combinations:
        raise ValueError(f"{total} combinations exceed max_combinations={max_combinations}")
    choice_lists = [np.r_[-1, g] for g in groups]  # -1: nothing in that slot
    c_p, c_z = model.c[prim], model.c[auxi]
    best_val, best_x = -np.inf, None
    combos = itertools.product(*choice_lists)
    while True:
        block = np.array(list(itertools.islice(combos, chunk)), dtype=np.int64)
        if block.size == 0:
            break
        block = block.reshape(-1, len(groups))
        xs = np.zeros((block.shape[0], prim.size))
        r, col = np.nonzero(block >= 0)
        xs[r, block[r, col]] = 1.0
        slack = model.b_ub[None, :] - xs @ a_p.T  # (N, m)
        feas = np.all(slack >= -1e-9, axis=1)
        if auxi.size:
            # z can be 1 iff every row holding it keeps slack >= 1
            rows_with = a_z.T != 0  # (n_z, m)
            zok = np.all(
                np.where(rows_with[None, :, :], slack[:, None, :] >= 1 - 1e-9, True), axis=2
            )
            zs_ = zok & (c_z[None, :] > 0)
        else:
            zs_ = np.zeros((block.shape[0], 0), dtype=bool)
        val = xs @ c_p + zs_ @ c_z
        val = np.where(feas, val, -np.inf)
        i = int(np.argmax(val))
        if val[i] > best_val + 1e-12:
            best_val = float(val[i])
            best_x = np.zeros(n)
            best_x[prim] = xs[i]
            best_x[auxi] = zs_[i]
    if best_x is None:  # pragma: no cover - the all-zero vector is always feasible
        raise ValueError("no feasible combination")
    return best_x, best_val


# ------------------------------------------------------------------------------- scheduler base
class MilpSchedulerBase:
    """What both MILP schedulers share: settings, model building and plan decoding.

    Subclasses set ``name`` and ``default_time_limit`` and implement :meth:`_solve` (one backend).

    Parameters
    ----------
    time_limit : float, optional
        Seconds per replan when the caller gives no limit (a given ``time_limit`` overrides it);
        ``default_time_limit`` if omitted.
    seed : int
        The backend's random seed (single worker / thread, so results are deterministic).
    **model_settings
        Fields of :class:`MilpParams` (``slots``, ``fresh_s``, ``tau_s``, ``slot_delay_s``,
        ``search_weight``, ``watch_weight``, ``fire_candidates``, ``search_candidates``,
        ``watch_altitude``, ``search_altitude`` ...).
    """

    name = "milp-base"
    default_time_limit = 0.2

    def __init__(self, time_limit: float | None = None, seed: int = 0, **model_settings) -> None:
        self.time_limit = float(self.default_time_limit if time_limit is None else time_limit)
        self.seed = int(seed)
        self.params = MilpParams(**model_settings)

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng=None) -> Plan:
        """Build the model of ``graph``, solve it with the backend and decode the plan.

        Raises
        ------
        RuntimeError
            If the backend returns no solution within the limit.
        """
        t0 = time.perf_counter()
        limit = self.time_limit if time_limit is None else float(time_limit)
        model = build_milp_model(graph, self.params)
        remaining = max(limit - (time.perf_counter() - t0), 1e-4)
        x, stats = self._solve(model, time_limit=remaining, seed=self.seed)
        return decode_plan(model, x, graph, stats)

    def _solve(self, model: MilpModel, *, time_limit: float, seed: int):  # pragma: no cover
        raise NotImplementedError


# -------------------------------------------------------------------------------- plan scoring
def plan_objective(
    graph: TaskGraph, plan: Plan, params: MilpParams | None = None
) -> tuple[float, bool]:
    """Score any scheduler's plan on this MILP's objective (for cross-scheduler comparisons).

    The model is built without candidate pruning (every task is a candidate), each agent's first
    ``slots`` route entries become the matching variables (``DUMP`` for agents with water on
    fires, ``WATCH`` for camera agents on fires, ``SEARCH`` on blocks), and each coupling variable
    is set to 1 exactly when its rows allow it (the best choice, its coefficient being positive).
    Route entries with no variable (beyond the conservative battery rows' pre-filter) add nothing.

    Returns
    -------
    objective : float
        ``c @ x`` of the encoded plan.
    feasible : bool
        Whether the encoded plan satisfies every row of the model (a plan may break rows that
        only this model imposes, e.g. the search spread rows; its gap to the MILP bound is then
        not meaningful).

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> from fcplan.scheduling import make_scheduler
    >>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
    >>> obj, ok = plan_objective(g, make_scheduler("milp").plan(g, time_limit=5.0, rng=None))
    >>> bool(np.isclose(obj, make_scheduler("milp").plan(g, time_limit=5.0, rng=None).stats.objective))
    True
    """
    p = params or MilpParams()
    p = MilpParams(
        **{**_asdict(p), "fire_candidates": graph.n_tasks, "search_candidates": graph.n_tasks}
    )
    model = build_milp_model(graph, p)
    x = np.zeros(model.n_vars)
    lookup = {
        (int(a), int(k), int(s)): i
        for i, (a, k, s) in enumerate(
            zip(model.var_agent, model.var_task, model.var_slot, strict=True)
        )
        if model.var_kind[i] != AUX
    }
    for agent, route in plan.routes.items():
        a = graph.agent_index[agent]
        for s, task in enumerate(route[: p.slots]):
            i = lookup.get((a, graph.task_index[task], s))
            if i is not None:
                x[i] = 1.0
    aux = np.flatnonzero(model.var_kind == AUX)
    x[aux] = 1.0
    slack = model.b_ub - model.A_ub @ x
    bad_rows = np.flatnonzero(slack < -1e-9)
    if bad_rows.size and aux.size:
        rows_aux = model.A_ub[bad_rows][:, aux]
        x[aux[np.unique(rows_aux.nonzero()[1])]] = 0.0
    feasible = bool(np.all(model.A_ub @ x <= model.b_ub + 1e-9))
    return float(model.c @ x), feasible


def _asdict(p: MilpParams) -> dict:
    return {f: getattr(p, f) for f in p.__dataclass_fields__}
