"""Plans: what a scheduler decides, how it is checked, and how it becomes agent commands.

A :class:`Plan` gives each agent an ordered route of task ids from the task graph it was made for
(plus, for perception and hybrid agents, an altitude). Agents a plan does not mention keep doing
what they were doing. :func:`validate_plan` checks a plan against its graph before it is executed;
:func:`plan_commands` turns it into :class:`fcplan.team.Command` objects for
:meth:`fcplan.world.World.step`.

Examples
--------
>>> from fcplan.plan import Plan
>>> plan = Plan(routes={"P1": ("search:D-04",)}, altitudes={"P1": 80.0})
>>> plan.routes["P1"]
('search:D-04',)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from fcplan.errors import PlanError
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Command

__all__ = ["Plan", "validate_plan", "plan_commands", "MAX_ROUTE_LENGTH"]

#: Most task visits in one agent's route. Validation refuses longer routes before looking at
#: their tasks, so a runaway scheduler cannot make an episode crawl (a route of 10^6 goals used
#: to turn a 20 s episode into 62 s); routes are replanned every period anyway.
MAX_ROUTE_LENGTH = 1000


@dataclass(frozen=True)
class Plan:
    """Routes of task ids per agent.

    Parameters
    ----------
    routes : mapping of agent id -> tuple of task ids
        The tasks each agent visits, in order. An empty tuple stops the agent where it is.
    altitudes : mapping of agent id -> float
        Altitude for perception/hybrid agents (m, within the agent's bounds).
    patrol : frozenset of agent ids
        Agents whose route repeats as a loop.
    home : frozenset of agent ids
        Agents sent home to idle (they must not have a route).
    stats : fcplan.scheduling.SolveStats, optional
        How the plan was found.
    """

    routes: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    altitudes: Mapping[str, float] = field(default_factory=dict)
    patrol: frozenset[str] = frozenset()
    home: frozenset[str] = frozenset()
    stats: object | None = None

    def with_stats(self, stats: object | None) -> Plan:
        """The same plan carrying ``stats``."""
        return Plan(self.routes, self.altitudes, self.patrol, self.home, stats)

    @property
    def n_assignments(self) -> int:
        """Total number of task visits in the plan."""
        return sum(len(r) for r in self.routes.values())


def validate_plan(plan: Plan, graph: TaskGraph) -> None:
    """Raise :class:`fcplan.errors.PlanError` unless ``plan`` fits ``graph``.

    Checks: agents and tasks exist; each task suits the agent's role (search blocks need a
    camera); altitudes are within the agent's bounds; no agent is both routed and sent home; and
    battery feasibility: every task is within a round trip of the agent's depot slot on a full
    battery, and an active agent can reach its first task and still fly home on what it has left.
    The battery rule is the graph's (:attr:`fcplan.taskgraph.TaskGraph.in_round_trip` and
    :attr:`fcplan.taskgraph.TaskGraph.reachable`), which schedulers can read before they plan.
    Every route is a sequence of at most :data:`MAX_ROUTE_LENGTH` task ids, checked first.

    Examples
    --------
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(2, 4, np.random.default_rng(0))
    >>> agent = g.agent_ids[0]
    >>> validate_plan(Plan(routes={agent: (g.task_ids[0],) * 1001}), g)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.errors.PlanError: agent ...: route of 1001 tasks is longer than MAX_ROUTE_LENGTH (1000)
    """
    if not isinstance(plan, Plan):
        raise PlanError(f"a scheduler must return a Plan, got {type(plan).__name__}")
    _check_route_lengths(plan)
    try:
        if _plan_ok(plan, graph):
            return
    except Exception:  # odd input (wrong types...): the checks below name the problem
        pass
    _check_plan(plan, graph)


_NUMBER = (int, float, np.integer, np.floating)


def _check_route_lengths(plan: Plan) -> None:
    """Every route is a sized sequence of at most :data:`MAX_ROUTE_LENGTH` items (before any
    per-item work)."""
    routes = plan.routes
    if not isinstance(routes, Mapping):
        raise PlanError(
            f"plan routes must be a mapping of agent id -> route, got {type(routes).__name__}"
        )
    for agent, route in routes.items():
        try:
            n = len(route)
        except TypeError:
            raise PlanError(
                f"agent {agent!r}: route must be a sequence of task ids, not {type(route).__name__}"
            ) from None
        if n > MAX_ROUTE_LENGTH:
            raise PlanError(
                f"agent {agent}: route of {n} tasks is longer than MAX_ROUTE_LENGTH "
                f"({MAX_ROUTE_LENGTH})"
            )


def _plan_ok(plan: Plan, graph: TaskGraph) -> bool:
    """True when every check of :func:`validate_plan` passes (vectorised, the same views);
    False sends the plan through :func:`_check_plan` for the precise error."""
    aidx, tidx = graph.agent_index, graph.task_index
    routes, alts = plan.routes, plan.altitudes
    if not (
        aidx.keys() >= routes.keys()
        and aidx.keys() >= alts.keys()
        and aidx.keys() >= set(plan.patrol)
        and aidx.keys() >= set(plan.home)
    ):
        return False
    if plan.home and set(plan.home) & {a for a, r in routes.items() if r}:
        return False
    if alts:
        if not all(isinstance(z, _NUMBER) for z in alts.values()):
            return False
        rows = [aidx[a] for a in alts]
        z = np.array(list(alts.values()), dtype=np.float64)
        rng = graph.agent_alt_range[rows]
        if not (np.isfinite(z) & (rng[:, 0] - 1e-9 <= z) & (z <= rng[:, 1] + 1e-9)).all():
            return False
    agent_rows: list[int] = []
    task_rows: list[int] = []
    first: list[bool] = []
    for agent, route in routes.items():
        if isinstance(route, str):
            return False
        i = aidx[agent]
        for j, t in enumerate(route):
            k = tidx.get(t)
            if k is None:
                return False
            agent_rows.append(i)
            task_rows.append(k)
            first.append(j == 0)
    if not task_rows:
        return True
    ai = np.array(agent_rows)
    ti = np.array(task_rows)
    search = graph.task_kind[ti] == TaskKind.SEARCH
    if (search & ~graph.agent_can_sense[ai]).any():
        return False
    if not graph.in_round_trip_at(ai, ti).all():
        return False
    f = np.array(first)
    return bool(graph.reachable_at(ai[f], ti[f]).all())


def _check_plan(plan: Plan, graph: TaskGraph) -> None:
    """The checks of :func:`validate_plan` one by one, raising the first failure's error."""
    aidx, tidx = graph.agent_index, graph.task_index
    for agent in list(plan.routes) + list(plan.altitudes) + list(plan.patrol) + list(plan.home):
        if agent not in aidx:
            raise PlanError(
                f"plan names unknown agent {agent!r}; agents are {', '.join(graph.agent_ids)}"
            )
    both = set(plan.home) & {a for a, r in plan.routes.items() if r}
    if both:
        raise PlanError(f"agents {sorted(both)} are both routed and sent home")
    for agent, z in plan.altitudes.items():
        i = aidx[agent]
        lo, hi = graph.agent_alt_range[i]
        if not (np.isfinite(z) and lo - 1e-9 <= z <= hi + 1e-9):
            raise PlanError(f"agent {agent}: altitude {z!r} is outside its range {lo:g}..{hi:g} m")
    for agent, route in plan.routes.items():
        i = aidx[agent]
        if isinstance(route, str):
            raise PlanError(f"agent {agent}: route must be a sequence of task ids, not a string")
        rows: list[int] = []
        for t in route:
            k = tidx.get(t)
            if k is None:
                raise PlanError(f"agent {agent}: unknown task {t!r} in its route")
            if graph.task_kind[k] == TaskKind.SEARCH and not graph.agent_can_sense[i]:
                raise PlanError(f"agent {agent}: cannot serve search task {t!r} (no camera)")
            rows.append(k)
        if not rows:
            continue
        too_far = ~graph.in_round_trip_at(np.full(len(rows), i), np.array(rows))
        if too_far.any():
            t = graph.task_ids[rows[int(np.argmax(too_far))]]
            raise PlanError(
                f"agent {agent}: task {t!r} is beyond a round trip on a full battery "
                f"({graph.agent_full_range[i]:.0f} px)"
            )
        if not graph.reachable_at(np.array([i]), np.array(rows[:1]))[0]:  # (role, round trip: ok)
            need = graph.agent_task_distance[i, rows[0]] + graph.task_home_distance[i, rows[0]]
            have = graph.agent_budget_px[i]
            raise PlanError(
                f"agent {agent}: cannot reach {graph.task_ids[rows[0]]!r} and fly home on its "
                f"remaining battery ({have:.0f} px < {need:.0f} px)"
            )


def plan_commands(plan: Plan, graph: TaskGraph) -> dict[str, Command]:
    """Turn a (valid) plan into one :class:`fcplan.team.Command` per mentioned agent."""
    tidx = graph.task_index
    out: dict[str, Command] = {}
    agents = set(plan.routes) | set(plan.altitudes) | set(plan.home)
    for agent in sorted(agents, key=graph.agent_index.__getitem__):
        if agent in plan.home:
            out[agent] = Command(home=True, altitude=plan.altitudes.get(agent))
            continue
        route = plan.routes.get(agent)
        pts = None
        if route is not None:
            pts = tuple(
                (float(graph.task_pos[tidx[t], 0]), float(graph.task_pos[tidx[t], 1]))
                for t in route
            )
        out[agent] = Command(
            route=pts, patrol=agent in plan.patrol, altitude=plan.altitudes.get(agent)
        )
    return out
