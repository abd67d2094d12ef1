"""Batched motion level: ``B`` worlds of :class:`fcplan.env.motion.MotionEnv` in one call.

:class:`VectorMotionEnv` is a ``gymnasium.vector.VectorEnv`` on a :class:`fcplan.batch.BatchWorld`:
one :meth:`~VectorMotionEnv.step` advances every world one tick. World ``i`` is, observation for
observation and reward for reward, the centralised single env ``fcplan/Motion-v0``
(:class:`fcplan.env.joint_gym.JointGymEnv` on a :class:`~fcplan.env.motion.MotionEnv`) reset with
seed ``s + i`` (``reset(seed=s)``) and then reset without a seed at each episode end, exactly what
``gymnasium.vector.SyncVectorEnv`` of that env does, whatever ``B``.

==================  ============================================================================
Actions             ``(B, N)`` int: agent ``j``'s ``Discrete(n_j)`` action in world ``b`` (the
                    motion env's table: stay, four moves, climb/descend, dump); batched
                    ``MultiDiscrete``. Masked actions are executed as ``stay``.
Observations        ``{"fov": (B, N, 7, v, v) float32, "agent": (B, N, 15) float32,
                    "action_mask": (B, N, n_max) int8}`` (:mod:`fcplan.env.vector_obs`); masks
                    padded with 0 beyond an agent's actions
Rewards             ``(B,)`` float64: the shared team reward of the tick (``PenaltyReward``,
                    minus the manual's negative reward; optional shaping as the single env)
Terminations        always False; ``truncations`` True at the scenario's duration
Infos               ``metrics`` (object array, ``_metrics`` mask): the final metrics of the
                    worlds whose episode ended this step
Autoreset           ``autoreset_mode="next_step"`` (Gymnasium's default: the step after the end
                    resets the world, ignoring its actions, and returns the reset observation
                    with reward 0), ``"same_step"`` (reset at once; ``final_obs`` and
                    ``final_info`` in the infos) or ``"disabled"`` (finished worlds are *held*:
                    not stepped, reward 0, until ``reset(options={"reset_mask": mask})``)
==================  ============================================================================

Options as :class:`~fcplan.env.motion.MotionEnv`: ``cell_px``, ``view``, ``stale_s``,
``idle_rule``, ``sense_bonus``, ``prune_bonus``, ``dump_cost`` (a custom ``reward_fn`` works on
one :class:`fcplan.World` and is not batched). ``make_vec("fcplan/Motion-v0", num_envs=B)``
returns this class (:mod:`fcplan.env.registration`).

Examples
--------
>>> import numpy as np
>>> env = VectorMotionEnv("practice", num_envs=3)
>>> obs, infos = env.reset(seed=0)
>>> obs["fov"].shape, obs["action_mask"].shape
((3, 4, 7, 15, 15), (3, 4, 7))
>>> obs, rewards, terms, truncs, infos = env.step(np.zeros((3, 4), dtype=np.int64))
>>> rewards.shape, bool(truncs.any())
((3,), False)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from fcplan.batch import BatchStepInfo, BatchWorld
from fcplan.env.action_input import integer_actions
from fcplan.env.motion import MotionEnv
from fcplan.env.motion_obs import N_AGENT_FEATURES, N_FOV
from fcplan.env.vector_base import BatchedEnv, per_world_info, reset_rows, reset_seeds
from fcplan.env.vector_obs import BatchMotionObs
from fcplan.errors import EnvError
from fcplan.metrics import facility_penalty
from fcplan.mission import ScenarioLike
from fcplan.team import CLIMB_PER_TICK

__all__ = ["VectorMotionEnv"]

_STAY, _MOVE, _ALTITUDE, _DUMP = range(4)
_ACTIVE = 1
_GOAL_REACH = 1.5  # (fcplan.env.motion: a move sets a goal 1.5 steps away)
_NAMES = {
    "P": ("stay", "west", "east", "north", "south", "climb", "descend"),
    "A": ("stay", "west", "east", "north", "south", "dump"),
    "H": ("stay", "west", "east", "north", "south", "climb", "descend", "dump"),
}
_DIRS = {"west": (-1.0, 0.0), "east": (1.0, 0.0), "north": (0.0, -1.0), "south": (0.0, 1.0)}


class VectorMotionEnv(BatchedEnv):
    """``num_envs`` motion-level worlds of ``scenario`` stepped together (module docstring)."""

    def __init__(
        self,
        scenario: ScenarioLike,
        num_envs: int = 1,
        *,
        autoreset_mode: str | AutoresetMode = "next_step",
        cell_px: int = 20,
        view: int = 15,
        stale_s: float = 30.0,
        idle_rule: bool = False,
        sense_bonus: float = 0.0,
        prune_bonus: float = 0.0,
        dump_cost: float = 0.0,
        reward_fn: Any = None,
    ) -> None:
        self._setup(num_envs, autoreset_mode)
        if reward_fn is not None:
            raise EnvError("reward_fn: a custom reward works on one World and is not batched")
        #: the single env of the same options (checks them; never stepped)
        self.one = MotionEnv(scenario, cell_px=cell_px, view=view, stale_s=stale_s)
        self.scenario = sc = self.one.scenario
        b = self.num_envs
        self.idle_rule = bool(idle_rule)
        self.shaping = (float(sense_bonus), float(prune_bonus), float(dump_cost))
        self.batch = BatchWorld(sc, b)
        self.views = BatchMotionObs(sc, b, cell_px=int(cell_px), view=int(view), stale_s=stale_s)
        self.agent_ids = list(self.batch.team.ids)
        self._actions_table()
        self._rows = np.arange(b)[:, None]
        n, v = len(self.agent_ids), int(view)
        n_max = self.views.n_max
        self.single_observation_space = spaces.Dict(
            {
                "fov": spaces.Box(0.0, 1.0, (n, N_FOV, v, v), np.float32),
                "agent": spaces.Box(0.0, 1.0, (n, N_AGENT_FEATURES), np.float32),
                "action_mask": spaces.Box(0, 1, (n, n_max), np.int8),
            }
        )
        self.single_action_space = spaces.MultiDiscrete(self.views.n_actions.copy())
        self.observation_space = batch_space(self.single_observation_space, b)
        self.action_space = batch_space(self.single_action_space, b)
        self._weight = sc.scoring.propagation_weight
        self._fb_last = np.full((b, self.batch.n_facilities), -1, dtype=np.int64)
        self._fb_pen = np.zeros(b)
        #: the batched simulator's report of the last step (None before the first): what a
        #: batched expert folds into its beliefs (:mod:`fcplan.env.vector_expert`)
        self.last_info: BatchStepInfo | None = None

    def _actions_table(self) -> None:
        """Per agent and action: kind, goal offset (dx, dy) and altitude change."""
        team, views = self.batch.team, self.views
        n, n_max = len(self.agent_ids), views.n_max
        self._kind = np.zeros((n, n_max), dtype=np.int64)
        self._offset = np.zeros((n, n_max, 2))
        self._dz = np.zeros((n, n_max))
        climb = CLIMB_PER_TICK * team.one.tick_scale
        for i, (r, sp) in enumerate(zip(views.letters, team.speed.tolist(), strict=True)):
            for a, name in enumerate(_NAMES[r]):
                if name in _DIRS:
                    self._kind[i, a] = _MOVE
                    dx, dy = _DIRS[name]
                    self._offset[i, a] = (dx * _GOAL_REACH * sp, dy * _GOAL_REACH * sp)
                elif name in ("climb", "descend"):
                    self._kind[i, a] = _ALTITUDE
                    self._dz[i, a] = (1.0 if name == "climb" else -1.0) * climb
                elif name == "dump":
                    self._kind[i, a] = _DUMP

    # ------------------------------------------------------------------ episodes
    def reset(
        self, *, seed: int | list | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start episodes: every world, or only ``options["reset_mask"]``'s; ``seed`` as
        Gymnasium's vector envs take it (an int ``s``: ``s + b`` for world ``b``; a list: one
        seed per world; None: each world continues its seeds), or one seed per world reset
        (:func:`fcplan.env.vector_base.reset_seeds`)."""
        rows = reset_rows(self.num_envs, seed, options)
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[rows] = True
        self.batch.reset(seeds=reset_seeds(self.num_envs, rows, seed), mask=mask)
        self._reset_views(rows)
        self._started = True
        return self.views.observe(self.batch), {}

    def _reset_views(self, rows: np.ndarray) -> None:
        self.views.reset_worlds(rows)
        self._pending[rows] = False
        self._fb_last[rows] = -1

    # ------------------------------------------------------------------ step
    def step(
        self, actions: Any
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Advance every world one tick with ``actions`` ((B, N) ints); see the module docstring."""
        batch = self.batch
        run = self._stepping(batch.done)
        act = self.check_actions(actions)
        next_step = self.autoreset_mode is AutoresetMode.NEXT_STEP
        self._decode(act, run)
        info = batch.step(autoreset=next_step)
        self.last_info = info
        batch.team.armed.fill(False)
        if np.count_nonzero(info.reset):
            self._reset_views(np.flatnonzero(info.reset))
        self.views.update(info, batch)
        rewards = self._rewards(info)
        truncs = info.ran & batch.done
        infos: dict[str, Any] = {}
        if np.count_nonzero(truncs):
            self._final_metrics(truncs, infos)
        obs = self.views.observe(batch)
        if self.autoreset_mode is AutoresetMode.SAME_STEP and np.count_nonzero(truncs):
            obs = self._same_step_reset(truncs, obs, infos)
        self._ended(truncs)
        terms = np.zeros(self.num_envs, dtype=bool)
        return obs, rewards, terms, truncs, infos

    def check_actions(self, actions: Any, num: int | None = None) -> np.ndarray:
        """``(num, N)`` int64 actions (``num`` default ``B``), checked against each agent's
        action count (:class:`~fcplan.errors.EnvError` naming the first bad one)."""
        b = self.num_envs if num is None else int(num)
        act = integer_actions(actions, (b, len(self.agent_ids)))
        bad = (act < 0) | (act >= self.views.n_actions)
        if np.count_nonzero(bad):
            b, j = (int(k[0]) for k in np.nonzero(bad))
            n = int(self.views.n_actions[j])
            raise EnvError(
                f"actions[{b}, {j}] ({self.agent_ids[j]}): must be an integer in 0..{n - 1} "
                f"(got {int(act[b, j])})"
            )
        return act

    def _decode(self, act: np.ndarray, run: np.ndarray) -> None:
        """Write the legal actions of the worlds ``run`` into the teams (``MotionEnv.step``)."""
        team, views = self.batch.team, self.views
        j = np.arange(act.shape[1])
        legal = views.masks[self._rows, j, act]
        kind = np.where(legal & run[:, None], self._kind[j, act], _STAY)
        move = kind == _MOVE
        if np.count_nonzero(move):
            team.goal[move] = team.pos[move] + self._offset[j, act][move]
            team.has_goal[move] = True
            team.mode[move] = _ACTIVE
        free = views.free & ~move & run[:, None]
        team.has_goal[free] = False
        dump = kind == _DUMP
        if np.count_nonzero(dump):
            team.armed[dump] = True
            team.mode[dump] = _ACTIVE
        alt = kind == _ALTITUDE
        if np.count_nonzero(alt):
            z = team.z + self._dz[j, act]
            zt = np.minimum(np.maximum(z, team.alt_lo), team.alt_hi)
            team.z_target[alt] = zt[alt]
        if not self.idle_rule:
            team.hover_s[run] = 0.0

    def _rewards(self, info: BatchStepInfo) -> np.ndarray:
        """(B,) reward of the tick (``PenaltyReward`` and the shaping terms; 0 if not stepped)."""
        batch = self.batch
        fb = batch.facility_burning
        changed = np.flatnonzero((fb != self._fb_last).any(axis=1) & info.ran)
        for b in changed.tolist():  # (rare: a facility's count changed; the metric's own sum)
            self._fb_pen[b] = facility_penalty(fb[b], batch.facility_penalties)
            self._fb_last[b] = fb[b]
        rate = self._weight * batch.fire.n_burning + self._fb_pen
        r = -rate / float(batch.tps)
        sense, prune, dump = self.shaping
        if sense or prune or dump:
            b = self.num_envs
            n_new = np.bincount(info.newly_sensed[0], minlength=b)
            n_pruned = np.bincount(info.pruned[0], minlength=b)
            r += sense * n_new + prune * n_pruned
            r -= dump * info.dumped.sum(axis=1)
        return np.where(info.ran, r, 0.0)

    def _final_metrics(self, truncs: np.ndarray, infos: dict[str, Any]) -> None:
        def metrics(b: int) -> dict[str, Any]:
            return {k: m.as_dict() for k, m in self.batch.metrics(b).items()}

        infos["metrics"], infos["_metrics"] = per_world_info(truncs, metrics)

    def _same_step_reset(
        self, truncs: np.ndarray, obs: dict[str, np.ndarray], infos: dict[str, Any]
    ) -> dict[str, np.ndarray]:
        """Reset the worlds that just ended; their final observations go into the infos."""
        final, mask = per_world_info(truncs, lambda b: {k: v[b].copy() for k, v in obs.items()})
        infos.update(final_obs=final, _final_obs=mask)
        final_info, mask = per_world_info(truncs, lambda b: {"metrics": infos["metrics"][b]})
        infos.update(final_info=final_info, _final_info=mask)
        self.batch.reset(mask=truncs)
        self._reset_views(np.flatnonzero(truncs))
        return self.views.observe(self.batch)

    def state(self) -> np.ndarray:
        """Global state of every world, ``(B, 8, nc, nc)`` float32 (``MotionEnv.state``)."""
        return self.views.state(self.batch)
