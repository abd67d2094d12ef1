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
(:func:`fcplan.taskgraph.build_batch.build_graphs`). Per world, in a loop: the scheduler (one
instance per world, through :func:`fcplan.scheduling.solve` with the world's controller
generator, so a failing solver falls back to greedy) and the move rule
(:class:`fcplan.env.motion_expert.TeamRoutes`, the single follower's own), a few Python
operations per agent. Worlds that finish are skipped (their actions are 0: the env ignores
them) and start afresh when the env resets them. The per-world schedulers are most of the cost:
with greedy on #1, rollouts of 256 worlds run about 2x the single env with
:class:`~fcplan.env.motion_expert.PlanFollower`, the expert taking three quarters of the time,
most of it in the greedy solves (``bench/bench_vector_expert.py``, ``bench/README.md``).

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
from fcplan.env.motion_expert import TeamRoutes
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import TeamView, world_graphs
from fcplan.errors import EnvError
from fcplan.mission import period_ticks
from fcplan.plan import Plan
from fcplan.scheduling import Scheduler, make_scheduler, solve
from fcplan.taskgraph import TaskGraphBuilder, TaskGraphParams

__all__ = ["BatchPlanFollower"]


class BatchPlanFollower:
    """Plans turned into moves in every world of a batched motion env (module docstring).

    Parameters
    ----------
    env : VectorMotionEnv
    scheduler : str, Scheduler or sequence of Scheduler
        A registered scheduler name or spec (one instance is made per world), or one instance
        per world (a scheduler that keeps state between calls sees only its own world).
    replan_period, time_limit, graph_params
        As :class:`fcplan.env.motion_expert.PlanFollower`.

    Attributes
    ----------
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
        if not replan_period > 0:
            raise EnvError(f"replan_period: must be > 0 simulated seconds (got {replan_period!r})")
        self.env, num = env, env.num_envs
        if isinstance(scheduler, str):
            self.schedulers: list[Scheduler] = [make_scheduler(scheduler) for _ in range(num)]
        elif isinstance(scheduler, (list, tuple)):
            self.schedulers = list(scheduler)
            if len(self.schedulers) != num:
                raise EnvError(
                    f"scheduler: need {num} schedulers, one per world (got {len(self.schedulers)})"
                )
        elif num == 1:
            self.schedulers = [cast(Scheduler, scheduler)]
        else:
            raise EnvError(
                "scheduler: give a name or one instance per world (an instance would be shared "
                "by the worlds)"
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
        self._routes = [TeamRoutes(self._ids, sc) for _ in range(num)]
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
        for b in rows.tolist():
            self._routes[b] = TeamRoutes(self._ids, sc)
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
        masks = observations["action_mask"]
        climb = 5.0 * team.one.tick_scale
        speed = team.speed.tolist()
        for b in np.flatnonzero(live).tolist():
            chosen = self._routes[b].choose(
                dict(zip(self._ids, masks[b], strict=True)), team.pos[b].tolist(),
                team.z_target[b].tolist(), team.mode[b].tolist(), speed, climb,
            )  # fmt: skip
            out[b] = [chosen[a] for a in self._ids]
        return out

    def _replan(self, rows: np.ndarray) -> None:
        """Build the graphs of the worlds ``rows`` together, then plan each with its scheduler
        (:meth:`fcplan.mission.Mission.replan`'s steps, per world)."""
        batch = self.env.batch
        graphs = world_graphs(rows, self._builders, self._teams, batch, self.belief, self._block_px)
        for b, graph in zip(rows.tolist(), graphs, strict=True):
            rng = batch.controller_rngs[b]
            assert rng is not None  # (set by every reset)
            plan = solve(self.schedulers[b], graph, time_limit=self.time_limit, rng=rng)
            self.plans[b] = plan
            self.replans[b] += 1
            self._routes[b].follow(plan, graph)
            self._next[b] = int(batch.tick[b]) + self.period
