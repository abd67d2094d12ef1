"""The ``oracle`` reference: a clairvoyant planner, an upper reference and **not a legal policy**.

A real team knows only what its cameras have seen. The oracle is told the true fire: its task
graphs are built from the team's belief plus every cell that is burning now, sensed or not
(:class:`fcplan.belief.ClairvoyantBelief`, chosen by :meth:`fcplan.mission.Mission.replan` for
any scheduler whose ``clairvoyant`` attribute is true). Everything else stays the world's: the
team's sensing state (a fire nobody has sensed is a task that has never been seen, and the world
still prunes only cells the team has sensed), batteries, tanks, speeds, the replan rule. On those
graphs it plans with an inner scheduler (``inner``, default ``greedy``; any registered name and
its settings: ``oracle:inner=milp``).

What it is for: a reference of what was achievable on the same (scenario, seed), so that a study
can report each scheduler's score as a fraction of the oracle's. Its results are labelled with
the name ``oracle`` (or ``oracle[inner]``); no comparison should rank it among the policies.

Settings
--------
``inner`` (str, default ``"greedy"``)
    The registered scheduler that plans on the clairvoyant graphs.
other keywords
    Passed to the inner scheduler's factory.

Examples
--------
>>> from fcplan import make_scheduler, run_episode
>>> run_episode("practice", "oracle", seed=0).scheduler
'oracle'
>>> make_scheduler("oracle:inner=routing:deterministic=true").name
'oracle[routing]'

A greedy oracle is a reference, not a bound: on most (scenario, seed) pairs it beats greedy
(on #24 seeds 0-2 by 20-39 points), but knowing more fire than the team can reach can also
distract a heuristic inner planner (one hard generated scenario and seed in nine tried: -36).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan import Plan, make_scheduler
from fcplan.errors import FcplanError
from fcplan.taskgraph import TaskGraph

__all__ = ["OracleScheduler"]


class OracleScheduler:
    """Plans with ``inner`` on graphs that know the true fire (module docstring).

    Parameters
    ----------
    inner : str
        A registered scheduler name (not ``oracle``).
    **settings
        The inner scheduler's settings.
    """

    #: tells the mission to build this scheduler's graphs from the true fire
    clairvoyant = True

    def __init__(self, inner: str = "greedy", **settings: Any) -> None:
        if not isinstance(inner, str) or inner.partition(":")[0] == "oracle":
            raise FcplanError(f"oracle: inner must name another scheduler (got {inner!r})")
        self.inner = make_scheduler(inner, **settings)
        self.name = "oracle" if inner == "greedy" and not settings else f"oracle[{inner}]"

    def plan(
        self, graph: TaskGraph, *, time_limit: float | None = None, rng: np.random.Generator
    ) -> Plan:
        """The inner scheduler's plan on the clairvoyant ``graph``."""
        return self.inner.plan(graph, time_limit=time_limit, rng=rng)
