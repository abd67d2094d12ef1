"""Greedy scheduler: value per travel time, with perception agents supporting the fire fight.

Each replan, in this order:

1. **Action agents** (and hybrids) with water are assigned fire tasks one pick at a time: among
   all (agent, task) pairs the pick with the highest ``value * freshness / (1 + eta)`` wins, where
   ``value`` is the task's known cells weighted by the penalties of the facilities it threatens,
   ``freshness`` decays once the fire has not been sensed for ``fresh_s`` seconds, and ``eta`` is
   the agent's arrival time (seconds) after the tasks already on its route. A fire task gets one
   agent; a route holds at most ``route_length`` tasks and no more than the agent's tank; every
   pick keeps the route plus the way home within the agent's battery. A hybrid (camera and
   water) sent to fires flies them at :meth:`fcplan.taskgraph.TaskGraph.dump_altitude` (the
   ``dump_altitude`` setting, by default the top of its bounds: the widest dump), the rule of
   every built-in scheduler.
2. **Perception agents** watch: each fire that an action agent is heading to first gets the
   nearest free perception agent hovering over it at ``watch_altitude`` (low, for a high sensing
   confidence), so the cells the fire adds before the dump are sensed and can be pruned. At most
   ``max_watch_fraction`` of the perception agents watch; the rest search.
3. **Searching** perception agents take the stalest search blocks by
   ``value / (1 + eta)``, one block at a time, discounting blocks near ones already taken so the
   agents spread out; they fly at ``search_altitude`` (a wide view).

Agents on a forced return (battery or tank) are planned from their depot slot with a full
battery: they resume the new route after recharging.

Settings are checked at construction (:func:`fcplan.settings.int_setting` and friends): a wrong
type, NaN or a value outside its range is a one-line :class:`fcplan.settings.SettingError`.

==================== ======= ============ ===============================================
setting              type    range        meaning
==================== ======= ============ ===============================================
route_length         int     1..1000      fire tasks per action agent per replan
search_route_length  int     1..1000      search blocks per searching perception agent
fresh_s              float   > 0          seconds a sensed fire stays fresh
watch_altitude       float   (0, 10000]   m, clipped to each agent's bounds
search_altitude      float   (0, 10000]   m, clipped to each agent's bounds
max_watch_fraction   float   [0, 1]       share of perception agents that may watch
spread_px            float   >= 0         px around a taken block that are discounted
dump_altitude        float   (0, 10000]   m of a hybrid's dumps, clipped; None: top of bounds
==================== ======= ============ ===============================================

The plans never depend on the wall clock or the time limit (``deterministic`` is always True):
greedy does not look at the clock, so its run time is its floor, what it takes whatever the
limit (``bench/bench_time_limits.py``: about a millisecond of CPU per replan on the manual
suite, 10-27 ms at 50-100 agents x 200-2,000 tasks). It is also what
:func:`fcplan.scheduling.solve` falls back to, so a fallback costs that on top of the failed call.

Many worlds at once. :meth:`GreedyScheduler.plan_batch` plans several independent graphs in one
call, the plans equal to :meth:`~GreedyScheduler.plan`'s graph for graph; the pick loop of all
the graphs runs together (:mod:`solvers.greedy_batch`), the rest of the steps per graph. The
batched envs' experts use it (:mod:`fcplan.scheduling_batch`).

Examples
--------
>>> from fcplan import run_episode
>>> m = run_episode(3, "greedy", seed=0).metrics["manual"]
>>> m.overall_firefighting > 0
True
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from fcplan.plan import MAX_ROUTE_LENGTH, Plan
from fcplan.scheduling import SolveStats, float_setting, int_setting
from fcplan.settings import altitude_setting
from fcplan.taskgraph import TaskGraph
from fcplan.team import Mode

__all__ = ["GreedyScheduler"]

#: One assignment problem: agent rows, task rows, task values, per-agent route limits.
_Job = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: Its answer: task rows per agent row, in pick order, and the value gained.
_Picks = tuple[dict[int, list[int]], float]
_Assigner = Callable[[list[TaskGraph], list[_Job | None], bool], list[_Picks | None]]


class GreedyScheduler:
    """Sequential best-ratio assignment (see the module docstring).

    Parameters
    ----------
    route_length : int
        Most fire tasks per action agent per replan.
    search_route_length : int
        Search blocks per searching perception agent.
    fresh_s : float
        A fire sensed within this many seconds counts as fresh.
    watch_altitude : float
        Altitude (m) of perception agents watching a fire (clipped to their bounds).
    search_altitude : float
        Altitude (m) of searching perception agents (clipped to their bounds).
    max_watch_fraction : float
        Largest share of perception agents that watch rather than search (at least one watches
        when there is a fire being fought).
    spread_px : float
        Search blocks within this distance of a block already taken are discounted.
    dump_altitude : float or None
        Altitude (m) of a hybrid (camera and water) on a route of fires, clipped to its bounds;
        None (default): the top of its bounds (:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`).
    """

    name = "greedy"
    #: The plans never depend on the wall clock (there is no time-limited search).
    deterministic = True

    def __init__(
        self,
        route_length: int = 3,
        search_route_length: int = 2,
        fresh_s: float = 5.0,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        max_watch_fraction: float = 0.5,
        spread_px: float = 250.0,
        dump_altitude: float | None = None,
    ) -> None:
        self.route_length = int_setting("route_length", route_length, 1, MAX_ROUTE_LENGTH)
        self.search_route_length = int_setting(
            "search_route_length", search_route_length, 1, MAX_ROUTE_LENGTH
        )
        self.fresh_s = float_setting("fresh_s", fresh_s, 0.0, lo_open=True, unit=" s")
        self.watch_altitude = altitude_setting("watch_altitude", watch_altitude)
        self.search_altitude = altitude_setting("search_altitude", search_altitude)
        self.max_watch_fraction = float_setting("max_watch_fraction", max_watch_fraction, 0.0, 1.0)
        self.spread_px = float_setting("spread_px", spread_px, 0.0, unit=" px")
        self.dump_altitude = (
            None if dump_altitude is None else altitude_setting("dump_altitude", dump_altitude)
        )

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Build the greedy plan for ``graph``."""
        return self._plans([graph], self._assign_each)[0]

    def plan_batch(
        self,
        graphs: Sequence[TaskGraph],
        *,
        time_limit: float | None = None,
        rngs: Sequence[Any] | None = None,
    ) -> list[Plan]:
        """The greedy plans of several independent graphs (one per world of a batched env), the
        assignments of all graphs computed together (:mod:`solvers.greedy_batch`): equal, plan
        for plan, to ``[self.plan(g) for g in graphs]`` (``tests/solvers/test_greedy_batch.py``).

        Examples
        --------
        >>> import numpy as np
        >>> from fcplan.taskgraph import synthetic_task_graph
        >>> gs = [synthetic_task_graph(4, 9, np.random.default_rng(s)) for s in range(3)]
        >>> g = GreedyScheduler()
        >>> [p.routes for p in g.plan_batch(gs)] == [g.plan(x).routes for x in gs]
        True
        """
        from solvers.greedy_batch import assign_batch

        return self._plans(list(graphs), lambda gs, jobs, spread: assign_batch(
            gs, jobs, spread_px=self.spread_px if spread else None))  # fmt: skip

    def _plans(self, graphs: list[TaskGraph], assign: _Assigner) -> list[Plan]:
        """The three steps of the module docstring for every graph, the two assignment steps
        done by ``assign`` (one graph at a time, or all together)."""
        roles = [_free_and_hybrids(g) for g in graphs]
        fire_jobs = [self._fire_job(g, *r) for g, r in zip(graphs, roles, strict=True)]
        fire_picks = assign(graphs, fire_jobs, False)
        out: list[Plan] = []
        search_jobs: list[_Job | None] = []
        states = []
        for g, (free, hybrids), picks in zip(graphs, roles, fire_picks, strict=True):
            routes: dict[str, tuple[str, ...]] = {}
            alts: dict[str, float] = {}
            first_fire: dict[int, int] = {}
            objective = 0.0
            if picks is not None:
                objective += picks[1]
                for row, tasks in picks[0].items():
                    if tasks:
                        routes[g.agent_ids[row]] = tuple(g.task_ids[k] for k in tasks)
                        first_fire[row] = tasks[0]
                        if g.agent_can_sense[row]:  # a hybrid: it dumps from its dump altitude
                            alts[g.agent_ids[row]] = g.dump_altitude(row, self.dump_altitude)
            # 2. perception agents watch the fires being fought
            sensors = np.flatnonzero(free & g.agent_can_sense & ~g.agent_can_act)
            busy = self._watch(g, sensors, first_fire, routes, alts)
            # 3. the others search
            searchers = np.array(
                [i for i in np.r_[sensors, hybrids] if i not in busy and g.agent_ids[i] not in routes],
                dtype=np.int64,
            )  # fmt: skip
            blocks = g.search_tasks
            job = None
            if searchers.size and blocks.size:
                job = (searchers, blocks, g.task_value[blocks].astype(np.float64),
                       np.full(searchers.size, self.search_route_length))  # fmt: skip
            search_jobs.append(job)
            states.append((routes, alts, objective))
        search_picks = assign(graphs, search_jobs, True)
        for g, (routes, alts, objective), picks in zip(graphs, states, search_picks, strict=True):
            if picks is not None:
                objective += picks[1]
                for row, tasks in picks[0].items():
                    if tasks:
                        routes[g.agent_ids[row]] = tuple(g.task_ids[k] for k in tasks)
                        alts[g.agent_ids[row]] = g.clip_altitude(row, self.search_altitude)
            size = {"agents": g.n_agents, "tasks": g.n_tasks, "fires": int(g.fire_tasks.size)}
            stats = SolveStats(status="heuristic", objective=float(objective), size=size)
            out.append(Plan(routes=routes, altitudes=alts, stats=stats))
        return out

    def _fire_job(self, graph: TaskGraph, free: np.ndarray, hybrids: np.ndarray) -> _Job | None:
        """Step 1's assignment problem: the action agents (and ``hybrids``) with water among the
        ``free`` ones, the fire tasks, their fresh values and the route limits; None when either
        side is empty."""
        fires = graph.fire_tasks
        actors = np.flatnonzero(
            free & graph.agent_can_act & (graph.agent_tank > 0) & ~graph.agent_can_sense
        )
        actors = np.r_[actors, hybrids].astype(np.int64)
        if not (actors.size and fires.size):
            return None
        stale = graph.task_staleness[fires]
        fresh = np.where(
            stale <= self.fresh_s,
            1.0,
            np.exp(-(stale - self.fresh_s) / max(self.fresh_s, 1e-9)),
        )
        value = graph.task_value[fires] * fresh
        return actors, fires, value, np.minimum(graph.agent_tank[actors], self.route_length)

    def _assign_each(
        self, graphs: list[TaskGraph], jobs: list[_Job | None], spread: bool
    ) -> list[_Picks | None]:
        """:meth:`_assign` on each graph's job in turn (the readable rule)."""
        return [
            None
            if job is None
            else self._assign(g, job[0], job[1], job[2], limit=job[3], spread=spread)
            for g, job in zip(graphs, jobs, strict=True)
        ]

    # ------------------------------------------------------------------ helpers
    def _watch(
        self,
        graph: TaskGraph,
        sensors: np.ndarray,
        first_fire: dict[int, int],
        routes: dict[str, tuple[str, ...]],
        alts: dict[str, float],
    ) -> set[int]:
        """Each fire an action agent heads to first (most valuable first, one per connected
        fire) gets the nearest free perception agent that can fly there and home, for at most
        ``max_watch_fraction`` of them (at least one); their routes and altitudes go into
        ``routes`` and ``alts``. Returns the rows of the watchers."""
        start, budget = graph.agent_start_pos, graph.agent_budget_px
        busy: set[int] = set()
        if not (sensors.size and first_fire):
            return busy
        n_watch = max(1, int(self.max_watch_fraction * sensors.size)) if sensors.size > 1 else 1
        watched_clusters: set[int] = set()
        targets = sorted(first_fire.values(), key=lambda k: -graph.task_value[k])
        for k in targets:
            if len(busy) >= n_watch:
                break
            cl = int(graph.task_cluster[k])
            if cl in watched_clusters:
                continue
            cand = [i for i in sensors if i not in busy]
            d = np.hypot(*(start[cand] - graph.task_pos[k]).T)
            ok = d + graph.task_home_distance[cand, k] <= budget[cand]
            if not ok.any():
                continue
            i = int(np.asarray(cand)[ok][np.argmin(d[ok])])
            busy.add(i)
            watched_clusters.add(cl)
            routes[graph.agent_ids[i]] = (graph.task_ids[k],)
            alts[graph.agent_ids[i]] = graph.clip_altitude(i, self.watch_altitude)
        return busy

    def _assign(
        self,
        graph: TaskGraph,
        agents: np.ndarray,
        tasks: np.ndarray,
        value: np.ndarray,
        *,
        limit: np.ndarray,
        spread: bool = False,
    ) -> tuple[dict[int, list[int]], float]:
        """Repeatedly give the best (agent, task) pick; return routes (task rows) per agent row.

        The (agent, task) score matrix is built once; after each pick only the picking agent's
        row (its position, time and budget changed), the taken task's column and the rows whose
        best choice was affected are updated, so a replan costs O(A K + picks (K + A)).
        """
        n_a, n_k = agents.size, tasks.size
        routes: dict[int, list[int]] = {int(a): [] for a in agents}
        if n_a == 0 or n_k == 0:
            return routes, 0.0
        value = value.astype(np.float64)
        speed = graph.agent_speed[agents]
        pos = graph.agent_start_pos[agents].copy()
        used = np.zeros(n_a)  # px already planned
        elapsed = np.zeros(n_a)  # s already planned
        home = graph.task_home_distance[np.ix_(agents, tasks)]  # (a, k)
        ok = graph.in_round_trip[np.ix_(agents, tasks)] & (value > 0)[None, :]
        left = graph.agent_budget_px[agents]
        count = np.zeros(n_a, dtype=np.int64)
        taken = np.zeros(n_k, dtype=bool)
        tpos = graph.task_pos[tasks]

        def rows(r: np.ndarray | slice) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            diff = pos[r][:, None, :] - tpos[None, :, :]
            d = np.sqrt(np.einsum("akc,akc->ak", diff, diff))
            eta = elapsed[r][:, None] + d / speed[r][:, None]
            feasible = ok[r] & (used[r][:, None] + d + home[r] <= left[r][:, None])
            return np.where(feasible, value[None, :] / (1.0 + eta), -np.inf), d, eta

        score, dist, eta = rows(slice(None))
        score[count >= limit] = -np.inf
        best = np.argmax(score, axis=1)
        best_s = score[np.arange(n_a), best]
        gained = 0.0
        while True:
            a = int(np.argmax(best_s))
            k = int(best[a])
            if not np.isfinite(best_s[a]):
                break
            routes[int(agents[a])].append(int(tasks[k]))
            gained += float(value[k])
            count[a] += 1
            used[a] += dist[a, k]
            elapsed[a] = eta[a, k]
            pos[a] = tpos[k]
            taken[k] = True
            score[:, k] = -np.inf  # one agent per task
            touched = best == k
            if spread:
                near = np.hypot(*(tpos - tpos[k]).T) < self.spread_px
                near[k] = False
                value[near] *= 0.3
                score[:, near] *= 0.3  # scores are proportional to value (finite ones are > 0)
                touched |= near[best]
            if count[a] < limit[a]:
                row, d_a, eta_a = rows(np.array([a]))
                row[0, taken] = -np.inf
                score[a], dist[a], eta[a] = row[0], d_a[0], eta_a[0]
            else:
                score[a] = -np.inf
            touched[a] = True
            idx = np.flatnonzero(touched)
            best[idx] = np.argmax(score[idx], axis=1)
            best_s[idx] = score[idx, best[idx]]
        return routes, gained


def _free_and_hybrids(graph: TaskGraph) -> tuple[np.ndarray, np.ndarray]:
    """(A,) bool: the agents not homing; and the rows of the free hybrids with water."""
    free = graph.agent_mode != Mode.HOMING
    hybrids = np.flatnonzero(
        free & graph.agent_can_act & graph.agent_can_sense & (graph.agent_tank > 0)
    )
    return free, hybrids
