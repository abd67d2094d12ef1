"""Many worlds' graphs planned in one call: the ``BatchScheduler`` protocol and
:func:`solve_batch`.

A batched env (:mod:`fcplan.env.vector_task`, :mod:`fcplan.env.vector_expert`) replans many
worlds at the same tick, each on its own :class:`fcplan.taskgraph.TaskGraph`. A scheduler that
can plan several independent graphs together offers, besides :meth:`plan`::

    class BatchScheduler(Scheduler, Protocol):
        def plan_batch(self, graphs, *, time_limit, rngs) -> list[Plan]: ...

with ``plan_batch(graphs, ...)[i]`` the plan ``plan(graphs[i], ...)`` would make, and no state
carried from one graph to another (greedy does: :mod:`solvers.greedy_batch`). One instance then
plans every world. :func:`solve_batch` calls it once and settles each world's plan by the rule
of :func:`fcplan.scheduling.solve` (:func:`fcplan.scheduling.settle`: validation, time-outs and
the greedy fallback, per world); the call's solver time is shared equally by the worlds in
their stats (``solver_s``; ``wall_time_s`` adds the world's own settling). If ``plan_batch`` raises, every world is solved on its own. A scheduler without
``plan_batch``, or one instance per world, is called world by world through ``solve``.

Examples
--------
>>> import numpy as np
>>> from fcplan.scheduling import make_scheduler
>>> from fcplan.taskgraph import synthetic_task_graph
>>> graphs = [synthetic_task_graph(4, 9, np.random.default_rng(s)) for s in range(3)]
>>> rngs = [np.random.default_rng(s) for s in range(3)]
>>> plans = solve_batch(make_scheduler("greedy"), graphs, time_limit=None, rngs=rngs)
>>> [p.stats.status for p in plans]
['heuristic', 'heuristic', 'heuristic']
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Protocol, runtime_checkable

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import Scheduler, settle, solve
from fcplan.taskgraph import TaskGraph

__all__ = ["BatchScheduler", "batch_capable", "instances", "solve_batch"]


@runtime_checkable
class BatchScheduler(Scheduler, Protocol):
    """A scheduler that also plans several independent graphs in one call (module docstring)."""

    def plan_batch(
        self,
        graphs: Sequence[TaskGraph],
        *,
        time_limit: float | None,
        rngs: Sequence[np.random.Generator] | None,
    ) -> list[Plan]:  # pragma: no cover - protocol
        """The plans :meth:`plan` would make of each graph (``time_limit`` per graph)."""
        ...


def batch_capable(scheduler: object) -> bool:
    """Whether one instance of ``scheduler`` plans many worlds at once (has ``plan_batch``).

    Examples
    --------
    >>> from fcplan.scheduling import make_scheduler
    >>> batch_capable(make_scheduler("greedy")), batch_capable(make_scheduler("routing"))
    (True, False)
    """
    return callable(getattr(scheduler, "plan_batch", None))


def instances(make: Callable[[], Scheduler], num: int) -> Scheduler | list[Scheduler]:
    """What plans ``num`` worlds: one instance from ``make()`` when it is :func:`batch_capable`
    (every world in one call), else ``num`` instances, one per world.

    Examples
    --------
    >>> from fcplan.scheduling import make_scheduler
    >>> instances(lambda: make_scheduler("greedy"), 3).name
    'greedy'
    >>> len(instances(lambda: make_scheduler("routing"), 3))
    3
    """
    first = make()
    return first if batch_capable(first) else [first] + [make() for _ in range(num - 1)]


def solve_batch(
    schedulers: Scheduler | Sequence[Scheduler],
    graphs: Sequence[TaskGraph],
    *,
    time_limit: float | None,
    rngs: Sequence[np.random.Generator],
) -> list[Plan]:
    """:func:`fcplan.scheduling.solve` of every graph: ``schedulers`` is one instance for all the
    worlds (batched when :func:`batch_capable`, else called on each graph in turn) or one per
    world; ``rngs[i]`` is world ``i``'s controller generator.

    Returns
    -------
    list of Plan
        Valid plans carrying :class:`fcplan.scheduling.SolveStats`, one per graph.
    """
    n = len(graphs)
    if len(rngs) != n:
        raise ValueError(f"solve_batch: {n} graphs but {len(rngs)} generators")
    if isinstance(schedulers, Sequence):
        if len(schedulers) != n:
            raise ValueError(f"solve_batch: {n} graphs but {len(schedulers)} schedulers")
        return [solve(s, g, time_limit=time_limit, rng=r)
                for s, g, r in zip(schedulers, graphs, rngs, strict=True)]  # fmt: skip
    one = schedulers
    if not (n and batch_capable(one)):
        return [
            solve(one, g, time_limit=time_limit, rng=r) for g, r in zip(graphs, rngs, strict=True)
        ]
    t0 = time.perf_counter()
    try:
        plans = list(one.plan_batch(graphs, time_limit=time_limit, rngs=rngs))  # type: ignore[attr-defined]
        if len(plans) != n:
            raise ValueError(f"plan_batch returned {len(plans)} plans for {n} graphs")
    except Exception:  # noqa: BLE001 - as solve: every world then gets its own call
        return [
            solve(one, g, time_limit=time_limit, rng=r) for g, r in zip(graphs, rngs, strict=True)
        ]
    share = (time.perf_counter() - t0) / n
    # each world's wall time: its share of the call, then its own settling
    return [settle(one, g, p, time.perf_counter() - share, share, time_limit=time_limit, rng=r)
            for g, p, r in zip(graphs, plans, rngs, strict=True)]  # fmt: skip
