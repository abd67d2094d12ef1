"""Conformance kit for schedulers: the checks every scheduler, built-in or yours, should pass.

:func:`check_scheduler` is to fcplan what PettingZoo's ``api_test``/``seed_test`` are to an
environment: the package ships the test its users run on their own code. It takes a *factory*
(a zero-argument callable returning a fresh scheduler, e.g. ``lambda: make_scheduler("greedy")``
or the scheduler class itself) and checks, on task graphs taken from real episodes of every shipped
scenario:

==================  ======================================================================
check               property
==================  ======================================================================
valid plans         ``plan(graph, time_limit=..., rng=...)`` returns a :class:`fcplan.Plan`
                    that passes :func:`fcplan.plan.validate_plan` on every graph: known agents
                    and tasks, tasks the agent's role can do, altitudes within bounds, every
                    route within the agent's battery (``TaskGraph`` feasibility views)
determinism         two fresh schedulers from the factory, given generators seeded alike,
                    return identical plans (routes, altitudes, patrols, homes); pass a factory
                    that builds the scheduler in its deterministic mode
time limit          each call returns within ``time_limit * (1 + time_tolerance) +
                    time_slack_s`` wall seconds
time-out            a call at a limit nobody can meet (``timeout_limit``, 1 us) still
                    answers: it does not raise, and its plan does not leave the team idle
                    (:func:`fcplan.scheduling.idle_team`) unless the scheduler declares
                    ``deterministic = True`` (then an idle team is its decision):
                    :func:`fcplan.scheduling.solve` would replace such a plan by greedy's
no mutation         every numpy array of the graph holds the same bytes after the call
batched plans       a scheduler with ``plan_batch`` (:mod:`fcplan.scheduling_batch`): one
                    call on all the sampled graphs returns, graph for graph, the plans
                    ``plan`` returns on each (fresh schedulers, generators seeded alike)
==================  ======================================================================

The graphs come from episodes played by ``greedy`` (so the states are realistic and the same for
every scheduler under test) and are sampled at ``ticks`` of each scenario. The kit calls
``scheduler.plan`` directly, not :func:`fcplan.scheduling.solve`, so a scheduler that would only
survive through the greedy fallback fails here.

Examples
--------
>>> from fcplan.scheduling import make_scheduler
>>> from fcplan.testing import check_scheduler
>>> report = check_scheduler(lambda: make_scheduler("greedy"), scenarios=["practice"], ticks=(0, 50))
>>> report.graphs, report.failures
(2, [])
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fcplan.plan import Plan, validate_plan
from fcplan.scheduling import Scheduler, idle_team, make_scheduler
from fcplan.scheduling_batch import batch_capable
from fcplan.taskgraph import TaskGraph

__all__ = ["ConformanceReport", "check_scheduler", "episode_graphs", "shipped_scenarios"]


@dataclass
class ConformanceReport:
    """What :func:`check_scheduler` saw.

    Attributes
    ----------
    name : str
        The scheduler's ``name``.
    graphs : int
        Task graphs the scheduler planned on.
    max_wall_s : float
        Longest ``plan`` call (wall seconds).
    failures : list of str
        One line per failed check (empty: the scheduler conforms).
    """

    name: str
    graphs: int = 0
    max_wall_s: float = 0.0
    failures: list[str] = field(default_factory=list)


def shipped_scenarios() -> list[str]:
    """Names of every scenario shipped with fcplan (practice, #1..#24 and the open-world files).

    Examples
    --------
    >>> names = shipped_scenarios()
    >>> "practice" in names and "24" in names
    True
    """
    from fcplan.scenario import list_scenarios

    return list_scenarios()


def episode_graphs(scenario: Any, ticks: Iterable[int], seed: int = 0) -> list[TaskGraph]:
    """Task graphs at the replan ``ticks`` of a ``greedy`` episode of ``scenario``.

    The episode replans every simulated second (event replans off), so a tick that is a multiple
    of ``ticks_per_second`` is a replan tick; other ticks are rounded up to the next replan.
    Ticks beyond the episode are dropped.

    Examples
    --------
    >>> [g.tick for g in episode_graphs("practice", (0, 15, 30))]
    [0, 20, 30]
    """
    from fcplan.mission import Mission

    mission = Mission(scenario, seed, event_replans=False)
    greedy = make_scheduler("greedy")
    wanted = sorted(set(int(t) for t in ticks))
    out: list[TaskGraph] = []
    while wanted and not mission.done:
        commands = None
        if mission.replan_due():
            graph, plan = mission.replan(greedy)
            while wanted and wanted[0] <= graph.tick:
                wanted.pop(0)
                if not out or out[-1] is not graph:
                    out.append(graph)
            commands = mission.commands_for(plan, graph)
        mission.step(commands)
    return out


def _arrays(graph: TaskGraph) -> dict[str, bytes]:
    return {
        k: np.ascontiguousarray(v).tobytes()
        for k, v in vars(graph).items()
        if isinstance(v, np.ndarray)
    }


def _same_plan(a: Plan, b: Plan) -> bool:
    def key(p: Plan) -> tuple:
        return (
            {k: tuple(v) for k, v in p.routes.items()},
            {k: float(v) for k, v in p.altitudes.items()},
            frozenset(p.patrol),
            frozenset(p.home),
        )

    return key(a) == key(b)


def _call(
    scheduler: Scheduler, graph: TaskGraph, time_limit: float | None, seed: int
) -> tuple[Plan, float]:
    t0 = time.perf_counter()
    plan = scheduler.plan(graph, time_limit=time_limit, rng=np.random.default_rng(seed))
    return plan, time.perf_counter() - t0


def _timeout_failure(scheduler: Scheduler, graph: TaskGraph, limit: float, seed: int) -> str:
    """Why a call at ``limit`` fails the time-out check ("" when it passes)."""
    try:
        plan, _ = _call(scheduler, graph, limit, seed)
        validate_plan(plan, graph)
    except Exception as exc:  # noqa: BLE001 - every failure is reported, not raised
        return f"at time_limit={limit:g}: {type(exc).__name__}: {exc}"
    idle = "" if getattr(scheduler, "deterministic", False) is True else idle_team(plan, graph)
    return f"at time_limit={limit:g} the plan left the team idle: {idle}" if idle else ""


def _batch_failures(
    factory: Callable[[], Scheduler],
    sampled: list[tuple[str, TaskGraph]],
    time_limit: float | None,
    seed: int,
) -> list[str]:
    """The batched-plans check (module docstring): what differs, per graph."""
    graphs = [g for _, g in sampled]
    rngs = [np.random.default_rng(seed) for _ in graphs]
    try:
        plans = factory().plan_batch(graphs, time_limit=time_limit, rngs=rngs)  # type: ignore[attr-defined]
        if len(plans) != len(graphs):
            return [f"plan_batch returned {len(plans)} plans for {len(graphs)} graphs"]
    except Exception as exc:  # noqa: BLE001 - every failure is reported, not raised
        return [f"plan_batch: {type(exc).__name__}: {exc}"]
    return [
        f"{where}: plan_batch's plan differs from plan's"
        for (where, g), p in zip(sampled, plans, strict=True)
        if not _same_plan(p, _call(factory(), g, time_limit, seed)[0])
    ]


def check_scheduler(
    factory: Callable[[], Scheduler],
    *,
    scenarios: Sequence[Any] | None = None,
    ticks: Sequence[int] = (0, 300, 900),
    seed: int = 0,
    time_limit: float | None = 0.5,
    time_tolerance: float = 0.1,
    time_slack_s: float = 0.05,
    timeout_limit: float | None = 1e-6,
    determinism_every: int = 4,
    raise_on_failure: bool = True,
) -> ConformanceReport:
    """Run the conformance checks (module docstring) on the schedulers ``factory`` builds.

    Parameters
    ----------
    factory : callable
        ``factory()`` returns a fresh scheduler (called twice for the determinism check).
    scenarios : sequence, optional
        Scenarios (names, paths or :class:`fcplan.scenario.Scenario`); default every shipped one.
    ticks : sequence of int
        Replan ticks of the greedy episode at which graphs are taken.
    seed : int
        Seed of the episodes and of the scheduler's generator.
    time_limit : float or None
        Passed to every ``plan`` call; None skips the time-limit check.
    time_tolerance, time_slack_s : float
        A call may take ``time_limit * (1 + time_tolerance) + time_slack_s`` seconds.
    timeout_limit : float or None
        The limit of the time-out check (module docstring); None skips it.
    determinism_every : int
        Check determinism on every n-th graph (it costs two more calls); 0 disables the check.
    raise_on_failure : bool
        Raise ``AssertionError`` listing every failure (default), or only return the report.

    Returns
    -------
    ConformanceReport
    """
    scheduler = factory()
    report = ConformanceReport(name=str(getattr(scheduler, "name", type(scheduler).__name__)))
    budget = None if time_limit is None else time_limit * (1 + time_tolerance) + time_slack_s
    sampled: list[tuple[str, TaskGraph]] = []
    for sc in shipped_scenarios() if scenarios is None else scenarios:
        for graph in episode_graphs(sc, ticks, seed):
            where = f"scenario {getattr(sc, 'name', sc)} tick {graph.tick}"
            sampled.append((where, graph))
            before = _arrays(graph)
            try:
                plan, wall = _call(scheduler, graph, time_limit, seed)
                validate_plan(plan, graph)
            except Exception as exc:  # noqa: BLE001 - every failure is reported, not raised
                report.failures.append(f"{where}: invalid plan: {type(exc).__name__}: {exc}")
                continue
            finally:
                report.graphs += 1
            report.max_wall_s = max(report.max_wall_s, wall)
            if budget is not None and wall > budget:
                report.failures.append(
                    f"{where}: plan took {wall:.3f} s, limit {time_limit} s (allowed {budget:.3f} s)"
                )
            # (views the graph caches on first use appear after the call: not a change)
            after = _arrays(graph)
            changed = [k for k, v in before.items() if after.get(k) != v]
            if changed:
                report.failures.append(f"{where}: the scheduler changed graph arrays {changed}")
            if timeout_limit is not None:
                failure = _timeout_failure(scheduler, graph, timeout_limit, seed)
                if failure:
                    report.failures.append(f"{where}: {failure}")
            if determinism_every and (report.graphs - 1) % determinism_every == 0:
                a, _ = _call(factory(), graph, time_limit, seed)
                b, _ = _call(factory(), graph, time_limit, seed)
                if not _same_plan(a, b):
                    report.failures.append(f"{where}: not deterministic under a fixed seed")
    if report.graphs == 0:
        report.failures.append("no task graph was sampled (no scenario, or no tick in range)")
    elif batch_capable(scheduler):
        report.failures += _batch_failures(factory, sampled, time_limit, seed)
    if raise_on_failure and report.failures:
        raise AssertionError(
            f"scheduler {report.name!r} failed {len(report.failures)} conformance check(s):\n  "
            + "\n  ".join(report.failures)
        )
    return report
