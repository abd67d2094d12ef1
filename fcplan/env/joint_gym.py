"""Gymnasium single-agent view of the motion level: one centralised controller for the team.

:class:`JointGymEnv` wraps a motion-level ``ParallelEnv``, either :class:`fcplan.env.motion.MotionEnv`
on a scenario or one of the reference presets (:mod:`fcplan.env.presets`), as a
:class:`gymnasium.Env` that passes ``gymnasium.utils.env_checker.check_env``. It is registered as
``fcplan/Motion-v0``, ``fcplan/MotionBase-v0``, ``fcplan/MotionCmplx1-v0`` and
``fcplan/MotionCmplx2-v0`` (:mod:`fcplan.env.registration`).

==================  ==================================================================
Actions             ``MultiDiscrete([n_1, ..., n_A])``: each agent's own ``Discrete`` in
                    agent order (perception and action agents differ)
Observations        ``Dict(fov=Box(A, C, v, v), agent=Box(A, F), action_mask=Box(A, n_max)
                    int8)``: the per-agent observations stacked; an agent's mask is padded
                    with 0 beyond its ``n_i`` actions
Reward              ``team_reward="first"`` (default on a scenario, whose reward is shared):
                    the shared reward; ``"sum"`` (default on a preset, whose rewards mix
                    local terms): the sum over agents
Episode end         ``terminated`` when the agents terminate (a preset's success);
                    ``truncated`` at the time limit
Info                ``agents``: the per-agent infos; ``metrics`` at the end of a scenario
                    episode (as the parallel env's)
==================  ==================================================================

Masked-out actions are the parallel env's business: the motion level executes them as ``stay``,
the presets have none.

Examples
--------
>>> env = JointGymEnv(preset="base", max_steps=5)
>>> obs, info = env.reset(seed=0)
>>> env.action_space.nvec.tolist(), obs["fov"].shape, obs["action_mask"].shape
([5, 5, 6, 6], (4, 10, 3, 3), (4, 6))
>>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from fcplan.env.action_input import integer_actions
from fcplan.env.human import HumanWindow, WindowedRender
from fcplan.env.wrappers import split_options
from fcplan.errors import EnvError
from fcplan.mission import ScenarioLike

__all__ = ["JointGymEnv"]


def _stack(boxes: list[spaces.Box]) -> spaces.Box:
    lo = np.stack([np.broadcast_to(b.low, b.shape) for b in boxes])
    hi = np.stack([np.broadcast_to(b.high, b.shape) for b in boxes])
    return spaces.Box(lo, hi, dtype=boxes[0].dtype)


class JointGymEnv(WindowedRender, gymnasium.Env):
    """Centralised Gymnasium view of a motion-level env (see the module docstring).

    Parameters
    ----------
    scenario : Scenario, str or int, optional
        A scenario for :class:`fcplan.env.motion.MotionEnv` (or a preset name).
    preset : {"base", "cmplx1", "cmplx2"}, optional
        A reference preset instead of a scenario.
    team_reward : {"first", "sum"}, optional
        How the per-agent rewards become one (default: ``"first"`` on a scenario, ``"sum"`` on
        a preset).
    render_mode : {None, "rgb_array", "human"}
    **kwargs
        The env's keyword arguments.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}

    def __init__(
        self,
        scenario: ScenarioLike | None = None,
        *,
        preset: str | None = None,
        team_reward: str | None = None,
        render_mode: str | None = None,
        **kwargs: Any,
    ) -> None:
        from fcplan.env.motion import PRESETS, parallel_env

        if render_mode not in (None, "rgb_array", "human"):
            raise EnvError(
                f"render_mode: must be None, 'rgb_array' or 'human' (got {render_mode!r})"
            )
        is_preset = preset is not None or (isinstance(scenario, str) and scenario in PRESETS)
        team_reward = team_reward or ("sum" if is_preset else "first")
        if team_reward not in ("first", "sum"):
            raise EnvError(f"team_reward: must be 'first' or 'sum' (got {team_reward!r})")
        inner_mode, human = split_options(render_mode)
        self.env = parallel_env(scenario, preset=preset, render_mode=inner_mode, **kwargs)
        self.render_mode = render_mode
        self.team_reward = team_reward
        meta = self.env.metadata
        self.metadata = {**self.metadata, "render_fps": meta.get("render_fps", 10)}
        self.window = (
            HumanWindow(str(meta.get("name")), self.metadata["render_fps"]) if human else None
        )
        ids = self.env.possible_agents
        self._n = [int(self.env.action_space(a).n) for a in ids]
        subs = [self.env.observation_space(a) for a in ids]
        self._n_max = max(self._n)
        #: where each agent's mask entries go in the flat (agents x n_max) padded mask
        self._mask_at = np.concatenate(
            [np.arange(k) + i * self._n_max for i, k in enumerate(self._n)]
        )
        self.observation_space = spaces.Dict(
            {
                "fov": _stack([s["fov"] for s in subs]),
                "agent": _stack([s["agent"] for s in subs]),
                "action_mask": spaces.Box(0, 1, (len(ids), self._n_max), np.int8),
            }
        )
        self.action_space = spaces.MultiDiscrete(np.array(self._n, dtype=np.int64))

    def _obs(self, obs: dict[str, Any]) -> dict[str, np.ndarray]:
        """The agents' observations stacked: ``np.stack`` of each field and the masks padded
        with 0 (one concatenation per field, and one scatter of the masks into the padded
        array at :attr:`_mask_at`: half the cost of ``np.stack`` and a loop over the agents)."""
        per = [obs[a] for a in self.env.possible_agents]
        n = len(per)
        fov = np.concatenate([o["fov"] for o in per]).reshape(n, *per[0]["fov"].shape)
        agent = np.concatenate([o["agent"] for o in per]).reshape(n, *per[0]["agent"].shape)
        mask = np.zeros(n * self._n_max, dtype=np.int8)
        mask[self._mask_at] = np.concatenate([o["action_mask"] for o in per])
        return {"fov": fov, "agent": agent, "action_mask": mask.reshape(n, self._n_max)}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode; ``seed`` as the parallel env's ``reset``."""
        super().reset(seed=seed)
        obs, infos = self.env.reset(seed=seed, options=options)
        self._show()
        return self._obs(obs), {"agents": infos}

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Apply the joint action; return ``(obs, reward, terminated, truncated, info)``."""
        ids = self.env.possible_agents
        act = integer_actions(action, (len(ids),), "action").tolist()
        obs, rew, term, trunc, infos = self.env.step(dict(zip(ids, act, strict=True)))
        if self.team_reward == "first":
            reward = float(rew[ids[0]])
        else:
            reward = float(sum(rew[a] for a in ids))
        info: dict[str, Any] = {"agents": infos}
        first = infos.get(ids[0], {})
        if "metrics" in first:
            info["metrics"] = first["metrics"]
        self._show()
        return self._obs(obs), reward, any(term.values()), any(trunc.values()), info
