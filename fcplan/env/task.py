"""Task-level FireCommander environment (PettingZoo ``ParallelEnv``): ``fcplan_task_v1``.

The team's scheduler, made learnable: every replan period each UAV picks one task of the current
task graph (:mod:`fcplan.taskgraph`) or no-op; the simulator (:class:`fcplan.world.World`, the
team's :class:`fcplan.belief.Belief`, together a :class:`fcplan.mission.Mission`) runs the resulting
:class:`fcplan.plan.Plan` until the next period. It is the replan loop of :func:`fcplan.run_episode`
(the same mission) with periodic replans only and the learner in place of the scheduler.

==================  ==================================================================
Import              ``from fcplan.env import parallel_env``
Agents              one per UAV, the scenario's ids (``"P1"``, ``"A1"``, ``"H1"`` ...)
Actions             ``Discrete(k + 1)``: slot ``0..k-1`` = candidate task, ``k`` = no-op
Observations        ``Dict(agent=Box(17,), tasks=Box(k, 17), action_mask=Box(k + 1,) int8)``
State               ``Box(17 A + 2 nb^2 + 4,)`` float32 (``nb`` = map side / 100 px), global,
                    for centralised critics (:meth:`TaskEnv.state`)
Reward              shared: minus the manual's negative reward accrued during the step
Episode end         truncation when the scenario's duration (or ``max_steps``) is reached
==================  ==================================================================

Arguments
---------
``scenario``
    A :class:`fcplan.scenario.Scenario` or a name/path for :func:`fcplan.load_scenario`.
``k`` (default 8)
    Candidate tasks per agent.
``replan_period`` (default 1.0)
    Simulated seconds per step (rounded to whole ticks, at least one).
``max_steps`` (default None)
    Truncate earlier than the scenario's duration (handy for tests).
``watch_altitude``, ``search_altitude`` (35 m, 70 m; in (0, 10000] m, as the schedulers')
    Altitudes given to agents with a camera sent to a fire / a search block.
``dump_altitude`` (default None)
    Altitude of a hybrid with water sent to a fire (it dumps there): None, the ``task_v1`` rule
    and every built-in scheduler's, the top of its bounds
    (:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`); ``"watch"``, the ``task_v0`` rule,
    ``watch_altitude``; or a number of metres, clipped to its bounds.
``prune_bonus`` (default 0.0)
    Optional shaping: this much reward per cell put out during the step. Off by default, so the
    return is exactly minus the manual's total negative reward.
``illegal_action`` ("noop" or "raise")
    What a masked-out action does (see :mod:`fcplan.env.task_actions`).
``validate`` (default True)
    Check that every step's plan passes :func:`fcplan.plan.validate_plan`. The mask already
    guarantees it, so the check is vectorised: each chosen (agent, task) pair must be legal by
    :func:`~fcplan.env.task_candidates.legal_tasks` (validate_plan's arithmetic for one-task
    routes); a pair that is not sends the plan through ``validate_plan``, which raises
    :class:`fcplan.errors.PlanError` naming it. ``False`` skips the check.
``graph_params``
    :class:`fcplan.taskgraph.TaskGraphParams` for the task graph.
``reward_fn``
    The step's reward before shaping, a :class:`fcplan.env.reward.RewardFn` (default
    :class:`~fcplan.env.reward.PenaltyReward`: minus the manual's negative reward).
``render_mode``
    ``None`` or ``"rgb_array"`` (:func:`fcplan.render.render_frame` of the live world).

Candidates, mask and features
    :mod:`fcplan.env.task_candidates`: the ``k`` most relevant *legal* tasks of each agent by a
    deterministic ranking (value x freshness / (1 + flight time); agents with a camera get both
    fires and search blocks), the mask of legal slots (the no-op is always legal), and the
    ``k x F`` task-feature table (:data:`~fcplan.env.task_candidates.TASK_FEATURES`, padding rows
    zero) plus the agent's own-state vector
    (:data:`~fcplan.env.task_candidates.AGENT_FEATURES`). Features are float32 in ``[-10, 10]``.

Actions, no-op and conflicts
    :mod:`fcplan.env.task_actions`: a chosen slot sends the agent to that one task (replacing its
    route); the **no-op holds course** (the plan does not mention the agent: it keeps its route,
    keeps hovering, keeps going home). Two agents of the same role picking one task: the first to
    arrive keeps it, the other gets the no-op. The actions become commands (exactly
    ``plan_commands`` of the one-task ``Plan`` they describe, checked as ``validate`` says),
    applied on the step's first tick.

Reward
    ``r = -sum_ticks rate(t) / tps + prune_bonus * pruned``, with ``rate`` the manual's penalty rate
    (``0.1 |active| + sum_f PC_f n_f``, :mod:`fcplan.env.reward`), the same for every agent. Over
    an unshaped episode the rewards sum to minus the manual total negative reward (up to float
    rounding).

Termination and truncation
    No terminal state: every agent is truncated at the step that reaches the scenario's duration
    (or ``max_steps``). That step's ``infos[agent]["metrics"]`` holds
    ``compute_all(world.trace())`` as plain dicts (``"manual"``, ``"reference2020"``).

Infos (every step)
    ``tick``, ``illegal`` and ``conflict`` (this agent's action was replaced by the no-op),
    ``task`` (the task id it was sent to, or ``None``).

Seeding
    ``reset(seed=s)`` resets the world with seed ``s`` (the same fire as
    ``run_episode(..., seed=s)``); ``reset()`` without a seed continues a deterministic sequence
    spawned from the last seed. Same seed and actions give identical observations, rewards and
    metrics in any process. The environment itself draws nothing at random.

How it differs from ``run_episode`` with a scheduler
    one task per agent per step (the rest of a route is dropped: the agent hovers at its task
    until the next step), altitudes from the rule above, only periodic replans (no event
    replans), candidates limited to the top ``k``, conflicts resolved as above.
    :mod:`fcplan.env.demonstrations` measures the score difference.

Examples
--------
>>> from fcplan.env.task import TaskEnv
>>> env = TaskEnv("practice", k=4, max_steps=3)
>>> obs, infos = env.reset(seed=0)
>>> sorted(obs["P1"])
['action_mask', 'agent', 'tasks']
>>> noop = {a: env.k for a in env.agents}
>>> for _ in range(3):
...     obs, rew, term, trunc, infos = env.step(noop)
>>> all(trunc.values()), env.agents, sorted(infos["P1"]["metrics"])
(True, [], ['manual', 'reference2020'])
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pettingzoo import ParallelEnv

from fcplan.belief import Belief
from fcplan.env.action_input import integer_action
from fcplan.env.reward import PenaltyReward, RewardFn
from fcplan.env.task_actions import (
    actions_plan,
    altitude_option,
    decode_actions,
    resolve_dump_altitude,
    rows_commands,
)
from fcplan.env.task_candidates import (
    AGENT_FEATURES,
    FEATURE_BOUND,
    TASK_FEATURES,
    Candidates,
    agent_features,
    rank_candidates,
    task_features,
)
from fcplan.errors import EnvError
from fcplan.metrics import compute_all
from fcplan.mission import (
    Commands,
    Mission,
    ScenarioLike,
    as_scenario,
    check_replan_period,
    period_ticks,
)
from fcplan.plan import Plan, validate_plan
from fcplan.shared_views import KeepsViews
from fcplan.taskgraph import TaskGraph, TaskGraphParams
from fcplan.team import Command
from fcplan.world import World, check_seed

__all__ = ["TaskEnv"]


class TaskEnv(KeepsViews, ParallelEnv):
    """Task-level parallel environment (the module docstring is its documentation page)."""

    metadata = {
        "name": "fcplan_task_v1",
        "render_modes": ["rgb_array"],
        "is_parallelizable": True,
        "render_fps": 4,
    }

    def __init__(
        self,
        scenario: ScenarioLike,
        *,
        k: int = 8,
        replan_period: float = 1.0,
        max_steps: int | None = None,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        dump_altitude: float | str | None = None,
        prune_bonus: float = 0.0,
        illegal_action: str = "noop",
        validate: bool = True,
        graph_params: TaskGraphParams | None = None,
        render_mode: str | None = None,
        reward_fn: RewardFn | None = None,
    ) -> None:
        from gymnasium import spaces

        self.scenario = as_scenario(scenario)
        if not (isinstance(k, (int, np.integer)) and 1 <= k <= 1024):
            raise EnvError(f"k: must be an integer in 1..1024 (got {k!r})")
        replan_period = check_replan_period(replan_period, error=EnvError)
        if max_steps is not None and not (
            isinstance(max_steps, (int, np.integer)) and max_steps > 0
        ):
            raise EnvError(f"max_steps: must be a positive integer or None (got {max_steps!r})")
        if illegal_action not in ("noop", "raise"):
            raise EnvError(f"illegal_action: must be 'noop' or 'raise' (got {illegal_action!r})")
        if render_mode not in (None, "rgb_array"):
            raise EnvError(f"render_mode: must be None or 'rgb_array' (got {render_mode!r})")
        self.k = int(k)
        self.tps = self.scenario.ticks_per_second
        self.period = period_ticks(replan_period, self.tps)
        n_steps = -(-self.scenario.n_ticks // self.period)
        self.max_steps = n_steps if max_steps is None else min(int(max_steps), n_steps)
        self.watch_altitude = altitude_option("watch_altitude", watch_altitude)
        self.search_altitude = altitude_option("search_altitude", search_altitude)
        #: the resolved dump altitude: a number (``"watch"``: ``watch_altitude``) or None
        self.dump_altitude = resolve_dump_altitude(dump_altitude, self.watch_altitude)
        self.prune_bonus = float(prune_bonus)
        self.illegal_action = illegal_action
        self.validate = bool(validate)
        self.graph_params = graph_params
        self.render_mode = render_mode
        self.possible_agents = [a.id for a in self.scenario.agents]
        self.agents: list[str] = []
        self.n_agents = len(self.possible_agents)
        w = self.scenario.world_size
        self._nb = -(-w // 100)
        b = FEATURE_BOUND
        f, s = len(TASK_FEATURES), len(AGENT_FEATURES)
        self._obs_space = spaces.Dict(
            {
                "agent": spaces.Box(-b, b, (s,), np.float32),
                "tasks": spaces.Box(-b, b, (self.k, f), np.float32),
                "action_mask": spaces.Box(0, 1, (self.k + 1,), np.int8),
            }
        )
        self.observation_spaces = {a: self._obs_space for a in self.possible_agents}
        self.action_spaces = {a: spaces.Discrete(self.k + 1) for a in self.possible_agents}
        n_state = self.n_agents * s + 2 * self._nb * self._nb + 4
        self.state_space = spaces.Box(-b, b, (n_state,), np.float32)
        #: the episode: world, belief and the periodic replan rule (no event replans)
        self.mission = Mission(
            self.scenario,
            0,
            replan_period=replan_period,
            event_replans=False,
            graph_params=graph_params,
        )
        self.reward_fn: RewardFn = reward_fn or PenaltyReward()
        self._seed_seq: np.random.SeedSequence | None = None
        self.graph: TaskGraph | None = None
        self.candidates: Candidates | None = None

    def rows_plan(self, graph: TaskGraph, rows: np.ndarray) -> Plan:
        """The one-task plan of chosen task rows (``-1``: not mentioned) under this env's
        altitude settings (:func:`~fcplan.env.task_actions.actions_plan`)."""
        return actions_plan(
            graph,
            rows,
            watch_altitude=self.watch_altitude,
            search_altitude=self.search_altitude,
            dump_altitude=self.dump_altitude,
        )

    def rows_commands(
        self, graph: TaskGraph, rows: list[int]
    ) -> tuple[dict[str, Command], list[list[float]]]:
        """:func:`~fcplan.env.task_actions.rows_commands` under this env's altitude settings:
        the commands of chosen task rows and the task position of each agent sent."""
        return rows_commands(
            graph, rows, self.watch_altitude, self.search_altitude, self.dump_altitude
        )

    @property
    def world(self) -> World:
        """The live :class:`fcplan.world.World` (the mission's)."""
        return self.mission.world

    @property
    def belief(self) -> Belief:
        """The team's :class:`fcplan.belief.Belief` (the mission's)."""
        belief = self.mission.belief
        assert belief is not None  # (the mission keeps one)
        return belief

    # ------------------------------------------------------------------ spaces
    def observation_space(self, agent: str) -> Any:
        """The agent's observation space (the same object every call)."""
        return self.observation_spaces[agent]

    def action_space(self, agent: str) -> Any:
        """``Discrete(k + 1)`` (the same object every call)."""
        return self.action_spaces[agent]

    # ------------------------------------------------------------------ episode
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Start an episode; return ``(observations, infos)``.

        ``seed`` seeds the world exactly as ``World.reset(scenario, seed)``; without a seed the
        next seed of a deterministic sequence spawned from the last one is used (fresh OS
        entropy if no seed was ever given).
        """
        check_seed(seed, generator=False)  # (a one-line SeedError, not numpy's)
        if seed is not None:
            self._seed_seq = np.random.SeedSequence(seed)
            world_seed: Any = seed
        else:
            if self._seed_seq is None:
                self._seed_seq = np.random.SeedSequence()
            world_seed = self._seed_seq.spawn(1)[0]
        self.mission.reset(world_seed)
        self.reward_fn.reset(self.world)
        self.agents = list(self.possible_agents)
        self.steps = 0
        self.return_ = 0.0
        self._goal = np.full((self.n_agents, 2), np.nan)
        self._rows = np.full(self.n_agents, -1, dtype=np.int64)
        self._observe()
        infos = {a: {"tick": 0} for a in self.agents}
        return self._obs, infos

    def step(self, actions: dict[str, int]) -> tuple[dict[str, Any], ...]:
        """Apply one action per live agent (missing agents: no-op) and run one replan period.

        Returns ``(observations, rewards, terminations, truncations, infos)``.
        """
        if not self.agents:
            raise EnvError("step: the episode is over; call reset() first")
        graph, cand = self.graph, self.candidates
        assert graph is not None and cand is not None  # (built by reset)
        noop = self.k
        # (a list of Python ints: decode_actions' fast path, though its annotation says ndarray)
        act: Any = [
            noop if (x := actions.get(a)) is None else integer_action(x, f"action of {a}")
            for a in self.possible_agents
        ]
        rows, illegal, conflict = decode_actions(graph, cand, act, illegal=self.illegal_action)
        # a handful of agents: plain Python lists from here
        rows_l = rows.tolist()
        sent = [i for i, t in enumerate(rows_l) if t >= 0]
        if sent and self.validate:
            legal = cand.legal
            if not all(legal[i, rows_l[i]] for i in sent):
                # legal_tasks is validate_plan's arithmetic for one-task routes: only a bug gets
                # here, and validate_plan names the offending agent and task
                validate_plan(self.rows_plan(graph, rows), graph)
        commands, pos = self.rows_commands(graph, rows_l)
        goal = self._goal
        for i, p in zip(sent, pos, strict=True):
            goal[i] = p
        self._rows = rows
        reward = self._advance(commands)
        self.steps += 1
        self.return_ += reward
        done = self.world.done or self.steps >= self.max_steps
        self._observe()
        agents = self.agents
        rewards = dict.fromkeys(agents, reward)
        terms = dict.fromkeys(agents, False)
        truncs = dict.fromkeys(agents, done)
        tids, tick = graph.task_ids, self.world.tick
        illegal_l, conflict_l = illegal.tolist(), conflict.tolist()
        infos = {
            a: {
                "tick": tick,
                "illegal": illegal_l[i],
                "conflict": conflict_l[i],
                "task": tids[rows_l[i]] if rows_l[i] >= 0 else None,
            }
            for i, a in enumerate(agents)
        }
        if done:
            metrics = {n: m.as_dict() for n, m in compute_all(self.world.trace()).items()}
            for a in agents:
                infos[a]["metrics"] = metrics
                infos[a]["return"] = self.return_
            self.agents = []
        return self._obs, rewards, terms, truncs, infos

    def _advance(self, commands: Commands) -> float:
        """Run one period of ticks (cut at the scenario's end); return the step's reward."""
        world = self.world
        start, pruned = world.tick, world.fire.n_pruned
        self.mission.advance(self.period, commands)
        # cells put out during the step: the change of the fire's count (the sum of every tick's
        # info.pruned)
        return self.reward_fn(world, start) + self.prune_bonus * (world.fire.n_pruned - pruned)

    def _observe(self) -> None:
        """Build the graph, candidates and observations of the current tick."""
        self.graph = self.mission.task_graph()
        self.candidates = rank_candidates(self.graph, self.k)
        frac = self.world.tick / max(self.scenario.n_ticks, 1)
        self._agent_obs = agent_features(self.graph, self.candidates, frac)
        self._task_obs = task_features(self.graph, self.candidates, self._goal)
        self._mask = self.candidates.action_mask()
        self._obs = {
            a: {
                "agent": self._agent_obs[i],
                "tasks": self._task_obs[i],
                "action_mask": self._mask[i],
            }
            for i, a in enumerate(self.possible_agents)
        }

    # ------------------------------------------------------------------ extras
    def state(self) -> np.ndarray:
        """Global state for centralised critics, float32 ``(N,)``:

        every agent's own-state vector (scenario order), the known burning cells per 100-px
        block (``nb x nb``, share of the block), the **true** burning cells per block (privileged
        information the agents do not observe), then elapsed fraction, log1p of true burning,
        pruned and known cells / 10.
        """
        nb, w = self._nb, self.scenario.world_size
        known = np.zeros(nb * nb)
        k = self.belief.known
        if k.size:
            bx, by = (k // w) // 100, (k % w) // 100
            known = np.bincount(bx * nb + by, minlength=nb * nb).astype(np.float64)
        true_xy = self.world.fire.burning_cells()
        true = np.zeros(nb * nb)
        if len(true_xy):
            true = np.bincount(
                (true_xy[:, 0] // 100) * nb + true_xy[:, 1] // 100, minlength=nb * nb
            ).astype(np.float64)
        fire = self.world.fire
        scalars = [
            self.world.tick / max(self.scenario.n_ticks, 1),
            np.log1p(fire.n_burning) / 10.0,
            np.log1p(fire.n_pruned) / 10.0,
            np.log1p(k.size) / 10.0,
        ]
        out = np.concatenate(
            [self._agent_obs.ravel(), known / 1e4, true / 1e4, np.asarray(scalars)]
        ).astype(np.float32)
        return np.clip(out, -FEATURE_BOUND, FEATURE_BOUND)

    def render(self) -> np.ndarray | None:
        """An ``(H, W, 3)`` uint8 image of the map, known fire, agents, their fields of view and
        the goals still ahead, with the information panel (``render_mode="rgb_array"``; drawn
        by :func:`fcplan.render.render_frame`), else None."""
        if self.render_mode != "rgb_array":
            return None
        from fcplan.render import render_frame, snapshot

        frame = snapshot(self.world, self.belief, scores={"return": self.return_})
        return render_frame(self.scenario, frame)

    def close(self) -> None:
        """Nothing to release."""
