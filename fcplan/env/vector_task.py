"""Batched task level: ``B`` worlds of :class:`fcplan.env.task.TaskEnv` per call.

:class:`VectorTaskEnv` is a ``gymnasium.vector.VectorEnv``: one step is one replan period of
every world. World ``i`` is, observation for observation, reward for reward and episode for
episode, the single env of the same options (:class:`fcplan.env.gym_view.TaskGymEnv`;
``fcplan/Task-v1`` by default, ``fcplan/Task-v0`` with ``dump_altitude="watch"``) reset with seed ``s + i``
and then reset without a seed at each episode end (the task env's own seed sequence), what
``gymnasium.vector.SyncVectorEnv`` of that env gives, whatever ``B``.

==================  ============================================================================
Actions             ``(B, A)`` int: per world and agent a candidate slot ``0..k-1`` or ``k`` (the
                    no-op), batched ``MultiDiscrete``; masked slots act as the no-op
Observations        ``{"agents": (B, A, 17), "tasks": (B, A, k, 17), "action_mask":
                    (B, A, k + 1) int8}``, the task env's features stacked
Rewards             ``(B,)``: minus the manual's negative reward accrued during the step (plus
                    ``prune_bonus`` per cell put out)
Truncations         at the scenario's duration or ``max_steps``; ``terminations`` always False
Infos               ``tick`` ``(B,)``, ``illegal`` and ``conflict`` ``(B, A)``; at an episode's end
                    ``metrics`` and ``return`` (object arrays, ``_metrics``/``_return`` masks)
Autoreset           as :class:`fcplan.env.vector_motion.VectorMotionEnv`: ``"next_step"``
                    (default), ``"same_step"``, ``"disabled"`` (finished worlds held)
==================  ============================================================================

What is batched and what is not. The ticks of every world run in one
:class:`fcplan.batch.BatchWorld` (team, fire, sensing, dumps, facility counts and the reward's
counts: every per-tick array with a batch axis), and the team's belief of every world in one
:class:`fcplan.belief_batch.BatchBelief` (updated every tick from the batch's tick in a few
numpy calls; the coverage ages of the search blocks of all worlds computed together at each
replan). The task graphs' numpy work on ragged sets runs once for all worlds
(:func:`fcplan.taskgraph.build_batch.build_graphs`: the known cells of every world binned into
fire tiles by one sort, the tiles' boxes, counts and staleness, connected-fire labels, threat
distances and search values on flat arrays with a world index), and so do the ranked
candidates and the feature tables (:func:`fcplan.env.task_batch.batch_observe`: the ragged task
sets padded, the distance tables and the feasibility rule with a batch axis) and the decoding
of actions into one-point routes (:meth:`_commands`, applied by
:meth:`fcplan.batch.team.BatchTeam.go_to`). Each is tested bit for bit against the per-graph or
per-world code, which stays the specification. Per world and per step, in a loop over the
worlds, remain the graph objects themselves (:class:`fcplan.taskgraph.TaskGraph`: task ids,
the per-graph task arrays and distance tables, the threat's matrix product, and the whole
builder path of a graph without known fire), which the schedulers (:meth:`expert_actions`) and
the user read. ``bench/README.md`` measures the shares.

Options as :class:`~fcplan.env.task.TaskEnv`: ``k``, ``replan_period``, ``max_steps``,
``watch_altitude``, ``search_altitude``, ``dump_altitude``, ``prune_bonus``, ``validate``,
``graph_params`` (masked actions always act as the no-op, as in the Gymnasium view).

Examples
--------
>>> import numpy as np
>>> env = VectorTaskEnv("practice", num_envs=2, k=4)
>>> obs, infos = env.reset(seed=0)
>>> obs["tasks"].shape, obs["action_mask"].shape
((2, 4, 4, 17), (2, 4, 5))
>>> obs, rewards, terms, truncs, infos = env.step(np.full((2, 4), 4))  # everyone holds course
>>> infos["tick"].tolist()
[10, 10]
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from fcplan.batch import BatchStepInfo, BatchWorld
from fcplan.belief_batch import BatchBelief
from fcplan.env.action_input import integer_actions
from fcplan.env.task import TaskEnv
from fcplan.env.task_actions import (
    MappingCounts,
    decode_actions,
    plan_to_actions,
)
from fcplan.env.task_batch import batch_observe
from fcplan.env.vector_base import BatchedEnv, per_world_info, reset_rows, reset_seeds
from fcplan.errors import EnvError
from fcplan.metrics import facility_penalty, penalty_rate
from fcplan.mission import ScenarioLike
from fcplan.plan import validate_plan
from fcplan.scheduling import Scheduler
from fcplan.scheduling_batch import solve_batch
from fcplan.taskgraph import TaskGraph, TaskGraphBuilder, TaskGraphParams
from fcplan.taskgraph.build_batch import build_graphs
from fcplan.team import Team

__all__ = ["VectorTaskEnv", "TeamView", "world_graphs"]


class TeamView:
    """World ``b``'s team of a :class:`fcplan.batch.team.BatchTeam`, read as a
    :class:`fcplan.team.Team` (what the task graph builder reads)."""

    def __init__(self, team: Any, b: int) -> None:
        self._team, self._b = team, b
        #: the batch's range_px row of this world, set while the env builds its graph
        self._range: np.ndarray | None = None
        one = team.one
        self.ids, self.home, self.role = one.ids, one.home, one.role
        self.can_sense, self.can_act = one.can_sense, one.can_act
        self.alt_lo, self.alt_hi, self.speed = one.alt_lo, one.alt_hi, one.speed
        self.battery_capacity, self.tank_capacity = one.battery_capacity, one.tank_capacity

    def range_px(self) -> np.ndarray:
        """:meth:`fcplan.team.Team.range_px` (the batch's, computed for all worlds at once,
        while the env builds the graphs)."""
        if self._range is not None:
            return self._range
        out: np.ndarray = Team.range_px(self)  # type: ignore[arg-type]
        return out

    @property
    def pos(self) -> np.ndarray:
        return self._team.pos[self._b]

    @property
    def z(self) -> np.ndarray:
        return self._team.z[self._b]

    @property
    def battery(self) -> np.ndarray:
        return self._team.battery[self._b]

    @property
    def tank(self) -> np.ndarray:
        return self._team.tank[self._b]

    @property
    def mode(self) -> np.ndarray:
        return self._team.mode[self._b]


def world_graphs(rows: np.ndarray, builders: Sequence[TaskGraphBuilder], teams: Sequence[TeamView],
                 batch: BatchWorld, belief: BatchBelief, block_px: int) -> list[TaskGraph]:  # fmt: skip
    """The task graphs of the worlds ``rows`` of ``batch``, built together from their beliefs
    (:func:`fcplan.taskgraph.build_batch.build_graphs`; ``builders[b]`` and ``teams[b]`` are
    world ``b``'s; the agents' ranges computed once for all worlds)."""
    views = belief.views(rows, block_px)
    rows_l = rows.tolist()
    chosen = [teams[b] for b in rows_l]
    ranges = batch.team.range_px()
    for b, team in zip(rows_l, chosen, strict=True):
        team._range = ranges[b]
    try:
        return build_graphs([builders[b] for b in rows_l], chosen, views)
    finally:
        for team in chosen:
            team._range = None


class VectorTaskEnv(BatchedEnv):
    """``num_envs`` task-level worlds of ``scenario`` stepped together (module docstring)."""

    def __init__(
        self,
        scenario: ScenarioLike,
        num_envs: int = 1,
        *,
        autoreset_mode: str | AutoresetMode = "next_step",
        **kwargs: Any,
    ) -> None:
        self._setup(num_envs, autoreset_mode)
        if kwargs.get("render_mode") is not None or kwargs.get("reward_fn") is not None:
            raise EnvError("render_mode, reward_fn: not available in the batched task env")
        kwargs["illegal_action"] = "noop"
        #: the single env of the same options: its spaces and constants (it is never stepped)
        self.one = one = TaskEnv(scenario, **kwargs)
        self.scenario = sc = one.scenario
        b, a, k = self.num_envs, one.n_agents, one.k
        self.batch = BatchWorld(sc, b)
        sub = one.observation_space(one.possible_agents[0])
        lo, hi = float(sub["agent"].low.min()), float(sub["agent"].high.max())
        self.single_observation_space = spaces.Dict(
            {
                "agents": spaces.Box(lo, hi, (a, *sub["agent"].shape), np.float32),
                "tasks": spaces.Box(lo, hi, (a, *sub["tasks"].shape), np.float32),
                "action_mask": spaces.Box(0, 1, (a, k + 1), np.int8),
            }
        )
        self.single_action_space = spaces.MultiDiscrete(np.full(a, k + 1, dtype=np.int64))
        self.observation_space = batch_space(self.single_observation_space, b)
        self.action_space = batch_space(self.single_action_space, b)
        self.teams = [TeamView(self.batch.team, i) for i in range(b)]
        self._seed_seqs: list[np.random.SeedSequence | None] = [None] * b
        #: the team's belief of every world (one batch)
        self.belief = BatchBelief(sc, b)
        self._block_px = int((one.graph_params or TaskGraphParams()).search_block_px)
        self.builders = [TaskGraphBuilder(sc, one.graph_params) for _ in range(b)]
        self.graphs: list[Any] = [None] * b
        self.candidates: list[Any] = [None] * b
        self.steps = np.zeros(b, dtype=np.int64)
        self.returns = np.zeros(b)
        #: per world, agent and slot: the candidate's task row, position and kind (fire)
        self._slot_rows = np.full((b, a, k), -1, dtype=np.int64)
        self._slot_pos = np.zeros((b, a, k, 2))
        self._slot_fire = np.zeros((b, a, k), dtype=bool)
        self._slot_eta = np.zeros((b, a, k))
        self._role = self.batch.team.one.role.astype(np.int64)
        self._lower = np.tri(a, k=-1, dtype=bool)  # [i, j]: j < i
        self._goal = np.full((b, a, 2), np.nan)
        self._obs = {
            "agents": np.zeros((b, a, *sub["agent"].shape), np.float32),
            "tasks": np.zeros((b, a, *sub["tasks"].shape), np.float32),
            "action_mask": np.zeros((b, a, k + 1), np.int8),
        }

    # ------------------------------------------------------------------ episodes
    def reset(
        self, *, seed: int | list | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start episodes in every world, or in ``options["reset_mask"]``'s; ``seed`` as
        Gymnasium's vector envs take it (an int ``s``: ``s + b`` for world ``b``; a list: one
        seed per world; None: each world continues its seed sequence), or one seed per world
        reset (:func:`fcplan.env.vector_base.reset_seeds`)."""
        rows = reset_rows(self.num_envs, seed, options)
        self._reset_worlds(rows, reset_seeds(self.num_envs, rows, seed))
        self._started = True
        return self._observation(), {"tick": self.batch.tick.copy()}

    def _reset_worlds(self, rows: np.ndarray, seeds: list[Any]) -> None:
        """New episodes in the worlds ``rows`` (the task env's seed rule, per world)."""
        world_seeds = []
        for b, s in zip(rows.tolist(), seeds, strict=True):
            if s is not None:
                self._seed_seqs[b] = np.random.SeedSequence(s)
                world_seeds.append(s)
            else:
                if self._seed_seqs[b] is None:
                    self._seed_seqs[b] = np.random.SeedSequence()
                world_seeds.append(self._seed_seqs[b].spawn(1)[0])
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[rows] = True
        self.batch.reset(seeds=world_seeds, mask=mask)
        self._goal[rows] = np.nan
        self.belief.reset(rows)
        for b in rows.tolist():
            self.builders[b] = TaskGraphBuilder(self.scenario, self.one.graph_params)
        self._observe(rows)
        self.steps[rows] = 0
        self.returns[rows] = 0.0
        self._pending[rows] = False

    def _observe(self, rows: np.ndarray) -> None:
        """The graphs, candidates and observation rows of the worlds ``rows``
        (``TaskEnv._observe``; candidates and features of all of them at once,
        :func:`fcplan.env.task_batch.batch_observe`)."""
        if not rows.size:
            return
        rows_l = rows.tolist()
        graphs = world_graphs(
            rows, self.builders, self.teams, self.batch, self.belief, self._block_px
        )
        frac = self.batch.tick[rows] / max(self.scenario.n_ticks, 1)
        seen = batch_observe(graphs, self.one.k, self._goal[rows], frac)
        for b, graph, cand in zip(rows_l, graphs, seen.candidates, strict=True):
            self.graphs[b], self.candidates[b] = graph, cand
        self._obs["agents"][rows] = seen.agents
        self._obs["tasks"][rows] = seen.tasks
        mask = self._obs["action_mask"]
        mask[rows, :, :-1] = seen.valid
        mask[rows, :, -1] = 1
        self._slot_rows[rows] = seen.rows
        self._slot_pos[rows] = seen.slot_pos
        self._slot_fire[rows] = seen.slot_fire
        self._slot_eta[rows] = seen.slot_eta

    def _observation(self) -> dict[str, np.ndarray]:
        return {k: v.copy() for k, v in self._obs.items()}

    # ------------------------------------------------------------------ step
    def step(
        self, actions: Any
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One replan period of every world with ``actions`` ((B, A) ints)."""
        batch = self.batch
        run = self._stepping(batch.done | (self.steps >= self.one.max_steps))
        a = self.one.n_agents
        act = self.check_actions(actions)
        resets = ~run if self.autoreset_mode is AutoresetMode.NEXT_STEP else np.zeros_like(run)
        if np.count_nonzero(resets):
            self._reset_worlds(np.flatnonzero(resets), [None] * int(resets.sum()))
        illegal = np.zeros((self.num_envs, a), dtype=bool)
        conflict = np.zeros((self.num_envs, a), dtype=bool)
        self._commands(np.flatnonzero(run), act, illegal, conflict)
        start, pruned = batch.tick.copy(), batch.fire.n_pruned.copy()
        stop = np.where(run, np.minimum(start + self.one.period, batch.n_ticks), start)
        for _ in range(int((stop - start).max(initial=0))):
            info = batch.step(mask=batch.tick < stop)
            self._beliefs(info)
        rewards = self._rewards(run, start, stop, pruned)
        self.steps += run
        self.returns += rewards
        done = run & (batch.done | (self.steps >= self.one.max_steps))
        self._observe(np.flatnonzero(run))
        infos: dict[str, Any] = {
            "tick": batch.tick.copy(),
            "illegal": illegal,
            "conflict": conflict,
        }
        if np.count_nonzero(done):
            self._finals(done, infos)
        obs = self._observation()
        if self.autoreset_mode is AutoresetMode.SAME_STEP and np.count_nonzero(done):
            final, mask = per_world_info(done, lambda b: {k: v[b] for k, v in obs.items()})
            infos.update(final_obs=final, _final_obs=mask)
            self._reset_worlds(np.flatnonzero(done), [None] * int(done.sum()))
            obs = self._observation()
        self._ended(done)
        return obs, rewards, np.zeros(self.num_envs, dtype=bool), done, infos

    def check_actions(self, actions: Any, num: int | None = None) -> np.ndarray:
        """``(num, A)`` int64 actions (``num`` default ``B``; any integer: a slot out of range
        acts as the no-op and is reported ``illegal``)."""
        b = self.num_envs if num is None else int(num)
        return integer_actions(actions, (b, self.one.n_agents))

    def _commands(
        self, worlds: np.ndarray, act: np.ndarray, illegal: np.ndarray, conflict: np.ndarray
    ) -> None:
        """Decode the actions of ``worlds`` into commands and apply them: ``_command`` of each
        world, as array operations over all of them.

        A slot's action sends the agent to the slot's task if the slot is valid (else the no-op;
        an action other than ``k`` is then illegal). When agents of one role chose the same task,
        the first to arrive keeps it (ties: the lower agent row) and the others lose it
        (:func:`fcplan.env.task_actions.decode_actions`' rule: agent ``i`` loses when another
        agent ``j`` of its group comes before it in (arrival time, row) order). The one-point
        routes are applied by :meth:`fcplan.batch.team.BatchTeam.go_to`. A valid slot always
        holds a legal task (the candidates are ranked among the legal ones), so ``_command``'s
        plan validation never applies to them.
        """
        one, k = self.one, self.one.k
        if not worlds.size:
            return
        a = act[worlds]
        s = np.clip(a, 0, k - 1)[:, :, None]
        ok = (a >= 0) & (a < k)
        ok &= np.take_along_axis(self._obs["action_mask"][worlds], s, axis=2)[:, :, 0] == 1
        rows = np.where(ok, np.take_along_axis(self._slot_rows[worlds], s, axis=2)[:, :, 0], -1)
        illegal[worlds] = (rows < 0) & (a != k)
        sent = rows >= 0
        key = rows * 8 + self._role
        # same[:, i, j]: agents i and j (i != j) were both sent to one task with one role
        same = (key[:, :, None] == key[:, None, :]) & sent[:, :, None] & sent[:, None, :]
        same &= ~np.eye(len(self._role), dtype=bool)
        if same.any():
            eta = np.take_along_axis(self._slot_eta[worlds], s, axis=2)[:, :, 0]
            ei, ej = eta[:, :, None], eta[:, None, :]
            first = (ej < ei) | ((ej == ei) & self._lower)  # [:, i, j]: j comes before i
            lose = (same & first).any(axis=2)
            sent &= ~lose
            conflict[worlds] = lose
        else:
            conflict[worlds] = False
        n, i = np.nonzero(sent)
        w, slot = worlds[n], s[n, i, 0]
        goals = self._slot_pos[w, i, slot]
        team = self.batch.team
        fire = self._slot_fire[w, i, slot]
        alt = np.where(fire, one.watch_altitude, one.search_altitude)
        dumper = fire & team.can_act[i] & (team.tank[w, i] > 0)  # hybrids among the cameras
        dump = team.alt_hi[i] if one.dump_altitude is None else one.dump_altitude
        alt = np.where(dumper, dump, alt)
        alt = np.minimum(np.maximum(alt, team.alt_lo[i]), team.alt_hi[i])
        alt[~team.can_sense[i]] = np.nan
        self._goal[w, i] = goals
        team.go_to(w, i, goals, alt)

    def _command(self, b: int, act: np.ndarray, illegal: np.ndarray, conflict: np.ndarray) -> None:
        """Decode world ``b``'s actions into commands (``TaskEnv.step``) and apply them: the
        per-world rule, which :meth:`_commands` computes for all worlds at once (the tests
        compare them)."""
        one, graph, cand = self.one, self.graphs[b], self.candidates[b]
        rows, ill, con = decode_actions(graph, cand, act.tolist(), illegal="noop")
        illegal[b], conflict[b] = ill, con
        rows_l = rows.tolist()
        sent = [i for i, t in enumerate(rows_l) if t >= 0]
        if sent and one.validate and not all(cand.legal[i, rows_l[i]] for i in sent):
            validate_plan(one.rows_plan(graph, rows), graph)
        commands, pos = one.rows_commands(graph, rows_l)
        for i, p in zip(sent, pos, strict=True):
            self._goal[b, i] = p
        self.batch.team.apply(b, commands)

    def _beliefs(self, info: BatchStepInfo) -> None:
        """Fold the tick into the belief of every world that ran it (one batched update)."""
        self.belief.update(info, self.batch.tick)

    def _rewards(
        self, run: np.ndarray, start: np.ndarray, stop: np.ndarray, pruned: np.ndarray
    ) -> np.ndarray:
        """(B,) reward of the step: ``PenaltyReward`` over the step's ticks, plus shaping."""
        batch = self.batch
        w, tps = self.scenario.scoring.propagation_weight, float(self.scenario.ticks_per_second)
        out = np.zeros(self.num_envs)
        pen = batch.facility_penalties
        for b in np.flatnonzero(run).tolist():
            s, e = int(start[b]), int(stop[b])
            if e - s == 1:  # (the world's counts are the tick's trace row)
                active, in_fac = int(batch.fire.n_burning[b]), batch.facility_burning[b]
            else:
                active = int(batch.trace_sum(b, "active", s, e))
                in_fac = batch.trace_sum(b, "facility_burning", s, e)
            rate = penalty_rate(active, facility_penalty(in_fac, pen), w)
            out[b] = -rate / tps + self.one.prune_bonus * int(batch.fire.n_pruned[b] - pruned[b])
        return out

    def expert_actions(
        self,
        schedulers: Scheduler | Sequence[Scheduler],
        *,
        time_limit: float | None = None,
        counts: MappingCounts | Sequence[MappingCounts] | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(B, A) actions of a scheduler's plans on every world's current graph, and (B,) bool:
        the plan came from the greedy fallback.

        ``schedulers`` is one instance per world (a scheduler that keeps state between calls
        sees only its own world), or one instance for every world: the worlds' graphs are then
        planned in one call when it has ``plan_batch`` (greedy does), else in turn
        (:func:`fcplan.scheduling_batch.solve_batch`, with each world's controller generator,
        as :func:`fcplan.env.demonstrations.demonstrations` does on one env). Each plan becomes
        actions by :func:`fcplan.env.task_actions.plan_to_actions`, counted in ``counts`` (one
        for all the worlds, or one per world).
        """
        a, k = self.one.n_agents, self.one.k
        out = np.full((self.num_envs, a), k, dtype=np.int64)
        rngs = list(self.batch.controller_rngs)
        assert all(r is not None for r in rngs)  # (set by every reset)
        plans = solve_batch(schedulers, self.graphs, time_limit=time_limit, rngs=rngs)  # type: ignore[arg-type]
        fallback = np.array([getattr(p.stats, "status", None) == "fallback" for p in plans])
        for b, plan in enumerate(plans):
            c = counts if counts is None or isinstance(counts, MappingCounts) else counts[b]
            out[b] = plan_to_actions(plan, self.graphs[b], self.candidates[b], c)
        return out, fallback

    def _finals(self, done: np.ndarray, infos: dict[str, Any]) -> None:
        def metrics(b: int) -> dict[str, Any]:
            return {n: m.as_dict() for n, m in self.batch.metrics(b).items()}

        infos["metrics"], infos["_metrics"] = per_world_info(done, metrics)
        infos["return"], infos["_return"] = per_world_info(done, lambda b: float(self.returns[b]))
