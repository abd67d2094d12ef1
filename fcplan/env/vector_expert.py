"""A scheduler's plans as the actions of every world of a batched motion env.

:class:`BatchPlanFollower` is :class:`fcplan.env.motion_expert.PlanFollower` for a
:class:`fcplan.env.vector_motion.VectorMotionEnv`: world ``b``'s actions are, tick for tick,
those the single follower chooses on the single env of world ``b``'s seed (the same beliefs,
replans, plans and moves: ``tests/env/test_vector_expert.py``), so that a learned motion policy
is compared with, or imitates, a scheduling baseline on the batched env.

What is batched and what is not. The team's belief of every world is one
:class:`fcplan.belief_batch.BatchBelief`, folded in from the batched simulator's report of each
step (:attr:`VectorMotionEnv.last_info <fcplan.env.vector_motion.VectorMotionEnv.last_info>`);
the task graphs of the worlds that replan at a tick are built together
(:func:`fcplan.taskgraph.build_batch.build_graphs`) and planned together
(:func:`fcplan.scheduling_batch.solve_batch`): a scheduler named by a spec that offers
``plan_batch`` (greedy) is one instance planning every replanning world in one call, any other
one instance per world called in turn, each plan settled as :func:`fcplan.scheduling.solve`
settles it (with the world's controller generator; a failing solver falls back to greedy for
its world). The move rule is the single follower's (:class:`fcplan.env.motion_expert.TeamRoutes`)
run for every world and agent at once by its fast kernel
(:class:`fcplan.env.vector_moves.BatchRoutes`, tested equal to it). Worlds that finish are skipped
(their actions are 0: the env ignores them) and start afresh when the env resets them. What
this costs against the single env with :class:`~fcplan.env.motion_expert.PlanFollower` is
measured by ``bench/bench_vector_expert.py`` (figures in ``bench/README.md``).

Examples
--------
>>> from fcplan.env.vector_motion import VectorMotionEnv
>>> env = VectorMotionEnv("practice", 3)
>>> expert = BatchPlanFollower(env, "greedy")
>>> obs, infos = env.reset(seed=0)
>>> for _ in range(30):
...     obs, rewards, terms, truncs, infos = env.step(expert.actions(obs))
>>> expert.replans.tolist()
[3, 3, 3]
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, cast

import numpy as np

from fcplan.belief_batch import BatchBelief
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_moves import BatchRoutes
from fcplan.env.vector_task import TeamView, world_graphs
from fcplan.errors import EnvError
from fcplan.mission import check_replan_period, period_ticks
from fcplan.plan import Plan
from fcplan.scheduling import Scheduler, deterministic_spec, make_scheduler
from fcplan.scheduling_batch import batch_capable, instances, solve_batch
from fcplan.taskgraph import TaskGraphBuilder, TaskGraphParams

__all__ = ["BatchPlanFollower"]


class BatchPlanFollower:
    """Plans turned into moves in every world of a batched motion env (module docstring).

    Parameters
    ----------
    env : VectorMotionEnv
    scheduler : str, Scheduler or sequence of Scheduler
        A registered scheduler name or spec (one instance planning every world together when it
        has ``plan_batch``, as greedy, else one instance per world); one instance with
        ``plan_batch`` (shared by the worlds); or one instance per world (a scheduler that keeps
        state between calls sees only its own world). A spec runs in the scheduler's
        deterministic mode if it has one, as :class:`~fcplan.env.motion_expert.PlanFollower`'s.
    replan_period, time_limit, graph_params
        As :class:`fcplan.env.motion_expert.PlanFollower`.

    Attributes
    ----------
    shared : Scheduler or None
        The one instance planning every world in one call (:mod:`fcplan.scheduling_batch`),
        else None (one call per world).
    replans : ndarray, (B,) int64
        Plans made in each world since its episode started.
    plans : list of Plan or None
        Each world's last plan.
    """

    def __init__(
        self,
        env: VectorMotionEnv,
        scheduler: str | Scheduler | Sequence[Scheduler],
        *,
        replan_period: float = 1.0,
        time_limit: float | None = None,
        graph_params: TaskGraphParams | None = None,
    ) -> None:
        if not isinstance(env, VectorMotionEnv):
            raise EnvError("BatchPlanFollower: env must be a VectorMotionEnv")
        replan_period = check_replan_period(replan_period, error=EnvError)
        self.env, num = env, env.num_envs
        self.shared: Scheduler | None = None
        if isinstance(scheduler, str):
            spec = deterministic_spec(scheduler)
            made = instances(lambda: make_scheduler(spec), num)
            self.shared = None if isinstance(made, list) else made
            self.schedulers: list[Scheduler] = made if isinstance(made, list) else [made] * num
        elif isinstance(scheduler, (list, tuple)):
            self.schedulers = list(scheduler)
            if len(self.schedulers) != num:
                raise EnvError(
                    f"scheduler: need {num} schedulers, one per world (got {len(self.schedulers)})"
                )
        elif num == 1 or batch_capable(scheduler):
            self.schedulers = [cast(Scheduler, scheduler)] * num
            self.shared = self.schedulers[0] if num > 1 else None
        else:
            raise EnvError(
                "scheduler: give a name, an instance with plan_batch, or one instance per world "
                "(an instance without plan_batch would be shared by the worlds)"
            )
        if any(getattr(s, "clairvoyant", False) for s in self.schedulers):
            raise EnvError("scheduler: clairvoyant schedulers (oracle) are not batched")
        sc = env.scenario
        self.time_limit, self.graph_params = time_limit, graph_params
        self.period = period_ticks(float(replan_period), sc.ticks_per_second)
        self._block_px = int((graph_params or TaskGraphParams()).search_block_px)
        self._ids = list(env.agent_ids)
        self._teams = [TeamView(env.batch.team, b) for b in range(num)]
        self.belief = BatchBelief(sc, num)
        self._routes = BatchRoutes(self._ids, sc, num)
        self._builders = [TaskGraphBuilder(sc, graph_params) for _ in range(num)]
        self._next = np.zeros(num, dtype=np.int64)  # the tick of each world's next replan
        self._last_tick = np.zeros(num, dtype=np.int64)
        self._folded: Any = env.last_info  # (the step report already in the beliefs)
        self.replans = np.zeros(num, dtype=np.int64)
        self.plans: list[Plan | None] = [None] * num

    def reset(self, rows: Any = None) -> None:
        """Start the worlds ``rows`` (default all) afresh: no belief, no routes, a replan due
        at once. :meth:`actions` calls it by itself for the worlds the env has reset."""
        rows = np.arange(self.env.num_envs) if rows is None else np.asarray(rows, dtype=np.int64)
        sc = self.env.scenario
        self.belief.reset(rows)
        self._routes.reset(rows)
        for b in rows.tolist():
            self._builders[b] = TaskGraphBuilder(sc, self.graph_params)
            self.plans[b] = None
        tick = self.env.batch.tick[rows]
        self._next[rows] = tick
        self._last_tick[rows] = tick
        self.replans[rows] = 0

    def actions(self, observations: dict[str, np.ndarray]) -> np.ndarray:
        """(B, N) int64 actions of every world for the current tick (0 in finished worlds)."""
        env, batch = self.env, self.env.batch
        if not env._started:
            raise EnvError("BatchPlanFollower.actions: reset the env first")
        tick = batch.tick
        fresh = np.flatnonzero(tick < self._last_tick)  # (worlds the env has reset)
        info = env.last_info
        if info is not None and info is not self._folded:
            self.belief.update(info, tick)
            self._folded = info
        if fresh.size:
            self.reset(fresh)
        self._last_tick = tick.copy()
        live = ~batch.done
        due = np.flatnonzero(live & (tick >= self._next))
        if due.size:
            self._replan(due)
        team = batch.team
        out = np.zeros((env.num_envs, len(self._ids)), dtype=np.int64)
        rows = np.flatnonzero(live)
        if rows.size:
            out[rows] = self._routes.choose(
                rows, observations["action_mask"], team.pos, team.z_target, team.mode,
                np.asarray(team.speed, dtype=np.float64), 5.0 * team.one.tick_scale,
            )  # fmt: skip
        return out

    def _replan(self, rows: np.ndarray) -> None:
        """Build the graphs of the worlds ``rows`` together, then plan each with its scheduler
        (:meth:`fcplan.mission.Mission.replan`'s steps, per world)."""
        batch = self.env.batch
        graphs = world_graphs(rows, self._builders, self._teams, batch, self.belief, self._block_px)
        rngs = [batch.controller_rngs[b] for b in rows.tolist()]
        assert all(r is not None for r in rngs)  # (set by every reset)
        who = (
            self.shared if self.shared is not None else [self.schedulers[b] for b in rows.tolist()]
        )
        plans = solve_batch(who, graphs, time_limit=self.time_limit, rngs=rngs)
        for b, graph, plan in zip(rows.tolist(), graphs, plans, strict=True):
            self.plans[b] = plan
            self.replans[b] += 1
            self._routes.follow(b, plan, graph)
            self._next[b] = int(batch.tick[b]) + self.period
