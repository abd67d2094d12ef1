"""CBBA: the consensus-based bundle algorithm, run as decentralised agents with a radio range.

Choi, Brunet and How, "Consensus-Based Decentralized Auctions for Robust Task Allocation", IEEE
Transactions on Robotics 25(4), 2009. Every agent keeps its own copy of the auction state and
only talks to the agents within ``graph.comm_range`` px of it; the scheduler simulates those
agents in synchronous rounds and assembles their final bundles into a :class:`fcplan.plan.Plan`.

Two auctions run one after the other over the same communication graph, each a complete CBBA
run with fixed scores: a **dump auction** (action and hybrid agents with water bid on the fire
tasks), then a **sense auction** (the camera agents that won no dump bid on watching a fire or
covering a search block). The plan keeps one holder per (task, service).

Modules: :mod:`~solvers.cbba.comms` (who can talk to whom), :mod:`~solvers.cbba.auction` (one
auction: bundle construction and consensus), :mod:`~solvers.cbba.scheduler` (the two auctions,
their scores, and the plan).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.cbba import CBBAScheduler
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0), comm_range=400.0)
>>> plan = CBBAScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
>>> plan.stats.size["converged"], plan.stats.size["rounds"] > 0
(True, True)
"""

from solvers.cbba.auction import StageResult
from solvers.cbba.comms import CommGraph, communication_graph
from solvers.cbba.scheduler import CBBAResult, CBBAScheduler

__all__ = ["CBBAScheduler", "CBBAResult", "CommGraph", "StageResult", "communication_graph"]
