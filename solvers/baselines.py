"""Lower baselines: ``idle`` does nothing, ``random`` sends each agent to a random task.

``idle`` takes no settings; ``random`` takes ``keep_probability``, a number in [0, 1] checked at
construction (a wrong type or NaN is a one-line :class:`fcplan.settings.SettingError`). Neither
depends on the wall clock: ``random`` draws from the episode's controller stream only.

Examples
--------
>>> from fcplan import run_episode
>>> run_episode("practice", "idle", seed=0).metrics["manual"].overall_firefighting
0.0
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats, float_setting
from fcplan.taskgraph import TaskGraph
from fcplan.team import Mode

__all__ = ["IdleScheduler", "RandomScheduler"]


class IdleScheduler:
    """Never moves anyone: the score of doing nothing."""

    name = "idle"
    deterministic = True

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Return the empty plan."""
        return Plan(stats=SolveStats(status="heuristic", objective=0.0))


class RandomScheduler:
    """Each agent that is not on its way home gets one random task its role and battery allow,
    and perception agents a random altitude.

    Parameters
    ----------
    keep_probability : float
        Chance that an agent with a route keeps it at a replan (so agents finish some trips).
    """

    name = "random"
    deterministic = True

    def __init__(self, keep_probability: float = 0.5) -> None:
        self.keep_probability = float_setting("keep_probability", keep_probability, 0.0, 1.0)

    def plan(
        self, graph: TaskGraph, *, time_limit: float | None = None, rng: np.random.Generator
    ) -> Plan:
        """Draw a random feasible route of one task per free agent."""
        feasible = graph.reachable
        routes, alts = {}, {}
        for i, agent in enumerate(graph.agent_ids):
            if graph.agent_mode[i] == Mode.HOMING:
                continue
            if graph.agent_mode[i] == Mode.ACTIVE and rng.random() < self.keep_probability:
                continue
            options = np.flatnonzero(feasible[i])
            if options.size == 0:
                continue
            routes[agent] = (graph.task_ids[int(rng.choice(options))],)
            if graph.agent_can_sense[i]:
                lo, hi = graph.agent_alt_range[i]
                alts[agent] = float(rng.uniform(lo, hi))
        return Plan(routes=routes, altitudes=alts, stats=SolveStats(status="heuristic"))
