"""
Each replan builds and solves (with OR-Tools' routing library, ``pywrapcp.RoutingModel``) up to two
models, first the **action** model, then the **perception** model:

* **Vehicles** are the available agents of the role (not ``HOMING``). A vehicle starts where the
  agent is, or at its depot slot with a full battery if the agent is on a forced return (it
  recharges first, see :attr:`fcplan.taskgraph.TaskGraph.agent_start_pos`), and ends at its depot
  slot.
* **Nodes** are the tasks that role can serve: fire tasks for action agents; search blocks *and*
  fire tasks for perception agents. Hybrids (camera and water) that still have water are action
  vehicles (fires only, no altitude is set for them, as in ``greedy``); hybrids with an empty
  tank are perception vehicles.
* **Visits are optional** (prize collecting): leaving task ``k`` unvisited costs a drop penalty
  equal to its value converted to pixels (below). Each task is visited at most once per model.

Each model is a prize-collecting vehicle routing problem on plain arrays
(:func:`~solvers.routing.model.solve_routes`): travel plus the drop penalties of the tasks left
out is minimised, within each vehicle's battery and visit limits.

Modules: :mod:`~solvers.routing.model` (the model on plain arrays and its solution),
:mod:`~solvers.routing.search` (how OR-Tools searches it), :mod:`~solvers.routing.scheduler`
(:class:`RoutingScheduler`: task values, candidate nodes, time split and the plan).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0))
>>> plan = RoutingScheduler(deterministic=True).plan(g, time_limit=None, rng=None)
>>> plan.stats.status in ("feasible", "time_limit"), plan.stats.size["vehicles"]
(True, 4)

:func:`solve_routes` is the model on plain arrays (one vehicle from (0, 0) to its depot slot at
(0, 10), two mandatory stops):

>>> sol = solve_routes(
...     start=np.array([[0.0, 0.0]]), end=np.array([[0.0, 10.0]]),
...     nodes=np.array([[10.0, 10.0], [10.0, 0.0]]), penalty=np.full(2, np.inf),
...     budget=np.array([100.0]), charge_return=True, deterministic=True)
>>> sol.routes, round(sol.travel_px, 3)
(((1, 0),), 30.0)
"""

from solvers.routing.model import RouteSolution, RoutingFailedError, solve_routes
from solvers.routing.scheduler import RoutingScheduler

__all__ = ["RoutingScheduler", "RouteSolution", "RoutingFailedError", "solve_routes"]
