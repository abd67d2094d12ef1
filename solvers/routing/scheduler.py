"""The routing scheduler: task values, candidate nodes, the two models' time, and the plan.

Per role (action first, then perception; see :mod:`solvers.routing`) the vehicles' budgets are
:attr:`fcplan.taskgraph.TaskGraph.agent_budget_px` (their remaining range, a full battery for a
forced return; the way back to the depot slot counts in it), and a vehicle may only serve the
tasks within a full-battery round trip of its depot slot
(:attr:`fcplan.taskgraph.TaskGraph.in_round_trip`) that it can reach and still fly home from.
``visits`` per route are capped by ``max_visits`` and, for action vehicles, by the water left in
the tank (each fire visit uses one dump).

**Objective** (minimised): total travel in px plus the sum of the drop penalties of the candidate
tasks left out, both in px-equivalent units. OR-Tools needs integers: distances are scaled by
``scale`` (10: decimetres) and rounded *up* (so a route the solver accepts is within the battery
in real px too), capacities are rounded down, penalties are rounded (at least 1, so a visit stays
optional). The objective in :class:`fcplan.scheduling.SolveStats` is the sum of the models'
OR-Tools objectives divided by ``scale`` (px). With ``charge_return=False`` (default) the legs
into the depot slots cost nothing (an agent replans every second, long before it would fly home;
charging the way home would pull the search towards the depot) but they still count in the
battery dimension; with ``charge_return=True`` the travel is the whole path start -> tasks ->
depot slot.

**Values** (drop penalties: how many px a vehicle would fly to serve the task):

* action, fire ``k``: ``fire_base_px + fire_value_px * value_k * freshness_k`` where ``value_k``
  is the task's known cells weighted by the facilities it threatens and ``freshness_k`` is 1
  while the fire was sensed within ``fresh_s`` seconds, then decays as
  ``exp(-(staleness - fresh_s) / fresh_s)`` (as in ``greedy``). Action agents have nothing else
  to do, so the base term (default 2000 px, more than most trips across a map) makes every
  reachable fire worth a visit while the tank and ``max_visits`` allow; the value term decides
  which fires when they do not, and travel decides the order;
* perception, search block ``k``: ``search_value_px * value_k`` (its coverage age in s, more
  near known fire), optionally discounted by ``h / (h + eta_k)`` (``search_horizon_s = h > 0``,
  ``eta_k`` the earliest arrival of any perception vehicle; 0, off, by default);
* perception, fire ``k`` ("watching"): ``watch_value_px * value_k * w_k``. Only sensed cells can
  be pruned, and a fire being fought keeps adding unsensed cells, so ``w_k = 1`` for the fires
  a dump is imminent at: the *first* tasks of this replan's action routes (one per connected
  fire, the most valuable, for at most ``max_watch_fraction`` of the perception vehicles, at least
  one, so the others keep searching); this is why the action model is solved first. Other fires
  get ``w_k = clip((staleness - fresh_s) / fresh_s, 0, 1)``: a fire not sensed for a while is
  worth refreshing for the action agents. The default ``watch_value_px = 1000`` px per cell makes
  watching beat searching almost always, so the cap covers every fire offered to watch: at most
  ``max_watch_fraction`` of the perception vehicles (at least one) are offered a fire, one per
  connected fire, the fires of highest watching value. Without it (``cap_all_watch=False``,
  the behaviour before 2026-11-29) stale fires were offered uncapped, and once a fight had run
  for a while every perception agent hovered over some fire and none searched: fires that
  ignite later went unfound (``bench/README.md``, "Routing: watching capped").

A perception route whose first task is a fire becomes a **watch**: the route is cut to that fire
(the agent hovers over it until the next replan) at ``watch_altitude`` (low: reliable sensing);
other perception routes fly at ``search_altitude`` (high: a wide view). A hybrid on an action
route flies it at ``dump_altitude`` (:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`: by default
the top of its bounds, the widest dump; the rule of every built-in scheduler). Altitudes are
clipped to each agent's bounds. Agents with an empty route are not mentioned in the plan (they keep their
current route), as in ``greedy``.

**Model size**: a role with more than ``group_vehicles`` vehicles is split into groups of at
most that many vehicles lying close together, each with the tasks nearest to it, and each group
is its own model (:mod:`solvers.routing.decompose`; 12 by default, so the manual's teams are one
model per role). Each model's candidate nodes are its ``max(max_nodes, nodes_per_vehicle * V)``
most valuable tasks that one of its ``V`` vehicles can reach (default 60; among tasks of equal
value the nearest to one of its vehicles); the others are not offered this replan. On big task graphs this is what keeps a replan within its time limit.
Routes hold at most ``max_visits`` (4) tasks.

**Search and time**: each model is a :func:`solvers.routing.solve_routes` problem (locations:
the ``V`` vehicles' starts, their depot slots, the candidate tasks) searched by ``backend``:
``ortools`` (first solution ``first_solution``, default ``"auto"``: ``PARALLEL_CHEAPEST_INSERTION``
on these prize-collecting models, then ``metaheuristic``, default guided local search) or ``pyvrp`` (iterated local search; the
``routing-pyvrp`` scheduler is this class with ``backend="pyvrp"``).

* default mode: until ``time_limit`` seconds per replan (default 0.1 s; the ``time_limit``
  argument of :meth:`RoutingScheduler.plan` overrides it when given), model building included
  and ``min(10 %, 5 ms)`` of the limit kept back for turning routes into the plan. The action
  model gets a share of the time in proportion to its node count (25 % to 50 %), the perception
  model the rest; each backend sets its own limit from the time left once its model is built.
  On a loaded machine every step takes longer than the clock checks expect (OR-Tools overshot a
  30 ms limit by 60-80 % at p90 under a load of 12 on 2 cores): the scheduler tracks how many
  times longer than asked its recent model calls took (``stretch``: starts at 1.5, rises at
  once, decays by 10 % a call towards what it measures) and asks for that much less;
  The plan depends on the machine's speed in this mode: it is **not** reproducible run to run;
* ``deterministic=True``: the search stops on work limits only (OR-Tools: ``solution_limit``
  solutions or ``branch_limit`` branches; PyVRP: ``iterations`` with seed ``seed``), never on
  the clock, so the same graphs give the same plans run to run and on any machine.

**Warm start**: the scheduler keeps its last plan (per agent, the task ids of its route); its
warm routes are the tasks of an agent's last route that are still candidates of its role, in
order, cut to fit its tank, visits and battery. ``warm_start="fallback"`` (default) keeps them
only as the answer when the clock ends a search before it found anything;
``warm_start="search"`` also starts each search from them; ``"off"`` never uses them. The
memory is dropped when the graph's time does not advance (a new episode) or the agents change.
Starting the search from the last plan scored -11.5 [-19.2, -3.8] points against the previous
scheduler, paired over scenarios 1-24 x seeds 0-2 (wall-clock mode on a loaded machine; see
``bench/README.md``), so it is not the default.

**Time limit**: a search cut by the clock is never handed back as a decision
(:mod:`solvers.routing.core`): unfinished routes are completed by cheapest insertion; if it found
nothing, the warm start is kept (completed by insertion), or, without one, the routes are built
by cheapest insertion from scratch. So the scheduler always answers with routes of its own
model; its floor, when the limit is over before it starts, is reading the graph and building
the distance matrices and the insertion (no solver model is built then).

**Status**: routing never proves optimality. ``feasible``: the work limits or a local optimum
ended the search; ``time_limit``: the clock did (the worse of the two models is reported; the
message says whether a warm start was kept or routes were completed).

**Tours**: ``max_visits=0`` and ``max_nodes=0`` lift the caps on route length and candidate
tasks, and ``charge_return=True`` charges the way home: the model is then a full prize-collecting
VRP (with infinite prizes and one agent, a TSP).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import (
    SolveStats,
    bool_setting,
    choice_setting,
    float_setting,
    int_setting,
)
from fcplan.settings import altitude_setting
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode
from solvers.routing.core import BACKENDS, RoutesResult
from solvers.routing.decompose import bisection_sizes, spatial_groups
from solvers.routing.ortools_backend import OrToolsOptions
from solvers.routing.pyvrp_backend import PyVRPOptions
from solvers.routing.solve import solve_routes

__all__ = ["WARM_STARTS", "PyVRPRoutingScheduler", "RoutingScheduler"]

#: The ways the scheduler uses its last plan (``warm_start``).
WARM_STARTS = ("fallback", "search", "off")


class RoutingScheduler:
    """Prize-collecting vehicle routing per role (see the module docstring).

    Parameters
    ----------
    time_limit : float
        Default seconds per replan (both models together), used when :meth:`plan` gets
        ``time_limit=None``.
    deterministic : bool
        Stop each model's search on work limits, never on the clock: identical plans run to run.
    backend : {"ortools", "pyvrp"}
        Which solver searches the models.
    solution_limit, branch_limit : int, optional
        OR-Tools work limits per model: solutions (deterministic mode only) and search branches
        (both modes; None: no such limit).
    iterations : int
        PyVRP iterations per model in deterministic mode.
    seed : int
        PyVRP's seed.
    max_visits : int
        Most tasks per route (0: no limit).
    max_nodes, nodes_per_vehicle : int
        Candidate tasks per model per replan: the ``max(max_nodes, nodes_per_vehicle * V)`` most
        valuable reachable ones, ``V`` the model's vehicles (``max_nodes=0``: all of them).
    group_vehicles : int
        Most vehicles per model: a role with more is split into spatial groups (0: never).
    fire_base_px : float
        Drop penalty (px) of any fire task for action agents, on top of the value term: action
        agents have nothing else to do, so every reachable fire is worth a trip this long.
    fire_value_px : float
        Drop penalty (px) per unit of (freshness-weighted) fire value for action agents.
    watch_value_px : float
        Drop penalty (px) per unit of fire value for perception agents watching a fire that is
        being fought or is stale.
    search_value_px : float
        Drop penalty (px) per unit of search value (coverage age, s) for perception agents.
    search_horizon_s : float
        If > 0, a search block's penalty is multiplied by ``h / (h + eta)`` with ``eta`` the
        earliest arrival (s) of any perception vehicle at the block (0: no discount).
    fresh_s : float
        A fire sensed within this many seconds counts as fresh.
    watch_altitude, search_altitude : float
        Altitudes (m) of watching and searching perception agents (clipped to their bounds).
    dump_altitude : float or None
        Altitude (m) of a hybrid (camera and water) on an action route, clipped to its bounds;
        None (default): the top of its bounds.
    max_watch_fraction : float
        Largest share of the perception vehicles offered a fire to watch (at least one; one
        fire per connected fire), so the others keep searching.
    cap_all_watch : bool
        The ``max_watch_fraction`` cap covers stale fires too (default); False caps only the
        fires being fought, as before 2026-11-29 (kept to reproduce earlier results).
    charge_return : bool
        Count the way back to the depot slot in the objective (it always counts for the battery).
    first_solution, metaheuristic : str
        OR-Tools ``FirstSolutionStrategy`` (or ``"auto"``, see
        :mod:`solvers.routing.ortools_backend`) / ``LocalSearchMetaheuristic`` names.
    scale : float
        Integer units per px in the models (10: decimetres), in 0.01..1000.
    warm_start : {"fallback", "search", "off"}
        How the last plan's routes are used (see the module docstring); ``True`` / ``False``
        mean ``"search"`` / ``"off"``.
    """

    name = "routing"

    def __init__(
        self,
        time_limit: float = 0.1,
        deterministic: bool = False,
        backend: str = "ortools",
        solution_limit: int = 40,
        branch_limit: int | None = 2000,
        iterations: int = 200,
        seed: int = 0,
        max_visits: int = 4,
        max_nodes: int = 60,
        nodes_per_vehicle: int = 2,
        group_vehicles: int = 12,
        fire_base_px: float = 2000.0,
        fire_value_px: float = 200.0,
        watch_value_px: float = 1000.0,
        search_value_px: float = 10.0,
        search_horizon_s: float = 0.0,
        fresh_s: float = 5.0,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        dump_altitude: float | None = None,
        max_watch_fraction: float = 0.5,
        cap_all_watch: bool = True,
        charge_return: bool = False,
        first_solution: str = "auto",
        metaheuristic: str = "GUIDED_LOCAL_SEARCH",
        scale: float = 10.0,
        warm_start: str | bool = "fallback",
    ) -> None:
        if isinstance(warm_start, (bool, np.bool_)):
            warm_start = "search" if warm_start else "off"
        self.warm_start = choice_setting("warm_start", warm_start, WARM_STARTS)
        self.backend = choice_setting("backend", backend, BACKENDS)
        self.time_limit = float_setting("time_limit", time_limit, 0, lo_open=True, unit=" s")
        self.deterministic = bool_setting("deterministic", deterministic)
        self.solution_limit = int_setting("solution_limit", solution_limit, 1)
        self.branch_limit = (
            None if branch_limit is None else int_setting("branch_limit", branch_limit, 1)
        )
        self.iterations = int_setting("iterations", iterations, 1)
        self.seed = int_setting("seed", seed, 0, 2**31 - 1)  # PyVRP and OR-Tools take 32 bits
        self.max_visits = int_setting("max_visits", max_visits, 0)
        self.max_nodes = int_setting("max_nodes", max_nodes, 0)
        self.nodes_per_vehicle = int_setting("nodes_per_vehicle", nodes_per_vehicle, 1)
        self.group_vehicles = int_setting("group_vehicles", group_vehicles, 0)
        self.fire_base_px = float_setting("fire_base_px", fire_base_px, 0)
        self.fire_value_px = float_setting("fire_value_px", fire_value_px, 0)
        self.watch_value_px = float_setting("watch_value_px", watch_value_px, 0)
        self.search_value_px = float_setting("search_value_px", search_value_px, 0)
        self.search_horizon_s = float_setting("search_horizon_s", search_horizon_s, 0, unit=" s")
        self.fresh_s = float_setting("fresh_s", fresh_s, 0, unit=" s")
        self.watch_altitude = altitude_setting("watch_altitude", watch_altitude)
        self.search_altitude = altitude_setting("search_altitude", search_altitude)
        self.dump_altitude = (
            None if dump_altitude is None else altitude_setting("dump_altitude", dump_altitude)
        )
        self.max_watch_fraction = float_setting("max_watch_fraction", max_watch_fraction, 0, 1)
        self.cap_all_watch = bool_setting("cap_all_watch", cap_all_watch)
        self.charge_return = bool_setting("charge_return", charge_return)
        self.first_solution = first_solution
        self.metaheuristic = metaheuristic
        # integer units per px: 10,000 px x 1,000 stays far inside the solvers' 64-bit costs
        self.scale = float_setting("scale", scale, 0.01, 1000.0)
        # the search settings, checked now (unknown OR-Tools names raise ValueError)
        self._options: OrToolsOptions | PyVRPOptions = (
            OrToolsOptions(
                first_solution=first_solution, metaheuristic=metaheuristic,
                solution_limit=self.solution_limit,
                branch_limit=self.branch_limit if self.branch_limit is not None else 1 << 62,
                wall_branch_limit=self.branch_limit, scale=self.scale,
            )
            if backend == "ortools"
            else PyVRPOptions(iterations=self.iterations, seed=self.seed, scale=self.scale)
        )  # fmt: skip
        # how many times longer than asked a wall-clock model call took lately (>= 1)
        # (starts cautious: the first replan of an episode has no warm start to fall back on)
        self._stretch = 1.5
        # the last plan: (graph time, agent ids, per agent the task ids of its route)
        self._last: tuple[float, tuple[str, ...], dict[str, tuple[str, ...]]] | None = None

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Route both roles on ``graph`` within ``time_limit`` seconds (default: the setting)."""
        limit = self.time_limit if time_limit is None else float(time_limit)
        # keep a little of the limit for turning routes into the plan and freeing the models
        deadline = time.perf_counter() + limit - min(0.1 * limit, 0.005)
        free = graph.agent_mode != Mode.HOMING
        actors = np.flatnonzero(free & graph.agent_can_act & (graph.agent_tank > 0))
        sensors = np.flatnonzero(
            free & graph.agent_can_sense & ~(graph.agent_can_act & (graph.agent_tank > 0))
        )
        last = self._last
        if last is not None and (last[0] >= graph.time_s or last[1] != graph.agent_ids):
            last = None  # a new episode, or other agents: the last plan means nothing here
        warm = last[2] if last is not None and self.warm_start != "off" else {}
        routes: dict[str, tuple[str, ...]] = {}
        alts: dict[str, float] = {}
        sols: dict[str, list[RoutesResult]] = {}
        first_fires = self._route_actors(graph, actors, sensors, deadline, warm, routes, sols)
        for i in actors[graph.agent_can_sense[actors]].tolist():  # hybrids: from the dump altitude
            if graph.agent_ids[i] in routes:
                alts[graph.agent_ids[i]] = graph.dump_altitude(i, self.dump_altitude)
        if sensors.size:
            self._route_sensors(graph, sensors, first_fires, deadline, warm, routes, alts, sols)
        self._last = (graph.time_s, graph.agent_ids, dict(routes))
        return Plan(routes=routes, altitudes=alts, stats=_stats(graph, sols))

    def _route_actors(
        self,
        graph: TaskGraph,
        actors: np.ndarray,
        sensors: np.ndarray,
        deadline: float,
        warm: dict[str, tuple[str, ...]],
        routes: dict[str, tuple[str, ...]],
        sols: dict[str, list[RoutesResult]],
    ) -> list[int]:
        """Action agents -> fires (one visit per dump left in the tank); the routes go into
        ``routes``, the models' solutions into ``sols``. Returns the first fire of each route."""
        fires, blocks = graph.fire_tasks, graph.search_tasks
        stale = graph.task_staleness[fires]
        fresh = np.exp(-np.maximum(stale - self.fresh_s, 0.0) / max(self.fresh_s, 1e-9))
        act_value = self.fire_base_px + self.fire_value_px * graph.task_value[fires] * fresh
        act_value = np.where(graph.task_value[fires] > 0, act_value, 0.0)
        models = self._models(graph, actors, fires, act_value)
        sense_value_guess = np.r_[
            self.watch_value_px * graph.task_value[fires],
            self.search_value_px * graph.task_value[blocks],
        ]
        n_sense = min(
            sum(self._n_candidates(n) for n in bisection_sizes(sensors.size, self._group_size)),
            int((sense_value_guess > 0).sum()) if sensors.size else 0,
        )  # for the time split only
        first_fires: list[int] = []
        n_act = sum(nodes[0].size for _, nodes in models)
        if n_act:
            share = 1.0 if n_sense == 0 else min(max(n_act / (n_act + n_sense), 0.25), 0.5)
            for agents, rows in self._solve_models(graph, models, deadline, share, warm,
                                                   sols.setdefault("action", []), tank=True):  # fmt: skip
                for i, ks in zip(agents.tolist(), rows, strict=True):
                    if ks.size:
                        routes[graph.agent_ids[i]] = tuple(graph.task_ids[k] for k in ks)
                        first_fires.append(int(ks[0]))
        return first_fires

    def _route_sensors(
        self,
        graph: TaskGraph,
        sensors: np.ndarray,
        first_fires: list[int],
        deadline: float,
        warm: dict[str, tuple[str, ...]],
        routes: dict[str, tuple[str, ...]],
        alts: dict[str, float],
        sols: dict[str, list[RoutesResult]],
    ) -> None:
        """Perception agents -> search blocks and fires to watch; the routes and altitudes go
        into ``routes`` and ``alts``, the models' solutions into ``sols``."""
        fires, blocks = graph.fire_tasks, graph.search_tasks
        stale = graph.task_staleness[fires]
        fought = self._fought(graph, fires, first_fires, sensors.size)
        share_stale = np.clip((stale - self.fresh_s) / max(self.fresh_s, 1e-9), 0.0, 1.0)
        watch = self.watch_value_px * graph.task_value[fires] * np.maximum(fought, share_stale)
        if self.cap_all_watch:
            offered = self._watch_cap(graph, fires, watch, sensors.size)
            fires, watch = fires[offered], watch[offered]
        tasks = np.r_[fires, blocks].astype(np.int64)
        search = self.search_value_px * graph.task_value[blocks]
        if self.search_horizon_s > 0 and blocks.size:
            # information is worth less the later it comes: discount each block by the
            # earliest arrival of any perception vehicle (keeps searchers near the action)
            eta = (
                _pairwise(graph.agent_start_pos[sensors], graph.task_pos[blocks])
                / graph.agent_speed[sensors, None]
            )
            search = search * self.search_horizon_s / (self.search_horizon_s + eta.min(0))
        models = self._models(graph, sensors, tasks, np.r_[watch, search])
        solved = self._solve_models(graph, models, deadline, 1.0, warm,
                                    sols.setdefault("perception", []), tank=False)  # fmt: skip
        for agents, rows in solved:
            for i, ks in zip(agents.tolist(), rows, strict=True):
                if not ks.size:
                    continue
                if graph.task_kind[ks[0]] == TaskKind.FIRE:
                    ks, z = ks[:1], self.watch_altitude  # watch: hover over the fire
                else:
                    z = self.search_altitude
                routes[graph.agent_ids[i]] = tuple(graph.task_ids[k] for k in ks)
                alts[graph.agent_ids[i]] = graph.clip_altitude(i, z)

    def _fought(
        self, graph: TaskGraph, fires: np.ndarray, first_fires: list[int], n_sensors: int
    ) -> np.ndarray:
        """(len(fires),) bool: the fires worth watching because a dump is imminent: first tasks
        of action routes, one per connected fire (the most valuable), at most
        ``max_watch_fraction`` of the perception vehicles (at least one)."""
        if not first_fires:
            return np.zeros(fires.size, dtype=bool)
        ks = np.unique(np.asarray(first_fires, dtype=np.int64))
        return np.isin(fires, self._top_per_cluster(graph, ks, graph.task_value[ks], n_sensors))

    def _watch_cap(
        self, graph: TaskGraph, fires: np.ndarray, watch: np.ndarray, n_sensors: int
    ) -> np.ndarray:
        """(k,) positions in ``fires`` of the fires offered to watch: those of positive
        ``watch`` value, the most valuable of each connected fire, at most ``max_watch_fraction``
        of the ``n_sensors`` perception vehicles (at least one)."""
        pos = np.flatnonzero(watch > 0)
        top = self._top_per_cluster(graph, fires[pos], watch[pos], n_sensors)
        return pos[np.isin(fires[pos], top)]

    def _top_per_cluster(
        self, graph: TaskGraph, ks: np.ndarray, value: np.ndarray, n_sensors: int
    ) -> np.ndarray:
        """The most valuable of the fire tasks ``ks`` in each connected fire, by ``value``
        (ties: the order of ``ks``), the first ``max(1, int(max_watch_fraction * n_sensors))``."""
        order = np.argsort(-value, kind="stable")
        ks = ks[order]
        _, first = np.unique(graph.task_cluster[ks], return_index=True)
        n_watch = max(1, int(self.max_watch_fraction * n_sensors))
        return ks[np.sort(first)][:n_watch]

    @property
    def _group_size(self) -> int:
        """Most vehicles per model (huge: no split)."""
        return self.group_vehicles if self.group_vehicles > 0 else 1 << 62

    def _n_candidates(self, n_vehicles: int) -> int:
        """Candidate nodes for a model with ``n_vehicles`` vehicles (huge: no cap)."""
        if self.max_nodes <= 0:
            return 1 << 62
        return max(self.max_nodes, self.nodes_per_vehicle * n_vehicles)

    def _models(
        self, graph: TaskGraph, agents: np.ndarray, tasks: np.ndarray, value: np.ndarray
    ) -> list[tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]]:
        """One role's models: per spatial group of ``agents`` (:mod:`solvers.routing.decompose`),
        its vehicles and (task rows, penalties px) of its candidates, the most valuable tasks
        (see :meth:`_n_candidates`) of the group that one of its vehicles can serve (positive
        value, within a round trip, reachable with the way home). Groups without a candidate
        are left out."""
        if agents.size == 0 or tasks.size == 0:
            return []
        start, budget, trip = graph.agent_start_pos, graph.agent_budget_px, graph.in_round_trip
        d = (
            _pairwise(start[agents], graph.task_pos[tasks])
            + graph.task_home_distance[np.ix_(agents, tasks)]
        )
        reach = trip[np.ix_(agents, tasks)] & (d <= budget[agents, None]) & (value > 0)[None, :]
        out = []
        for gv, gt in spatial_groups(start[agents], graph.task_pos[tasks], reach, self._group_size):
            ok = gt[reach[np.ix_(gv, gt)].any(axis=0)]
            # the most valuable; among equal values the nearest to a vehicle of the group (at
            # t = 0 every search block is worth the same: task order would pick the map's
            # first columns however far they are), then task order
            near = _pairwise(start[agents[gv]], graph.task_pos[tasks[ok]]).min(axis=0)
            order = np.lexsort((np.arange(ok.size), near, -value[ok]))
            top = ok[order[: self._n_candidates(gv.size)]]
            top = np.sort(top)  # task order: the model does not depend on value ties
            if top.size:
                out.append((agents[gv], (tasks[top], value[top])))
        return out

    def _solve_models(
        self,
        graph: TaskGraph,
        models: list[tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]],
        deadline: float,
        share: float,
        warm: dict[str, tuple[str, ...]],
        sols: list[RoutesResult],
        *,
        tank: bool,
    ) -> list[tuple[np.ndarray, list[np.ndarray]]]:
        """Solve one role's models in turn with ``share`` of the time left before
        ``deadline``, each model a part in proportion to its nodes; their solutions go into
        ``sols``. Returns per model its agents and their routes as task rows."""
        now = time.perf_counter()
        role_end = now + max(deadline - now, 0.0) * share
        weights = [nodes[0].size for _, nodes in models]
        out = []
        for n, (agents, nodes) in enumerate(models):
            sol, rows = self._solve(graph, agents, nodes, role_end, weights[n] / sum(weights[n:]),
                                    warm, capacity=graph.agent_tank[agents] if tank else None)  # fmt: skip
            sols.append(sol)
            out.append((agents, rows))
        return out

    def _solve(
        self,
        graph: TaskGraph,
        agents: np.ndarray,
        nodes: tuple[np.ndarray, np.ndarray],
        deadline: float,
        share: float,
        warm: dict[str, tuple[str, ...]],
        capacity: np.ndarray | None = None,
    ) -> tuple[RoutesResult, list[np.ndarray]]:
        """Solve one role's model with ``share`` of the time left before ``deadline``, from the
        warm start's routes; returns the result and per agent its route as task rows."""
        tasks, penalty = nodes
        n_v, m = agents.size, tasks.size
        # locations: the V starts, the V depot slots, then the m candidate tasks
        pos = np.concatenate([graph.agent_start_pos[agents], graph.agent_home[agents],
                              graph.task_pos[tasks]])  # fmt: skip
        allowed = np.ones((n_v, 2 * n_v + m), dtype=bool)
        allowed[:, 2 * n_v :] = graph.in_round_trip[np.ix_(agents, tasks)]
        caps = None
        if self.max_visits > 0:
            caps = np.full(n_v, self.max_visits, dtype=np.int64)
        if capacity is not None:
            caps = capacity if caps is None else np.minimum(caps, capacity)
        warm_routes = None
        if warm:
            where = {graph.task_ids[k]: 2 * n_v + j for j, k in enumerate(tasks.tolist())}
            warm_routes = [
                [where[t] for t in warm.get(graph.agent_ids[i], ()) if t in where]
                for i in agents.tolist()
            ]
        t0 = time.perf_counter()
        ask = max(deadline - t0, 0.0) * share / self._stretch
        res = solve_routes(
            _pairwise(pos, pos),
            starts=np.arange(n_v),
            ends=n_v + np.arange(n_v),
            prizes=np.r_[np.zeros(2 * n_v), penalty],
            budgets=graph.agent_budget_px[agents],
            capacities=caps,
            allowed=allowed,
            charge_return=self.charge_return,
            time_limit=ask,
            deterministic=self.deterministic,
            warm_start=warm_routes,
            search_from_warm=self.warm_start == "search",
            backend=self.backend,
            options=self._options,
        )
        if not self.deterministic and ask > 1e-3:
            # how much longer than asked the call took: rises at once, decays slowly
            ratio = min(max((time.perf_counter() - t0) / ask, 1.0), 4.0)
            self._stretch = max(ratio, 0.9 * self._stretch + 0.1 * ratio)
        rows = [tasks[np.asarray(r, dtype=np.int64) - 2 * n_v] for r in res.routes]
        return res, rows


