"""Building the assignment model of a task graph: variables, objective and rows put together."""

from __future__ import annotations

import numpy as np

from fcplan.taskgraph import TaskGraph
from solvers.milp_model.constraints import model_rows
from solvers.milp_model.objective import objective_coefficients
from solvers.milp_model.types import AUX, MilpModel, MilpParams
from solvers.milp_model.variables import model_variables

__all__ = ["build_milp_model"]


def build_milp_model(graph: TaskGraph, params: MilpParams | None = None) -> MilpModel:
    """Build the assignment MILP of ``graph`` (see :mod:`solvers.milp_model`).

    Parameters
    ----------
    graph : TaskGraph
    params : MilpParams, optional

    Returns
    -------
    MilpModel
    """
    p = params or MilpParams()
    v = model_variables(graph, p)
    c = objective_coefficients(graph, p, v)
    mat, b, families = model_rows(graph, p, v)
    n_x, n_z = v.n_x, v.n_z
    n = n_x + n_z
    size = {
        "variables": int(n),
        "binaries": int(n),
        "aux": int(n_z),
        "constraints": int(b.size),
        "nonzeros": int(mat.nnz),
        "agents": int(graph.n_agents),
        "tasks": int(graph.n_tasks),
        "fires": int(v.fire.sum()),
        "pairs": v.n_pairs,
    }
    return MilpModel(
        c=c.astype(np.float64),
        A_ub=mat,
        b_ub=b,
        integrality=np.ones(n, dtype=np.int8),
        var_agent=np.r_[v.va, np.full(n_z, -1)].astype(np.int64),
        var_task=np.r_[v.vk, v.zk].astype(np.int64),
        var_slot=np.r_[v.vs, v.zs].astype(np.int64),
        var_kind=np.r_[v.vkind, np.full(n_z, AUX)].astype(np.int8),
        row_kind=families,
        agent_ids=graph.agent_ids,
        task_ids=graph.task_ids,
        params=p,
        size=size,
    )
