"""Gymnasium single-agent view of the task level: one centralised controller for the whole team.

``fcplan.env.gym_env(scenario, **kwargs)`` wraps :class:`fcplan.env.task.TaskEnv` (same keyword
arguments) as a :class:`gymnasium.Env` that passes ``gymnasium.utils.env_checker.check_env``.

==================  ==================================================================
Actions             ``MultiDiscrete([k + 1] * A)``: one slot (or ``k`` = no-op) per agent,
                    agents in scenario order
Observations        ``Dict(agents=Box(A, S), tasks=Box(A, k, F), action_mask=Box(A, k + 1)
                    int8)``: the per-agent observations stacked
Reward              the shared team reward of the task level
Episode end         ``truncated`` at the scenario's duration (or ``max_steps``);
                    ``terminated`` is always False
Info                ``tick``; per-agent ``illegal``/``conflict`` arrays; at the end
                    ``metrics`` (manual and reference2020 as dicts) and ``return``
Render modes        ``"rgb_array"`` (the task env's frame) and ``"human"`` (that frame in a
                    pygame window, :mod:`fcplan.env.human`)
Gymnasium ids       ``fcplan/Task-v1`` (the env's defaults) and ``fcplan/Task-v0`` (v0's hybrid
                    rule, ``dump_altitude="watch"``; :mod:`fcplan.env.registration`)
==================  ==================================================================

Masked-out actions (an unmasked ``action_space.sample()``, as ``check_env`` does) act as the
no-op and are reported in ``info["illegal"]``; a learner should sample with the mask, e.g.
``action_mask[i].nonzero()`` per agent.

Examples
--------
>>> from fcplan.env import gym_env
>>> env = gym_env("practice", k=4, max_steps=2)
>>> obs, info = env.reset(seed=0)
>>> obs["tasks"].shape, env.action_space.nvec.tolist()
((4, 4, 17), [5, 5, 5, 5])
>>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from fcplan.env.action_input import integer_actions
from fcplan.env.human import HumanWindow, WindowedRender
from fcplan.env.task import TaskEnv
from fcplan.env.wrappers import split_options
from fcplan.errors import EnvError
from fcplan.mission import ScenarioLike

__all__ = ["TaskGymEnv", "gym_env"]


class TaskGymEnv(WindowedRender, gymnasium.Env):
    """Centralised Gymnasium view of :class:`TaskEnv` (see the module docstring).

    Parameters
    ----------
    scenario : Scenario or str or int
    **kwargs
        :class:`TaskEnv` keyword arguments (``illegal_action`` is forced to ``"noop"``).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 4}

    def __init__(self, scenario: ScenarioLike, **kwargs: Any) -> None:
        kwargs["illegal_action"] = "noop"
        self.render_mode = kwargs.get("render_mode")
        if self.render_mode not in (None, "rgb_array", "human"):
            raise EnvError(
                f"render_mode: must be None, 'rgb_array' or 'human' (got {self.render_mode!r})"
            )
        kwargs["render_mode"], human = split_options(self.render_mode)
        #: the pygame window of ``render_mode="human"`` (else None)
        title = str(TaskEnv.metadata["name"])
        self.window = HumanWindow(title, self.metadata["render_fps"]) if human else None
        self.env = TaskEnv(scenario, **kwargs)
        e = self.env
        a, k = e.n_agents, e.k
        sub = e.observation_space(e.possible_agents[0])
        lo, hi = float(sub["agent"].low.min()), float(sub["agent"].high.max())
        self.observation_space = spaces.Dict(
            {
                "agents": spaces.Box(lo, hi, (a,) + sub["agent"].shape, np.float32),
                "tasks": spaces.Box(lo, hi, (a,) + sub["tasks"].shape, np.float32),
                "action_mask": spaces.Box(0, 1, (a, k + 1), np.int8),
            }
        )
        self.action_space = spaces.MultiDiscrete(np.full(a, k + 1, dtype=np.int64))

    def _obs(self) -> dict[str, np.ndarray]:
        e = self.env  # fresh arrays every step: no copies needed
        return {"agents": e._agent_obs, "tasks": e._task_obs, "action_mask": e._mask}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode; ``seed`` as :meth:`TaskEnv.reset`."""
        super().reset(seed=seed)
        self.env.reset(seed=seed, options=options)
        self._show()
        return self._obs(), {"tick": 0}

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Apply the joint action; return ``(obs, reward, terminated, truncated, info)``."""
        e = self.env
        ids = e.possible_agents
        act = integer_actions(action, (len(ids),), "action").tolist()
        _, rew, _, trunc, infos = e.step(dict(zip(ids, act, strict=True)))
        first = infos[ids[0]]
        info = {
            "tick": first["tick"],
            "illegal": np.array([infos[a]["illegal"] for a in ids]),
            "conflict": np.array([infos[a]["conflict"] for a in ids]),
        }
        if "metrics" in first:
            info["metrics"] = first["metrics"]
            info["return"] = first["return"]
        self._show()
        return self._obs(), float(rew[ids[0]]), False, bool(trunc[ids[0]]), info


def gym_env(scenario: ScenarioLike, **kwargs: Any) -> TaskGymEnv:
    """Make the Gymnasium view of the task level (keyword arguments as :class:`TaskEnv`)."""
    return TaskGymEnv(scenario, **kwargs)
