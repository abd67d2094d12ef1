"""The model's objective coefficients (maximised): per variable, its share of the objective of
:mod:`solvers.milp_model` (travel-time discounted values of searching, watching and dumping; a
stale dump's loss and its coupling ``z``; the support bonus).
"""

from __future__ import annotations

import numpy as np

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.types import DUMP, SEARCH, WATCH, MilpParams
from solvers.milp_model.variables import Variables

__all__ = ["objective_coefficients"]


def objective_coefficients(graph: TaskGraph, p: MilpParams, v: Variables) -> np.ndarray:
    """(n_x + n_z,) objective coefficients of the variables ``v`` (module docstring)."""
    value = graph.task_value.astype(np.float64)
    va, vk, vs, vkind = v.va, v.vk, v.vs, v.vkind
    eta = v.eta0[va, vk] + vs * p.slot_delay_s
    disc = 1.0 / (1.0 + eta / p.tau_s)
    val = value[vk]
    weight = np.select(
        [vkind == SEARCH, vkind == WATCH], [p.search_weight, p.watch_weight], default=1.0
    )
    c_x = weight * val * disc
    stale_dump = (vkind == DUMP) & v.stale[vk]
    c_x = np.where(stale_dump, -val * (1.0 - disc), c_x)
    c: np.ndarray = np.r_[c_x, value[v.zk] * np.where(v.stale[v.zk], 1.0, p.support_weight)]
    return c
