"""The CBBA scheduler: the dump auction, then the sense auction, then one conflict-free plan.

Auction items and services
--------------------------
A fire task can be served in two ways, so conflict-freeness is per **(task, service)**:

* ``dump``: one action (or hybrid) agent dumps water on the fire task;
* ``sense``: one camera agent (perception or hybrid) serves the task with its camera: it covers
  a search block, or it *watches* a fire task (hovers over it, low) so the cells the fire adds
  before the dump are sensed and can be pruned (only sensed cells can be pruned).

A fire task may thus appear in one dumper's route and one watcher's route, never in two dumpers'
or two watchers' routes; a search task appears in at most one route. Two auctions run one after
the other over the same communication graph, each a complete CBBA run with fixed scores:

1. the **dump auction**: items are the fire tasks; bidders are the action and hybrid agents with
   water (an agent on a forced return counts its full tank: it refills at the depot first);
2. the **sense auction**: items are all tasks (watch a fire, cover a search block); bidders are
   the camera agents that won no dump. Each agent values the items with what it learnt in the
   dump auction (its own winner vector, so only what reached its component). A fire an
   action-only agent will dump on is *fought*; the fought tile of each connected fire closest to
   its dumper's start *leads* the fight (most likely the first dump; every agent knows where its
   teammates are from the task graph, but not their paths: CBBA only shares ``y, z, s``).
   Watching a lead is worth ``watch_weight * (top search value + value_k)``, so one camera per
   fought fire supports the fight before any searching (greedy's watchers, one per connected
   fire); watching another fought tile is worth ``watch_weight * value_k``, and an unfought fire
   ``watch_weight * value_k * (1 - freshness_k)`` (re-sensing a stale fire makes it worth dumping
   at the next replan; a fresh, unfought fire is worth nothing to watch). Search blocks are
   worth their task value. A watch is a whole route on its own (the agent flies there and
   hovers): it is only bid on with an empty bundle and nothing joins it.

Both auctions are plain CBBA with scores fixed for the whole auction (the sense scores depend on
the dump auction's outcome, settled by then), so each converges on its own; the rounds and
messages reported are the sums over the two.

Disconnected teams
------------------
Each connected component reaches consensus on its own, and agents in different components may
both win the same (task, service). Sending both would be what a truly decentralised team does, but
the testbed executes one plan, so the plan assembly keeps the higher bid (ties to the lower agent
index) and drops the task from the other route; dropping a task from a route never breaks its
battery feasibility (triangle inequality). These are counted as ``conflicts_resolved`` in the
stats, so the price of the partition is visible; with a connected team it is 0 at convergence.

Time limit
----------
The rounds stop when the time limit passes (each auction runs at least one round, so perception
agents still get routes); the bundles the agents hold then are assembled as above (conflicts
resolved by bid) and the status is ``time_limit``.

Stats
-----
``status`` is ``heuristic`` (``time_limit`` when stopped by the limit); ``objective`` is the sum of
the winning bids of the tasks in the final plan; ``size`` holds ``agents``, ``tasks``, ``rounds``,
``messages``, ``converged``, ``components``, ``diameter`` and ``conflicts_resolved``, and
``message`` says the same in words. Agents on their way home for good (``HOMING``) do not bid but
relay messages. Camera agents fly at ``watch_altitude`` when they watch and at ``search_altitude``
when they search. The algorithm uses no randomness (ties go to lower indices), so plans
are deterministic.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode
from solvers.cbba.auction import NO_WINNER, Auction, StageResult, resolve_conflicts, run_auction
from solvers.cbba.comms import CommGraph, communication_graph

__all__ = ["CBBAResult", "CBBAScheduler"]


@dataclass(frozen=True, eq=False)
class CBBAResult:
    """What :meth:`CBBAScheduler.run` found.

    Attributes
    ----------
    routes : dict of int -> list of int
        Agent row -> task rows in flying order, after cross-component conflicts were resolved.
    service : dict of int -> str
        Agent row -> ``"dump"`` or ``"sense"`` for every routed agent.
    stages : tuple of StageResult
        The dump auction, then the sense auction.
    comm : CommGraph
    objective : float
        Sum of the winning bids of the tasks kept in the plan.
    conflicts_resolved : int
        (task, service) pairs held by more than one agent at the end, given to the highest bid.
    """

    routes: dict[int, list[int]]
    service: dict[int, str]
    stages: tuple[StageResult, ...]
    comm: CommGraph
    objective: float
    conflicts_resolved: int

    @property
    def rounds(self) -> int:
        """Consensus rounds over both auctions."""
        return sum(s.rounds for s in self.stages)

    @property
    def messages(self) -> int:
        """Messages sent over both auctions."""
        return sum(s.messages for s in self.stages)

    @property
    def converged(self) -> bool:
        """Both auctions converged."""
        return all(s.converged for s in self.stages)

    @property
    def timed_out(self) -> bool:
        """The time limit stopped an auction."""
        return any(s.timed_out for s in self.stages)


class CBBAScheduler:
    """Decentralised consensus-based bundle auction (see the module docstring).

    Parameters
    ----------
    bundle_length : int
        Most tasks an agent bids on per replan (``L`` in the paper); an action agent also no
        more than its tank.
    half_life_s : float
        Time discount: a task reached ``t`` seconds from now is worth ``2 ** (-t / half_life_s)``
        of its value.
    fresh_s : float
        A fire sensed within this many seconds counts as fresh; staler fires are worth less to
        dump on (``exp(-(staleness - fresh_s) / fresh_s)``, as greedy) and more to watch.
    watch_weight : float
        Value of watching a fire, relative to its task value (plus the top search-block value for
        the lead tile of a fought fire; see the module docstring).
    watch_altitude, search_altitude : float
        Altitude (m) of camera agents whose route ends with a watch / only covers search blocks
        (clipped to their bounds).
    max_rounds : int
        Cap on the rounds of each auction.

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(3, 12, np.random.default_rng(1))
    >>> res = CBBAScheduler().run(g)
    >>> res.converged, res.conflicts_resolved
    (True, 0)
    """

    name = "cbba"

    def __init__(
        self,
        bundle_length: int = 3,
        half_life_s: float = 2.0,
        fresh_s: float = 5.0,
        watch_weight: float = 2.0,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        max_rounds: int = 500,
    ) -> None:
        if int(bundle_length) < 1:
            raise ValueError(f"bundle_length must be >= 1, got {bundle_length!r}")
        if not float(half_life_s) > 0:
            raise ValueError(f"half_life_s must be > 0, got {half_life_s!r}")
        if int(max_rounds) < 1:
            raise ValueError(f"max_rounds must be >= 1, got {max_rounds!r}")
        self.bundle_length = int(bundle_length)
        self.half_life_s = float(half_life_s)
        self.fresh_s = float(fresh_s)
        self.watch_weight = float(watch_weight)
        self.watch_altitude = float(watch_altitude)
        self.search_altitude = float(search_altitude)
        self.max_rounds = int(max_rounds)

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Run both auctions on ``graph`` and return the assembled plan (``rng`` is unused:
        CBBA breaks ties by agent index)."""
        res = self.run(graph, time_limit=time_limit)
        routes: dict[str, tuple[str, ...]] = {}
        alts: dict[str, float] = {}
        for i, tasks in res.routes.items():
            if not tasks:
                continue
            agent = graph.agent_ids[i]
            routes[agent] = tuple(graph.task_ids[k] for k in tasks)
            if res.service[i] == "sense":
                watch = graph.task_kind[tasks[-1]] == TaskKind.FIRE
                z = self.watch_altitude if watch else self.search_altitude
                alts[agent] = graph.clip_altitude(i, z)
        comm = res.comm
        size = {
            "agents": graph.n_agents,
            "tasks": graph.n_tasks,
            "rounds": res.rounds,
            "messages": res.messages,
            "converged": res.converged,
            "components": comm.n_components,
            "diameter": comm.diameter,
            "conflicts_resolved": res.conflicts_resolved,
        }
        message = (
            f"{res.rounds} rounds, {res.messages} messages, {comm.n_components} component(s), "
            + ("converged" if res.converged else "not converged")
            + (f", {res.conflicts_resolved} conflicts resolved" if res.conflicts_resolved else "")
        )
        stats = SolveStats(
            status="time_limit" if res.timed_out else "heuristic",
            objective=res.objective,
            size=size,
            message=message,
        )
        return Plan(routes=routes, altitudes=alts, stats=stats)

    def run(self, graph: TaskGraph, *, time_limit: float | None = None) -> CBBAResult:
        """Run the dump auction, then the sense auction, and assemble conflict-free routes.

        Parameters
        ----------
        graph : TaskGraph
        time_limit : float, optional
            Seconds for both auctions together.
        """
        deadline = None if time_limit is None else time.perf_counter() + float(time_limit)
        comm = communication_graph(graph.agent_pos, graph.comm_range)
        a = graph.n_agents
        forced = graph.agent_mode == Mode.RETURNING
        free = graph.agent_mode != Mode.HOMING
        start = graph.agent_start_pos
        budget = graph.agent_budget_px
        d_start = graph.start_task_distance
        trip = graph.in_round_trip
        rate = math.log(2.0) / self.half_life_s
        fires = graph.fire_tasks
        stale = graph.task_staleness
        fresh = np.where(
            stale <= self.fresh_s, 1.0, np.exp(-(stale - self.fresh_s) / max(self.fresh_s, 1e-9))
        )

        # 1. dump auction: action / hybrid agents with water -> fire tasks
        tank = np.where(forced, graph.agent_tank_capacity, graph.agent_tank)
        dumpers = free & graph.agent_can_act & (tank > 0)
        dump_value = np.broadcast_to(graph.task_value[fires] * fresh[fires], (a, fires.size))
        dump = Auction(
            value=np.ascontiguousarray(dump_value),
            eligible=dumpers[:, None] & trip[:, fires] & (dump_value > 0),
            exclusive=np.zeros(fires.size, dtype=bool),
            limit=np.minimum(tank, self.bundle_length),
            item_pos=graph.task_pos[fires],
            d_start=d_start[:, fires],
            d_home=graph.task_home_distance[:, fires],
            start=start,
            home=graph.agent_home,
            budget=budget,
            speed=graph.agent_speed,
            rate=rate,
        )
        s1 = run_auction("dump", dump, fires, comm, max_rounds=self.max_rounds, deadline=deadline)

        # 2. sense auction: camera agents without a dump -> watch a fire / cover a search block
        has_dump = np.array([bool(p) for p in s1.paths], dtype=bool)
        sensors = free & graph.agent_can_sense & ~has_dump
        is_fire = graph.task_kind == TaskKind.FIRE
        value = np.broadcast_to(np.where(is_fire, 0.0, graph.task_value), (a, graph.n_tasks)).copy()
        if fires.size and a:
            near = d_start[:, fires]  # px from each dumper's start to each fire
            value[:, fires] = self._watch_values(graph, s1.winners, near, fresh[fires])
        sense = Auction(
            value=value,
            eligible=sensors[:, None] & trip & (value > 0),
            exclusive=is_fire,
            limit=np.full(a, self.bundle_length),
            item_pos=graph.task_pos,
            d_start=d_start,
            d_home=graph.task_home_distance,
            start=start,
            home=graph.agent_home,
            budget=budget,
            speed=graph.agent_speed,
            rate=rate,
        )
        s2 = run_auction(
            "sense",
            sense,
            np.arange(graph.n_tasks),
            comm,
            max_rounds=self.max_rounds,
            deadline=None if deadline is None else max(deadline, time.perf_counter()),
        )

        # 3. assembly: one holder per (task, service), the highest bid
        routes: dict[int, list[int]] = {}
        service: dict[int, str] = {}
        objective = 0.0
        conflicts = 0
        for stage in (s1, s2):
            keep, n_conf, gained = resolve_conflicts(stage)
            conflicts += n_conf
            objective += gained
            for i, path in enumerate(stage.paths):
                kept = [stage.items[j] for j in path if keep.get(j) == i]
                if kept:
                    routes[i] = [int(k) for k in kept]
                    service[i] = stage.name
        return CBBAResult(
            routes=routes,
            service=service,
            stages=(s1, s2),
            comm=comm,
            objective=float(objective),
            conflicts_resolved=conflicts,
        )

    def _watch_values(
        self, graph: TaskGraph, winner: np.ndarray, reach: np.ndarray, fresh: np.ndarray
    ) -> np.ndarray:
        """(A, F) value of watching each fire task to each agent, from its dump-auction winners.

        A fire that an action-only agent will dump on is *fought*; the fought tile of each
        connected fire closest to the start of its dumper (``reach``: (A, F) px from each agent's
        start; ties: lowest index) *leads* it: where the first dump of the fight will most likely
        be. Watching a lead is worth
        ``watch_weight * (top search value + fire value)``, so one camera per fought fire
        supports the fight before it goes searching (greedy's rule); another fought tile is worth
        ``watch_weight * value``, an unfought one ``watch_weight * value * (1 - freshness)``.
        """
        fires = graph.fire_tasks
        val = graph.task_value[fires]
        fought = (winner != NO_WINNER) & ~graph.agent_can_sense[np.maximum(winner, 0)]
        # order fires by (cluster, -value, index); a lead is the first fought fire of its cluster
        # per agent row: fires by (cluster, dumper distance, index); a lead is the first fought
        cluster = np.broadcast_to(graph.task_cluster[fires], winner.shape)
        index = np.broadcast_to(np.arange(fires.size), winner.shape)
        dist = reach[np.maximum(winner, 0), np.arange(fires.size)]
        order = np.lexsort((index, np.where(fought, dist, np.inf), cluster), axis=-1)
        rows = np.arange(winner.shape[0])[:, None]
        cl = cluster[rows, order]
        first = np.r_[True, cl[0, 1:] != cl[0, :-1]]
        f = fought[rows, order].astype(np.int64)
        csum = np.cumsum(f, axis=1)
        seg_start = np.flatnonzero(first)
        before = (csum - f)[:, seg_start]  # fought count before each cluster's segment
        seg = np.cumsum(first) - 1
        lead_sorted = (f == 1) & (csum - before[:, seg] == 1)
        lead = np.empty_like(lead_sorted)
        lead[rows, order] = lead_sorted
        search = graph.search_tasks
        top = float(graph.task_value[search].max()) if search.size else 0.0
        w = self.watch_weight
        return np.where(lead, w * (top + val), np.where(fought, w * val, w * val * (1.0 - fresh)))