def _stats(graph: TaskGraph, sols: dict[str, list[RoutesResult]]) -> SolveStats:
    """The plan's stats from the models' results (the worst status of them)."""
    results = [(role, n, s) for role, lst in sols.items() for n, s in enumerate(lst)]
    status = "time_limit" if any(s.status == "time_limit" for *_, s in results) else "feasible"
    size = {
        "models": len(results),
        "vehicles": sum(s.size["vehicles"] for *_, s in results),
        "nodes": sum(s.size["tasks"] for *_, s in results),
        "agents": graph.n_agents,
        "tasks": graph.n_tasks,
    }
    message = "; ".join(
        f"{role}{f' {n + 1}/{len(sols[role])}' if len(sols[role]) > 1 else ''}: {s.backend}, "
        f"{s.size['vehicles']} vehicles x {s.size['tasks']} nodes, travel "
        f"{s.travel:.0f} px, dropped {s.dropped:.0f} px, {s.status}"
        + (", from the warm start" if s.warm_started else "")
        + (", warm start kept (nothing better in time)" if s.kept_warm_start else "")
        + (", completed by insertion after the time-out" if s.repaired else "")
        + (", built by insertion (nothing found in time)" if s.from_insertion else "")
        for role, n, s in results
    )
    return SolveStats(
        status=status,
        objective=float(sum(s.objective for *_, s in results)),
        size=size,
        message=message,
    )


class PyVRPRoutingScheduler(RoutingScheduler):
    """:class:`RoutingScheduler` searched by PyVRP (``backend="pyvrp"``), registered as
    ``routing-pyvrp``; takes the same settings."""

    name = "routing-pyvrp"
    #: takes ``deterministic`` through ``**settings`` (PyVRP stops on iterations then), so
    #: comparisons and sweeps run it deterministically like ``routing``
    supports_deterministic = True

    def __init__(self, **settings: Any) -> None:
        settings.setdefault("backend", "pyvrp")
        super().__init__(**settings)


def _pairwise(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = a[:, None, :] - b[None, :, :]
    out: np.ndarray = np.sqrt(np.einsum("ijk,ijk->ij", d, d))
    return out
