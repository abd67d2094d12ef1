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
auction: bundle construction, consensus, the stopping rule), :mod:`~solvers.cbba.assembly`
(conflict-free routes; greedy completion of an auction cut short), :mod:`~solvers.cbba.clock`
(the wall-clock limit), :mod:`~solvers.cbba.scheduler` (the two auctions, their scores, the
modes, the plan, and its settings, checked by :mod:`fcplan.settings` as every scheduler's are)
and :mod:`~solvers.cbba.static` (the same auction on a static textbook instance, checked against an
independent implementation in ``tests/solvers/test_cbba_reference.py``).

Modes: with a ``time_limit`` (argument or setting) the scheduler stops on the wall clock and
returns within the limit, but for its floor (setting up the auctions and completing a cut
auction's empty bidders with one item each, :mod:`~solvers.cbba.clock`);
``deterministic=True`` never reads the clock and stops on ``max_rounds`` only, so plans are the
same in any process and under any load (use it for comparisons).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.cbba import CBBAScheduler
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0), comm_range=400.0)
>>> plan = CBBAScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
>>> plan.stats.size["converged"], plan.stats.size["rounds"] > 0
(True, True)
>>> fixed = CBBAScheduler(deterministic=True, max_rounds=3)
>>> fixed.plan(g, time_limit=1e-9, rng=None).routes == fixed.plan(g, time_limit=None, rng=None).routes
True
"""

from fcplan.settings import SettingError
from solvers.cbba.auction import StageResult
from solvers.cbba.comms import CommGraph, communication_graph
from solvers.cbba.scheduler import CBBAResult, CBBAScheduler
from solvers.cbba.static import StaticInstance, StaticResult, solve_static

#: The error of a bad CBBA setting: :class:`fcplan.settings.SettingError`, the one every
#: scheduler's settings raise (this name is kept for code that caught it by name).
CBBASettingsError = SettingError

__all__ = [
    "CBBAScheduler",
    "CBBAResult",
    "CBBASettingsError",
    "CommGraph",
    "StageResult",
    "StaticInstance",
    "StaticResult",
    "communication_graph",
    "solve_static",
]
