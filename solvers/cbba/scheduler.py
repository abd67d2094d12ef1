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

Both auctions are CBBA (:mod:`solvers.cbba.auction`) with scores fixed for the whole auction (the sense scores depend on
the dump auction's outcome, settled by then), so each converges on its own; the rounds and
messages reported are the sums over the two.

Disconnected teams
------------------
Each connected component reaches consensus on its own, and agents in different components may
both win the same (task, service). Sending both would be what a truly decentralised team does, but
the testbed executes one plan, so the plan assembly (:mod:`solvers.cbba.assembly`) keeps the
higher bid (ties to the lower agent index) and drops the task from the other route; dropping a
task from a route never breaks its battery feasibility (triangle inequality). These are counted
as ``conflicts_resolved`` in the stats, so the price of the partition is visible; with a
connected team it is 0 at convergence. The dump auction is assembled before the sense auction
starts, so a hybrid agent that lost all its dumps this way bids for camera work.

Limits and modes
----------------
* **Wall mode** (``deterministic=False``, the default): when a time limit is given (the
  ``time_limit`` argument of :meth:`CBBAScheduler.plan`, else the ``time_limit`` setting; None:
  no limit), the auctions ask a clock (:mod:`solvers.cbba.clock`) before every bundle
  construction and every neighbour slot of a consensus round and stop in time to complete
  what is missing. The dump auction may use a share of the limit proportional to its size
  (dumpers x fires against cameras x tasks, between 20 % and 80 %), the sense auction what is
  left. ``plan()`` returns within the limit but for its floor: setting up the auctions
  (reading the graph's views and scoring the items, which is not interrupted: well under a
  millisecond on the manual's scenarios, tens of milliseconds on 100 agents x 2,000 tasks),
  the step under way when the clock ran out (one bundle construction or one neighbour slot,
  about a millisecond at most) and the first pass of the completion below (a few
  milliseconds at that size). Pauses that the operating system imposes on a loaded machine
  come on top (``bench/README.md``). Plans then depend on the machine's speed and load.
* **Deterministic mode** (``deterministic=True``): the wall clock is never read; each auction
  stops at convergence or after ``max_rounds`` rounds, so the same graph gives the same plan in
  any process and under any load, whatever time limit is passed (use it for comparisons; the
  rounds per replan in ``bench/bench_cbba.py`` help pick ``max_rounds``).

An auction cut short (by either limit) is assembled from the bundles the agents hold then
(conflicts resolved by bid), and every bidder left with nothing is completed greedily from the
free tasks (:mod:`solvers.cbba.assembly`: one item each in a single vectorised pass, then the
rest of the bundles while the clock allows), so the limit never hands back idle agents as a
decision and never makes the scheduler fail; ``completed`` in the stats counts them.

Stats
-----
``status`` is ``heuristic`` when both auctions converged, ``time_limit`` when the wall clock
stopped one, ``feasible`` when ``max_rounds`` did; ``objective`` is the sum of the winning bids
of the tasks in the final plan; ``size`` holds ``agents``, ``tasks``, ``rounds``, ``messages``,
``last_change`` (rounds until the last change, summed over the auctions), ``converged``,
``stopped_by`` (``converged``, ``max_rounds`` or ``time_limit``: the first auction that did not
converge says why), ``completed``, ``components``, ``diameter`` and ``conflicts_resolved``, and
``message`` says the same in words. Agents on their way home for good (``HOMING``) do not bid but
relay messages. Camera agents fly at ``watch_altitude`` when they watch and at ``search_altitude``
when they search; a hybrid that won dumps flies them at ``dump_altitude``
(:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`: by default the top of its bounds, the widest
dump; the rule of every built-in scheduler). The algorithm uses no randomness (ties go to lower indices).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats
from fcplan.settings import altitude_setting, bool_setting, float_setting, int_setting
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode
from solvers.cbba.assembly import Assembly, assemble
from solvers.cbba.auction import NO_WINNER, Auction, StageResult, run_auction
from solvers.cbba.clock import Clock
from solvers.cbba.comms import CommGraph, communication_graph

__all__ = ["CBBAResult", "CBBAScheduler"]


@dataclass(frozen=True, eq=False)
class CBBAResult:
    """What :meth:`CBBAScheduler.run` found.

    Attributes
    ----------
    routes : dict of int -> list of int
        Agent row -> task rows in flying order, conflict-free (and completed when cut short).
    service : dict of int -> str
        Agent row -> ``"dump"`` or ``"sense"`` for every routed agent.
    auctions : tuple of Auction
        The dump auction, then the sense auction, as posed.
    stages : tuple of StageResult
        How each ran.
    assemblies : tuple of Assembly
        Their conflict-free routes (item indices).
    comm : CommGraph
    objective : float
        Sum of the winning bids of the tasks kept in the plan.
    """

    routes: dict[int, list[int]]
    service: dict[int, str]
    auctions: tuple[Auction, ...]
    stages: tuple[StageResult, ...]
    assemblies: tuple[Assembly, ...]
    comm: CommGraph
    objective: float

    @property
    def rounds(self) -> int:
        """Consensus rounds over both auctions."""
        return sum(s.rounds for s in self.stages)

    @property
    def messages(self) -> int:
        """Messages sent over both auctions."""
        return sum(s.messages for s in self.stages)

    @property
    def last_change(self) -> int:
        """Rounds until the last change, summed over both auctions."""
        return sum(s.last_change for s in self.stages)

    @property
    def converged(self) -> bool:
        """Both auctions converged."""
        return all(s.converged for s in self.stages)

    @property
    def stopped_by(self) -> str:
        """``converged``, or why the first auction that did not converge stopped."""
        return next((s.stopped_by for s in self.stages if not s.converged), "converged")

    @property
    def timed_out(self) -> bool:
        """The wall clock stopped an auction."""
        return any(s.timed_out for s in self.stages)

    @property
    def conflicts_resolved(self) -> int:
        """(task, service) pairs held by more than one agent at the end, given to the highest
        bid."""
        return sum(a.conflicts for a in self.assemblies)

    @property
    def completed(self) -> int:
        """Agents given a route by the greedy completion after a cut."""
        return sum(a.completed for a in self.assemblies)


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
    dump_altitude : float or None
        Altitude (m) of a hybrid (camera and water) on its dumps, clipped to its bounds; None
        (default): the top of its bounds.
    max_rounds : int
        Cap on the rounds of each auction (the work limit of the deterministic mode).
    time_limit : float, optional
        Seconds per replan when :meth:`plan` gets ``time_limit=None`` (None: no limit). Ignored
        when ``deterministic``.
    deterministic : bool
        Never read the wall clock: stop on ``max_rounds`` only (identical plans under any load).

    Raises
    ------
    fcplan.settings.SettingError
        A setting has the wrong type or is out of range (one line naming it and the range; the
        checks every scheduler's settings share).

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(3, 12, np.random.default_rng(1))
    >>> res = CBBAScheduler().run(g)
    >>> res.converged, res.conflicts_resolved
    (True, 0)
    >>> CBBAScheduler(deterministic=True, max_rounds=2).run(g).stopped_by
    'max_rounds'
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
        dump_altitude: float | None = None,
        max_rounds: int = 500,
        time_limit: float | None = None,
        deterministic: bool = False,
    ) -> None:
        self.bundle_length = int_setting("bundle_length", bundle_length, 1)
        self.half_life_s = float_setting("half_life_s", half_life_s, 0.0, lo_open=True, unit=" s")
        self.fresh_s = float_setting("fresh_s", fresh_s, 0.0, unit=" s")
        self.watch_weight = float_setting("watch_weight", watch_weight, 0.0)
        self.watch_altitude = altitude_setting("watch_altitude", watch_altitude)
        self.search_altitude = altitude_setting("search_altitude", search_altitude)
        self.dump_altitude = (
            None if dump_altitude is None else altitude_setting("dump_altitude", dump_altitude)
        )
        self.max_rounds = int_setting("max_rounds", max_rounds, 1)
        self.time_limit = (
            None
            if time_limit is None
            else float_setting("time_limit", time_limit, 0.0, lo_open=True, unit=" s")
        )
        self.deterministic = bool_setting("deterministic", deterministic)

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Run both auctions on ``graph`` and return the assembled plan (``rng`` is unused:
        CBBA breaks ties by agent index)."""
        res = self.run(graph, time_limit=time_limit)
        routes: dict[str, tuple[str, ...]] = {}
        alts: dict[str, float] = {}
        for i, tasks in res.routes.items():
            agent = graph.agent_ids[i]
            routes[agent] = tuple(graph.task_ids[k] for k in tasks)
            if res.service[i] == "sense":
                watch = graph.task_kind[tasks[-1]] == TaskKind.FIRE
                z = self.watch_altitude if watch else self.search_altitude
                alts[agent] = graph.clip_altitude(i, z)
            elif graph.agent_can_sense[i]:  # a hybrid on its dumps
                alts[agent] = graph.dump_altitude(i, self.dump_altitude)
        return Plan(routes=routes, altitudes=alts, stats=_stats(graph, res))

    def run(self, graph: TaskGraph, *, time_limit: float | None = None) -> CBBAResult:
        """Run the dump auction, then the sense auction, and assemble conflict-free routes.

        Parameters
        ----------
        graph : TaskGraph
        time_limit : float, optional
            Seconds for the whole call (None: the ``time_limit`` setting); ignored when
            ``deterministic``.
        """
        if time_limit is None:
            time_limit = self.time_limit
        elif not (math.isfinite(time_limit) and time_limit >= 0):
            raise ValueError(f"cbba: time_limit must be a finite number >= 0 s, got {time_limit!r}")
        clock = None if self.deterministic or time_limit is None else Clock.start(time_limit)
        comm = communication_graph(graph.agent_pos, graph.comm_range)
        stale = graph.task_staleness
        fresh = np.where(
            stale <= self.fresh_s, 1.0, np.exp(-(stale - self.fresh_s) / max(self.fresh_s, 1e-9))
        )
        fires = graph.fire_tasks
        dump = self._dump_auction(graph, fresh)
        if clock is not None:
            clock.stage_deadline(_dump_share(graph, dump))
        s1 = run_auction("dump", dump, fires, comm, max_rounds=self.max_rounds, clock=clock)
        a1 = assemble(s1, dump, clock)
        if clock is not None:
            clock.stage_deadline(1.0)
        winners = s1.winners  # what each agent learnt; after a cut, everyone gets the plan's
        if not s1.converged:
            winners = np.broadcast_to(a1.holders(fires.size), s1.winners.shape)
        sense = self._sense_auction(graph, fresh, a1, winners)
        items = np.arange(graph.n_tasks)
        s2 = run_auction("sense", sense, items, comm, max_rounds=self.max_rounds, clock=clock)
        a2 = assemble(s2, sense, clock)
        routes: dict[int, list[int]] = {}
        service: dict[int, str] = {}
        for stage, asm in ((s1, a1), (s2, a2)):
            for i, path in enumerate(asm.paths):
                if path:
                    routes[i] = [int(stage.items[j]) for j in path]
                    service[i] = stage.name
        return CBBAResult(
            routes=routes,
            service=service,
            auctions=(dump, sense),
            stages=(s1, s2),
            assemblies=(a1, a2),
            comm=comm,
            objective=a1.objective + a2.objective,
        )

    def _common(self, graph: TaskGraph) -> dict[str, Any]:
        """The fields every auction on ``graph`` shares (see :class:`Auction`)."""
        return {
            "start": graph.agent_start_pos,
            "home": graph.agent_home,
            "budget": graph.agent_budget_px,
            "speed": graph.agent_speed,
            "rate": math.log(2.0) / self.half_life_s,
        }

    def _dump_auction(self, graph: TaskGraph, fresh: np.ndarray) -> Auction:
        """Action / hybrid agents with water bid on the fire tasks."""
        a, fires = graph.n_agents, graph.fire_tasks
        forced = graph.agent_mode == Mode.RETURNING
        free = graph.agent_mode != Mode.HOMING
        tank = np.where(forced, graph.agent_tank_capacity, graph.agent_tank)
        dumpers = free & graph.agent_can_act & (tank > 0)
        value = np.broadcast_to(graph.task_value[fires] * fresh[fires], (a, fires.size))
        return Auction(
            value=np.ascontiguousarray(value),
            eligible=dumpers[:, None] & graph.in_round_trip[:, fires] & (value > 0),
            exclusive=np.zeros(fires.size, dtype=bool),
            limit=np.minimum(tank, self.bundle_length),
            item_pos=graph.task_pos[fires],
            d_start=graph.start_task_distance[:, fires],
            d_home=graph.task_home_distance[:, fires],
            **self._common(graph),
        )

    def _sense_auction(
        self, graph: TaskGraph, fresh: np.ndarray, dumps: Assembly, winners: np.ndarray
    ) -> Auction:
        """Camera agents without a dump bid on watching a fire or covering a search block."""
        a, fires = graph.n_agents, graph.fire_tasks
        has_dump = np.array([bool(p) for p in dumps.paths], dtype=bool)
        free = graph.agent_mode != Mode.HOMING
        sensors = free & graph.agent_can_sense & ~has_dump
        is_fire = graph.task_kind == TaskKind.FIRE
        value = np.broadcast_to(np.where(is_fire, 0.0, graph.task_value), (a, graph.n_tasks)).copy()
        if fires.size and a:
            near = graph.start_task_distance[:, fires]  # px from each agent's start to each fire
            if (winners == winners[0]).all():  # everyone agrees (a connected team): one row
                winners = winners[:1]
            value[:, fires] = self._watch_values(graph, winners, near, fresh[fires])
        return Auction(
            value=value,
            eligible=sensors[:, None] & graph.in_round_trip & (value > 0),
            exclusive=is_fire,
            limit=np.full(a, self.bundle_length),
            item_pos=graph.task_pos,
            d_start=graph.start_task_distance,
            d_home=graph.task_home_distance,
            **self._common(graph),
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


def _dump_share(graph: TaskGraph, dump: Auction) -> float:
    """Share of the wall limit for the dump auction: its bidder-item pairs against the camera
    agents' (all tasks), between 0.2 and 0.8."""
    w_dump = float(dump.eligible.sum())
    w_sense = float((graph.agent_can_sense[:, None] & graph.in_round_trip).sum())
    if w_dump + w_sense == 0:
        return 1.0
    return min(max(w_dump / (w_dump + w_sense), 0.2), 0.8)


def _stats(graph: TaskGraph, res: CBBAResult) -> SolveStats:
    """The plan's :class:`SolveStats` (see the module docstring)."""
    comm = res.comm
    stop = res.stopped_by
    size = {
        "agents": graph.n_agents,
        "tasks": graph.n_tasks,
        "rounds": res.rounds,
        "messages": res.messages,
        "last_change": res.last_change,
        "converged": res.converged,
        "stopped_by": stop,
        "completed": res.completed,
        "components": comm.n_components,
        "diameter": comm.diameter,
        "conflicts_resolved": res.conflicts_resolved,
    }
    words = {"converged": "converged", "max_rounds": "stopped by max_rounds"}
    message = (
        f"{res.rounds} rounds, {res.messages} messages, {comm.n_components} component(s), "
        + words.get(stop, "stopped by the time limit")
        + (f", {res.conflicts_resolved} conflicts resolved" if res.conflicts_resolved else "")
        + (f", {res.completed} agent(s) completed greedily" if res.completed else "")
    )
    status = {"converged": "heuristic", "max_rounds": "feasible"}.get(stop, "time_limit")
    return SolveStats(status=status, objective=res.objective, size=size, message=message)
