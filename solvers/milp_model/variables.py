"""The model's variables: which ``x[a, k, s]`` exist (kinds, the battery pre-filter and the
candidate pruning of :mod:`solvers.milp_model`), and the coupling variables ``z[k, s]``.

Battery terms are whole px, rounded up, and the range
(:attr:`fcplan.taskgraph.TaskGraph.agent_budget_px`) rounded down. Auxiliary ``z[k, s]`` exist
for the fires with a dump candidate in slot ``s``: stale ones (their dump is worth its value only
when sensed) and, with ``support_weight > 0``, fresh ones (the bonus for a watcher).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode
from solvers.milp_model.types import DUMP, SEARCH, WATCH, MilpParams

__all__ = ["Variables", "model_variables"]


@dataclass(frozen=True, eq=False)
class Variables:
    """The variables of one model: ``n_x`` primary ``x[a, k, s]`` ordered by (agent, slot,
    task), then ``n_z`` auxiliary ``z[k, s]``, with what the objective and the rows need."""

    va: np.ndarray  # (n_x,) agent row of each x
    vk: np.ndarray  # (n_x,) task row of each x
    vs: np.ndarray  # (n_x,) slot of each x
    vkind: np.ndarray  # (n_x,) int8 DUMP / WATCH / SEARCH
    zk: np.ndarray  # (n_z,) task row of each z
    zs: np.ndarray  # (n_z,) slot of each z
    fire: np.ndarray  # (K,) bool fire task
    stale: np.ndarray  # (K,) bool stale fire task (staleness > fresh_s)
    tank: np.ndarray  # (A,) dumps left (a full tank on a forced return)
    eta0: np.ndarray  # (A, K) s from each agent's start to each task
    first_leg: np.ndarray  # (A, K) whole px: start -> task -> home
    later_leg: np.ndarray  # (A, K) whole px: home -> task -> home
    rng_px: np.ndarray  # (A,) whole px of range
    n_pairs: int  # (agent, task) pairs kept

    @property
    def n_x(self) -> int:
        """Number of primary variables."""
        return int(self.va.size)

    @property
    def n_z(self) -> int:
        """Number of auxiliary variables."""
        return int(self.zk.size)


def model_variables(graph: TaskGraph, p: MilpParams) -> Variables:
    """The variables of the model of ``graph`` (see the module docstring)."""
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
    keep = _candidates(graph, p, fire, ok0 | ok_later, eta0)

    # ---- primary variables, ordered by (agent, slot, task)
    pa, pk = np.nonzero(keep)  # row-major: agent, then task
    slot_ok = np.stack([ok0[pa, pk]] + [ok_later[pa, pk]] * (n_slots - 1), axis=0)  # (n_slots, P)
    ss, pp = np.nonzero(slot_ok)
    va, vk, vs = pa[pp], pk[pp], ss
    order = np.lexsort((vk, vs, va))
    va, vk, vs = va[order], vk[order], vs[order]
    vkind = kind[va, vk]

    # ---- auxiliary z[k, s] for fires with a dump candidate in slot s: stale fires (their dump is
    # worth v_k only when sensed) and, with support_weight > 0, fresh ones (bonus for a watcher)
    stale = (graph.task_staleness > p.fresh_s) & fire
    stale_dump = (vkind == DUMP) & stale[vk]
    zsel = stale_dump | ((vkind == DUMP) & (p.support_weight > 0))
    zkey = np.unique(vk[zsel] * n_slots + vs[zsel])
    return Variables(
        va=va, vk=vk, vs=vs, vkind=vkind, zk=zkey // n_slots, zs=zkey % n_slots,
        fire=fire, stale=stale, tank=tank, eta0=eta0, first_leg=first_leg,
        later_leg=later_leg, rng_px=rng_px, n_pairs=int(pa.size),
    )  # fmt: skip


def _candidates(
    graph: TaskGraph, p: MilpParams, fire: np.ndarray, feasible: np.ndarray, eta0: np.ndarray
) -> np.ndarray:
    """(A, K) bool: per agent its ``fire_candidates`` best fire tasks and ``search_candidates``
    best search blocks among the ``feasible`` ones, by slot-0 discounted value."""
    value = graph.task_value.astype(np.float64)
    score = value[None, :] / (1.0 + eta0 / p.tau_s)
    keep = np.zeros_like(feasible)
    for cat_mask, n_keep in ((fire, p.fire_candidates), (~fire, p.search_candidates)):
        cand = feasible & cat_mask[None, :]
        if n_keep <= 0 or not cand.any():
            continue
        s = np.where(cand, score, -np.inf)
        order = np.argsort(-s, axis=1, kind="stable")[:, :n_keep]
        rows = np.arange(graph.n_agents)[:, None]
        keep[rows, order] |= np.isfinite(s[rows, order])
    return keep
