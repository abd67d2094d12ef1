"""The ``oracle`` reference: a clairvoyant planner, an upper reference and **not a legal policy**.

A real team knows only what its cameras have seen. The oracle is told the true fire: its task
graphs are built from the team's belief plus every cell that is burning now, sensed or not
(:class:`fcplan.belief.ClairvoyantBelief`, chosen by :meth:`fcplan.mission.Mission.replan` for
any scheduler whose ``clairvoyant`` attribute is true). Everything else stays the world's: the
team's sensing state (a fire nobody has sensed is a task that has never been seen, and the world
still prunes only cells the team has sensed), batteries, tanks, speeds, the replan rule. On those
graphs it plans with an inner scheduler (``inner``, default ``greedy``; any registered name and
its settings: ``oracle:inner=milp``).

**Looking where the fire is.** Knowing the fire is worth most to the perception agents: a fire
nobody has sensed cannot be put out, and finding it is the searchers' job. By default
(``look_for_fire``) the oracle therefore revalues the search blocks before its inner scheduler
plans: every block holding a fire task nobody has ever sensed (its staleness exceeds the
episode's age) is worth more than any other block, by the value of the unsensed fire in it, so the
searchers fly to the unsensed fire first, and the blocks' staleness ranks the rest as before.
Fire tasks and every other value are left alone. Measured on fcplan-bench-v2's hard-03, hard-04,
hard-07, hard-09 and hard-12 over seeds 100-103 (screening seeds, not the benchmark's): mean final
score 185.0 without it, 200.7 with it (greedy 176.3); it gained on 14 of the 20 pairs
(``bench/README.md``, "The oracle looks for fire"). ``look_for_fire=false`` keeps the former
behaviour, to reproduce results made with it.

What it is for: a reference of what was achievable on the same (scenario, seed), so that a study
can report each scheduler's score as a fraction of the oracle's. Its results are labelled with
the name ``oracle`` (or ``oracle[inner]``); no comparison should rank it among the policies.

Settings
--------
``inner`` (str, default ``"greedy"``)
    The registered scheduler that plans on the clairvoyant graphs.
``look_for_fire`` (bool, default true)
    Revalue the search blocks over unsensed fire before planning (above).
other keywords
    Passed to the inner scheduler's factory.

Examples
--------
>>> from fcplan import make_scheduler, run_episode
>>> run_episode("practice", "oracle", seed=0).scheduler
'oracle'
>>> make_scheduler("oracle:inner=routing:deterministic=true").name
'oracle[routing]'

A greedy oracle is a reference, not a bound. It beats greedy on #24 seeds 0-2 (by 17.7-55.3
points) and on the mean of fcplan-bench-v2's hard tier (148.5 against 135.4 over 120 pairs,
``docs/leaderboard.md``), but not everywhere: on that tier's hard-04, hard-06, hard-11 and
hard-12 greedy scores higher on the mean (hard-04: 215.5 against 182.6), the oracle's action
agents leaving more sensed fire unpruned late in the episode. The leaderboard takes, per
(scenario, seed), the best of the oracle variants run.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from fcplan import Plan, make_scheduler
from fcplan.errors import FcplanError
from fcplan.scheduling import bool_setting
from fcplan.taskgraph import TaskGraph

__all__ = ["OracleScheduler", "look_for_fire"]


def look_for_fire(graph: TaskGraph) -> TaskGraph:
    """``graph`` with every search block that holds unsensed fire worth more than any other block.

    A fire task is *unsensed* when nobody has ever sensed a cell of it (its staleness exceeds the
    graph's time: only a clairvoyant graph has such tasks). Each one belongs to the search block
    whose centre is nearest to it; a block holding some gets the largest search value of the
    graph plus the value of its unsensed fire. Every other value is unchanged; a graph without
    unsensed fire is returned as it is.

    Examples
    --------
    >>> from fcplan.mission import Mission
    >>> mission = Mission(1, seed=0)
    >>> _ = mission.advance(100)
    >>> g = mission.task_graph(clairvoyant=True)
    >>> seen = look_for_fire(g)
    >>> blocks = g.search_tasks
    >>> up = seen.task_value[blocks] > g.task_value[blocks]
    >>> bool(up.any()), bool(seen.task_value[blocks][up].min() > g.task_value[blocks].max())
    (True, True)
    """
    fires, blocks = graph.fire_tasks, graph.search_tasks
    if fires.size == 0 or blocks.size == 0:
        return graph
    unsensed = fires[graph.task_staleness[fires] > graph.time_s]
    if unsensed.size == 0:
        return graph
    _, home = cKDTree(graph.task_pos[blocks]).query(graph.task_pos[unsensed])
    add = np.bincount(home, weights=graph.task_value[unsensed], minlength=blocks.size)
    value = graph.task_value.copy()
    top = value[blocks].max()
    value[blocks] = np.where(add > 0, top + add, value[blocks])
    return dataclasses.replace(graph, task_value=value)


class OracleScheduler:
    """Plans with ``inner`` on graphs that know the true fire (module docstring).

    Parameters
    ----------
    inner : str
        A registered scheduler name (not ``oracle``).
    look_for_fire : bool
        Revalue the search blocks over unsensed fire before planning (:func:`look_for_fire`).
    **settings
        The inner scheduler's settings.
    """

    #: tells the mission to build this scheduler's graphs from the true fire
    clairvoyant = True

    def __init__(self, inner: str = "greedy", look_for_fire: bool = True, **settings: Any) -> None:
        if not isinstance(inner, str) or inner.partition(":")[0] == "oracle":
            raise FcplanError(f"oracle: inner must name another scheduler (got {inner!r})")
        self.look_for_fire = bool_setting("look_for_fire", look_for_fire)
        self.inner = make_scheduler(inner, **settings)
        self.name = "oracle" if inner == "greedy" and not settings else f"oracle[{inner}]"

    @property
    def deterministic(self) -> bool:
        """Whether the inner scheduler's plans are independent of the clock (its own flag)."""
        return getattr(self.inner, "deterministic", False) is True

    @property
    def time_limit(self) -> float | None:
        """The inner scheduler's default limit (seconds per call; None: none)."""
        limit = getattr(self.inner, "time_limit", None)
        return limit if isinstance(limit, (int, float)) else None

    def plan(
        self, graph: TaskGraph, *, time_limit: float | None = None, rng: np.random.Generator
    ) -> Plan:
        """The inner scheduler's plan on the clairvoyant ``graph`` (within ``time_limit``, as
        the inner scheduler honours it)."""
        if self.look_for_fire:
            graph = look_for_fire(graph)
        return self.inner.plan(graph, time_limit=time_limit, rng=rng)
