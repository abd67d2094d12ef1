"""The task graph: what there is to do, built from the team's belief at a replan tick.

Node kinds:

* ``agent``: every UAV, with its role, position, altitude, speed, remaining range and tank;
* ``depot``: where agents recharge and refill;
* ``fire``: a *dump-sized* cluster of known burning cells. Known cells are binned into tiles no
  larger than an action agent's field of view, so one dump at the task's position can reach every
  cell of the task. Attributes: centroid position, cell count, staleness (seconds since any of its
  cells was last sensed), threat (penalty-weighted closeness to facilities), the connected fire
  (``cluster``) it belongs to;
* ``search``: a grid block (100 px by default) to (re)explore, valued by how long ago the team's
  cameras last covered it, more when known fire is near;
* ``facility``: houses, hospitals, power stations and the depot footprint, with their penalties.

Edges: ``requires`` (fire -> the search block containing it: putting a fire out needs it sensed,
so that block must be kept fresh), ``threatens`` (fire -> facility within ``threat_radius_px``,
with an estimated time to reach it from the fastest spread rate of the scenario's fuel), and
``can_do`` (agent -> task its role can serve, with travel time).

Solvers should use the numpy views (``agent_*``, ``task_*``, :attr:`TaskGraph.agent_task_distance`,
:attr:`TaskGraph.task_distance`) and the feasibility rule (:attr:`TaskGraph.reachable`,
:attr:`TaskGraph.agent_budget_px` ..., see :mod:`fcplan.taskgraph.types`); the networkx view
(:attr:`TaskGraph.graph`) is built on first use, for inspection, drawing and teaching.

Modules: :mod:`~fcplan.taskgraph.types` (the graph, its views and settings),
:mod:`~fcplan.taskgraph.build` (:class:`TaskGraphBuilder`: one per episode),
:mod:`~fcplan.taskgraph.clusters` (connected fires), :mod:`~fcplan.taskgraph.synthetic`
(random graphs without a simulation).

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.belief import Belief
>>> from fcplan.taskgraph import TaskGraphBuilder
>>> world = World().reset(load_scenario(1), seed=0)
>>> g = TaskGraphBuilder(world.scenario).build(world.team, Belief(world.scenario))
>>> sorted({d["kind"] for _, d in g.graph.nodes(data=True)})
['agent', 'depot', 'facility', 'search']
>>> bool(g.reachable[:, g.search_tasks].any())  # some agent can go searching
True
"""

from fcplan.taskgraph.build import TaskGraphBuilder, build_task_graph, default_tile
from fcplan.taskgraph.synthetic import synthetic_task_graph
from fcplan.taskgraph.types import (
    FEASIBILITY_TOL_PX,
    SharedMemo,
    TaskGraph,
    TaskGraphParams,
    TaskKind,
    grid_block_name,
)

__all__ = [
    "FEASIBILITY_TOL_PX",
    "SharedMemo",
    "TaskKind",
    "TaskGraph",
    "TaskGraphBuilder",
    "TaskGraphParams",
    "build_task_graph",
    "default_tile",
    "grid_block_name",
    "synthetic_task_graph",
]
