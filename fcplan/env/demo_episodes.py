"""Task-level episodes of a demonstrations dataset: a scheduler's rollouts and human games.

An :class:`EpisodeRecord` is one episode as the centralised task-level env
(:class:`fcplan.env.gym_view.TaskGymEnv` with the dataset's env options, ``fcplan/Task-v1`` by
default) sees it: ``T + 1`` joint observations (``agents`` ``(A, 17)``, ``tasks``
``(A, k, 17)``, ``action_mask`` ``(A, k + 1)``),
``T`` joint actions, rewards and per-step infos, plus the episode's scenario, seed, source and
final metrics. :mod:`fcplan.env.demonstrations` flattens records into its npz rows and
:mod:`fcplan.env.demo_minari` writes them as Minari episodes.

Two sources:

* :func:`rollout_episode`: a scheduler plans on the env's graph every step and its plan becomes
  the env's actions (:func:`fcplan.env.task_actions.plan_to_actions`); replaying the actions
  through a fresh env with the seed gives the episode again, metrics included.
* :func:`recording_episode`: a recorded game (:class:`fcplan.recording.Recording`, e.g. a human's,
  ``source="human"``) re-simulated tick for tick with its own commands, observed every replan
  period as the env would observe it (the same belief, graph, candidates and features). The
  action of an agent is the candidate slot nearest to the first goal of the first route the
  player gave it during the period (the no-op when the player gave it none, or sent it home).
  The rewards and metrics are those of the game itself. The player's commands are richer than
  the env's actions (several goals, any point, any time), so replaying these actions through the
  env plays a different episode: the record is what the player saw and chose, not an env rollout.

Examples
--------
>>> from fcplan.env.task import TaskEnv
>>> from fcplan import make_scheduler
>>> env = TaskEnv("practice", k=4, max_steps=3)
>>> ep = rollout_episode(env, make_scheduler("greedy"), "practice", 0)
>>> ep.actions.shape, ep.observations["tasks"].shape, ep.source
((3, 4), (4, 4, 4, 17), 'greedy')
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fcplan.env.task import TaskEnv
from fcplan.env.task_actions import MappingCounts, plan_to_actions
from fcplan.env.task_candidates import agent_features, rank_candidates, task_features
from fcplan.metrics import facility_penalty, penalty_rate
from fcplan.mission import Mission
from fcplan.scheduling import Scheduler, solve
from fcplan.taskgraph import TaskKind

__all__ = ["EpisodeRecord", "rollout_episode", "recording_episode", "OBS_KEYS"]
__all__ += ["batched_rollouts", "scenario_from_metadata", "env_kwargs_from_metadata",
            "episode_mapping"]  # fmt: skip

#: the keys of a joint observation (the Gymnasium view's)
OBS_KEYS = ("agents", "tasks", "action_mask")
_FIRE = int(TaskKind.FIRE)


@dataclass(eq=False)
class EpisodeRecord:
    """One task-level episode (module docstring).

    Attributes
    ----------
    observations : dict of str -> ndarray
        ``(T + 1, ...)`` per key of :data:`OBS_KEYS`.
    actions : ndarray, (T, A) int64
    rewards : ndarray, (T,) float64
    ticks : ndarray, (T + 1,) int64
        The tick of each observation.
    illegal, conflict : ndarray, (T, A) bool
    scenario, seed, source : str, int, str
    metrics : dict
        Final metrics (``{"manual": {...}, "reference2020": {...}}``).
    fallbacks : int
        Steps whose plan came from the greedy fallback (scheduler rollouts).
    counts : dict
        How the episode's plans mapped onto actions (:class:`fcplan.env.task_actions.MappingCounts`;
        scheduler rollouts; empty for a recorded game).
    """

    observations: dict[str, np.ndarray]
    actions: np.ndarray
    rewards: np.ndarray
    ticks: np.ndarray
    illegal: np.ndarray
    conflict: np.ndarray
    scenario: str
    seed: int
    source: str
    metrics: dict[str, Any] = field(default_factory=dict)
    fallbacks: int = 0
    counts: dict[str, int] = field(default_factory=dict)

    @property
    def steps(self) -> int:
        """Steps ``T``."""
        return int(self.actions.shape[0])

    @property
    def return_(self) -> float:
        """Sum of the rewards, in step order."""
        total = 0.0
        for r in self.rewards.tolist():
            total += r
        return total


def _joint_obs(env: TaskEnv) -> dict[str, np.ndarray]:
    return {"agents": env._agent_obs, "tasks": env._task_obs, "action_mask": env._mask}


def rollout_episode(
    env: TaskEnv,
    scheduler: Scheduler,
    scenario_key: str,
    seed: int,
    *,
    time_limit: float | None = None,
    counts: MappingCounts | None = None,
) -> EpisodeRecord:
    """One episode of ``env`` with ``seed``, ``scheduler`` choosing the actions every step (its
    mapping counts in the record's ``counts``, and added to ``counts`` when given)."""
    ids = env.possible_agents
    own = MappingCounts()
    env.reset(seed=seed)
    rng = env.world.controller_rng
    obs, acts, rews, ticks, ill, con = [_joint_obs(env)], [], [], [0], [], []
    infos: dict[str, Any] = {}
    fallbacks = 0
    while env.agents:
        graph, cand = env.graph, env.candidates
        assert graph is not None and cand is not None  # (built by reset and step)
        plan = solve(scheduler, graph, time_limit=time_limit, rng=rng)
        fallbacks += getattr(plan.stats, "status", None) == "fallback"
        act = plan_to_actions(plan, graph, cand, own)
        _, rew, _, _, infos = env.step(dict(zip(ids, act.tolist(), strict=True)))
        acts.append(act)
        rews.append(rew[ids[0]])
        obs.append(_joint_obs(env))
        ticks.append(infos[ids[0]]["tick"])
        ill.append([infos[a]["illegal"] for a in ids])
        con.append([infos[a]["conflict"] for a in ids])
    rec = _record(obs, acts, rews, ticks, ill, con, scenario_key, seed, _name(scheduler))
    rec.metrics = infos[ids[0]]["metrics"]
    rec.fallbacks = fallbacks
    rec.counts = _count(own, counts)
    return rec


def _count(own: MappingCounts, total: MappingCounts | None) -> dict[str, int]:
    """An episode's mapping counts as a plain dict, added to ``total`` when given."""
    if total is not None:
        total.add(own)
    return dict(own)


def batched_rollouts(
    env: Any,
    schedulers: Scheduler | Sequence[Scheduler],
    scenario_key: str,
    seeds: Sequence[int],
    *,
    time_limit: float | None = None,
    counts: MappingCounts | None = None,
) -> list[EpisodeRecord]:
    """:func:`rollout_episode` of ``len(seeds)`` seeds at once in a
    :class:`fcplan.env.vector_task.VectorTaskEnv` of as many worlds (``autoreset_mode=
    "disabled"``): world ``b`` plays seed ``seeds[b]`` with ``schedulers[b]``
    (:meth:`~fcplan.env.vector_task.VectorTaskEnv.expert_actions`; one instance for every world
    is planned batched when it can be). Each record equals the sequential rollout of its seed
    (with a scheduler that keeps no state between episodes), its own mapping counts too."""
    n = len(seeds)
    own = [MappingCounts() for _ in range(n)]
    names = [_name(schedulers if not isinstance(schedulers, Sequence) else schedulers[b])
             for b in range(n)]  # fmt: skip
    obs, _ = env.reset(seed=[int(s) for s in seeds])
    keep: list[dict[str, np.ndarray]] = [obs]
    acts, rews, ticks, ill, con = [], [], [env.batch.tick.copy()], [], []
    falls = np.zeros(n, dtype=np.int64)
    done = np.zeros(n, dtype=bool)
    finals: list[Any] = [None] * n
    ends = np.zeros(n, dtype=np.int64)  # steps of each world's episode
    while not done.all():
        held = MappingCounts()  # (a held world's plans are not its episode's)
        per = [held if done[b] else own[b] for b in range(n)]
        act, fb = env.expert_actions(schedulers, time_limit=time_limit, counts=per)
        falls += fb & ~done
        obs, rew, _, trunc, info = env.step(act)
        keep.append(obs)
        acts.append(act)
        rews.append(rew)
        ticks.append(info["tick"])
        ill.append(info["illegal"])
        con.append(info["conflict"])
        for b in np.flatnonzero(trunc).tolist():
            finals[b], ends[b] = info["metrics"][b], len(acts)
        done |= trunc
    out = []
    for b, seed in enumerate(seeds):
        e = int(ends[b])
        rec = _record([{k: o[k][b] for k in OBS_KEYS} for o in keep[: e + 1]],
                      [x[b] for x in acts[:e]], [x[b] for x in rews[:e]],
                      [x[b] for x in ticks[: e + 1]], [x[b] for x in ill[:e]],
                      [x[b] for x in con[:e]], scenario_key, seed, names[b])  # fmt: skip
        rec.metrics, rec.fallbacks = finals[b], int(falls[b])
        rec.counts = _count(own[b], counts)
        out.append(rec)
    return out


def _name(scheduler: Any) -> str:
    return str(getattr(scheduler, "name", type(scheduler).__name__))


def _record(obs: list, acts: list, rews: list, ticks: list, ill: list, con: list,
            scenario: str, seed: int, source: str) -> EpisodeRecord:  # fmt: skip
    n_a = obs[0]["agents"].shape[0]
    return EpisodeRecord(
        observations={k: np.stack([o[k] for o in obs]) for k in OBS_KEYS},
        actions=np.array(acts, dtype=np.int64).reshape(-1, n_a),
        rewards=np.array(rews, dtype=np.float64),
        ticks=np.array(ticks, dtype=np.int64),
        illegal=np.array(ill, dtype=bool).reshape(-1, n_a),
        conflict=np.array(con, dtype=bool).reshape(-1, n_a),
        scenario=scenario,
        seed=int(seed),
        source=source,
    )


def recording_episode(recording: Any, env: TaskEnv, scenario_key: str) -> EpisodeRecord:
    """A recorded game as a task-level episode of ``env``'s options (module docstring).

    Raises
    ------
    fcplan.recording.RecordingError
        If the recording has no integer seed (it cannot be re-simulated).
    """
    from fcplan.recording import RecordingError

    if recording.seed is None:
        raise RecordingError(
            f"recording ({recording.source}): no integer seed, cannot be re-simulated"
        )
    sc, k, period = env.scenario, env.k, env.period
    mission = Mission(sc, recording.seed, replan_period=period / sc.ticks_per_second,
                      event_replans=False, graph_params=env.graph_params)  # fmt: skip
    by_tick = recording.commands()
    trace = recording.trace()
    n_a, n_ticks = len(sc.agents), min(recording.n_ticks, sc.n_ticks)
    goal = np.full((n_a, 2), np.nan)
    obs, acts, rews, ticks, ill, con = [], [], [], [], [], []
    for start in range(0, n_ticks, period):
        graph, cand, seen = _observe(mission, k, goal)
        obs.append(seen)
        ticks.append(start)
        stop = min(start + period, n_ticks)
        given = [by_tick.get(t, {}) for t in range(start, stop)]
        act = _player_actions(graph, cand, given, goal)
        acts.append(act)
        ill.append([False] * n_a)
        con.append([False] * n_a)
        for t in range(start, stop):
            mission.step(by_tick.get(t))
        rews.append(_period_reward(trace, start, stop, sc))
    obs.append(_observe(mission, k, goal)[2])
    ticks.append(n_ticks)
    rec = _record(obs, acts, rews, ticks, ill, con, scenario_key, recording.seed, recording.source)
    rec.metrics = {n: m.as_dict() for n, m in recording.metrics().items()}
    return rec


def _observe(mission: Mission, k: int, goal: np.ndarray) -> tuple[Any, Any, dict[str, np.ndarray]]:
    """The mission's graph and candidates now, and the env's joint observation of them."""
    graph = mission.task_graph()
    cand = rank_candidates(graph, k)
    frac = mission.world.tick / max(mission.scenario.n_ticks, 1)
    obs = {
        "agents": agent_features(graph, cand, frac),
        "tasks": task_features(graph, cand, goal),
        "action_mask": cand.action_mask(),
    }
    return graph, cand, obs


def _player_actions(graph: Any, cand: Any, given: list, goal: np.ndarray) -> np.ndarray:
    """(A,) actions: per agent the candidate slot nearest to the first goal of the first route
    the player gave it in the period (no-op: none given, or sent home); updates ``goal``."""
    n_a, k = cand.rows.shape
    out = np.full(n_a, k, dtype=np.int64)
    for i, agent in enumerate(graph.agent_ids):
        cmd = next(
            (c[agent] for c in given if agent in c and (c[agent].home or c[agent].route)), None
        )
        if cmd is None or cmd.home or not cand.valid[i].any():
            continue
        target = np.asarray(cmd.route[0], dtype=np.float64)
        p = graph.task_pos[np.maximum(cand.rows[i], 0)]
        d = np.where(cand.valid[i], np.hypot(*(p - target).T), np.inf)
        out[i] = slot = int(np.argmin(d))
        goal[i] = p[slot]
    return out


def _period_reward(trace: Any, start: int, stop: int, sc: Any) -> float:
    """Minus the manual's negative reward of ticks ``start + 1 .. stop`` (the env's reward)."""
    active = int(trace.active[start:stop].sum())
    in_fac = trace.facility_burning[start:stop].sum(axis=0)
    pen = np.array([f.penalty for f in sc.scored_facilities], dtype=np.float64)
    rate = penalty_rate(active, facility_penalty(in_fac, pen), sc.scoring.propagation_weight)
    return -rate / float(sc.ticks_per_second)


def episode_mapping(rec: EpisodeRecord) -> dict[str, Any]:
    """How episode ``rec``'s plans became actions, for its entry in a dataset's metadata:
    ``mapping`` (its :class:`~fcplan.env.task_actions.MappingCounts` as a dict; empty for a
    recorded game), ``conflicts`` (agent-steps whose action the env's conflict rule changed)
    and ``fallbacks`` (steps planned by the greedy fallback). The dataset's totals are their
    sums, so a user can leave out the episodes whose plans the env could not follow."""
    return {
        "mapping": {k: int(v) for k, v in sorted(rec.counts.items())},
        "conflicts": int(rec.conflict.sum()),
        "fallbacks": int(rec.fallbacks),
    }


def scenario_from_metadata(metadata: dict[str, Any], key: str) -> Any:
    """The scenario stored under ``key`` in a dataset's metadata (no file needed)."""
    from fcplan.scenario import Scenario

    return Scenario.from_dict(metadata["scenarios"][key])


def env_kwargs_from_metadata(metadata: dict[str, Any]) -> dict[str, Any]:
    """The task env's keyword arguments stored in a dataset's metadata (a dataset that names no
    ``dump_altitude`` was written when the env's default was ``"watch"``, ``task_v0``'s rule)."""
    kwargs = dict(metadata["env_kwargs"])
    kwargs.setdefault("dump_altitude", "watch")
    if kwargs.get("graph_params") is not None:
        from fcplan.taskgraph import TaskGraphParams

        gp = dict(kwargs["graph_params"])
        if gp.get("tile_px") is not None:
            gp["tile_px"] = tuple(gp["tile_px"])
        kwargs["graph_params"] = TaskGraphParams(**gp)
    return kwargs
