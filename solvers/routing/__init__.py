"""Routing schedulers (``routing``, ``routing-pyvrp``) and the routing core they share.

Each replan builds and solves up to two models, first the **action** model, then the
**perception** model:

* **Vehicles** are the available agents of the role (not ``HOMING``). A vehicle starts where the
  agent is, or at its depot slot with a full battery if the agent is on a forced return (it
  recharges first, see :attr:`fcplan.taskgraph.TaskGraph.agent_start_pos`), and ends at its depot
  slot.
* **Nodes** are the tasks that role can serve: fire tasks for action agents; search blocks *and*
  fire tasks for perception agents. Hybrids (camera and water) that still have water are action
  vehicles (fires only, flown at their dump altitude, as in every built-in scheduler); hybrids
  with an empty tank are perception vehicles.
* **Visits are optional** (prize collecting): leaving task ``k`` unvisited costs a drop penalty
  equal to its value converted to pixels. Each task is visited at most once per model.

Each model is a prize-collecting vehicle routing problem on a distance matrix,
:func:`solve_routes` (the **core**, :mod:`solvers.routing.core`): travel plus the prizes of the
tasks left out is minimised, within each vehicle's battery and visit limits. Two backends search
it: OR-Tools (:mod:`~solvers.routing.ortools_backend`, the ``routing`` scheduler) and PyVRP
(:mod:`~solvers.routing.pyvrp_backend`, the ``routing-pyvrp`` scheduler). The scheduler
(:mod:`~solvers.routing.scheduler`) turns the task graph into the models (task values, candidate
tasks, time split, warm start from its last plan) and the routes into a plan;
:mod:`~solvers.routing.tsplib` reads TSPLIB instances to check the core against known optima.

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0))
>>> plan = RoutingScheduler(deterministic=True).plan(g, time_limit=None, rng=None)
>>> plan.stats.status, plan.stats.size["vehicles"]
('feasible', 4)
>>> plan = PyVRPRoutingScheduler(deterministic=True).plan(g, time_limit=None, rng=None)
>>> plan.stats.status, plan.stats.size["vehicles"]
('feasible', 4)

The core on a plain distance matrix (a 4-city tour from city 0, every city required):

>>> xy = np.array([[0, 0], [0, 10], [10, 10], [10, 0]], dtype=float)
>>> dist = np.linalg.norm(xy[:, None] - xy[None], axis=2)
>>> res = solve_routes(dist, starts=[0], deterministic=True, backend="pyvrp")
>>> res.objective, sorted(res.routes[0])
(40.0, [1, 2, 3])
"""

from solvers.routing.core import BACKENDS, RoutesResult, RoutingFailedError
from solvers.routing.ortools_backend import OrToolsOptions
from solvers.routing.pyvrp_backend import PyVRPOptions
from solvers.routing.scheduler import PyVRPRoutingScheduler, RoutingScheduler
from solvers.routing.solve import solve_routes

__all__ = [
    "BACKENDS",
    "OrToolsOptions",
    "PyVRPOptions",
    "PyVRPRoutingScheduler",
    "RoutesResult",
    "RoutingFailedError",
    "RoutingScheduler",
    "solve_routes",
]
