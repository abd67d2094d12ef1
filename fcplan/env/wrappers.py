"""PettingZoo wrappers for the layouts learning libraries read: flat observations, equal action
spaces and the human render mode.

``fcplan.env.parallel_env`` and the versioned modules (``fcplan.env.task_v0`` ...) apply them
when asked; without options an env is returned unwrapped, exactly as before.

``obs_layout="flat"`` (:class:`FlatObservations`)
    Each agent's observation becomes ``{"observation": Box(D,) float32, "action_mask":
    Box(n,) int8}``, the layout of PettingZoo's classic envs that common MARL libraries read.
    ``observation`` concatenates the env's other fields, each flattened in C order, in the order
    of the env's ``Dict`` space (task level: ``agent`` then ``tasks``; motion level: ``agent``
    then ``fov``; :data:`gymnasium.spaces.Dict` keeps its keys sorted). The default
    ``obs_layout="dict"`` keeps the env's own observations.
``pad_actions=True`` (:class:`PadActions`)
    Every agent gets ``Discrete(n_max)``, the largest action space of the team, and an
    ``action_mask`` of ``n_max`` entries whose extra entries are 0. An extra action is never
    legal; if taken it acts as the agent's no-op (the agent is left out of the env's action
    dict: the motion level's ``stay``, the presets' no-op or default action). With equal spaces
    SuperSuit's ``pettingzoo_env_to_vec_env_v1`` accepts the motion level (perception agents
    have ``Discrete(7)``, action agents ``Discrete(6)``).
``render_mode="human"`` (:class:`HumanRender`)
    The env runs in ``rgb_array`` mode and its frame is shown in a pygame window
    (:class:`fcplan.env.human.HumanWindow`) after ``reset`` and every ``step``.

Examples
--------
>>> from fcplan.env import parallel_env
>>> env = parallel_env("practice", mode="motion", obs_layout="flat", pad_actions=True)
>>> obs, infos = env.reset(seed=0)
>>> sorted(obs["A1"]), obs["A1"]["observation"].shape, obs["A1"]["action_mask"].tolist()
(['action_mask', 'observation'], (1590,), [1, 1, 1, 1, 1, 1, 0])
>>> env.action_space("A1") == env.action_space("P1")
True
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv
from pettingzoo.utils import BaseParallelWrapper

from fcplan.env.human import HumanWindow
from fcplan.errors import EnvError

__all__ = ["FlatObservations", "PadActions", "HumanRender", "OBS_LAYOUTS", "wrap", "split_options"]

#: Observation layouts accepted by ``obs_layout``.
OBS_LAYOUTS = ("dict", "flat")


def _with_mode(env: ParallelEnv, metadata: dict[str, Any]) -> dict[str, Any]:
    return {**getattr(env, "metadata", {}), **metadata}


class FlatObservations(BaseParallelWrapper):
    """``{"observation": Box(D,), "action_mask": Box(n,)}`` per agent (module docstring)."""

    def __init__(self, env: ParallelEnv) -> None:
        super().__init__(env)
        self.metadata = _with_mode(env, {})
        self._spaces: dict[str, spaces.Dict] = {}
        self._keys: dict[str, list[str]] = {}
        for a in env.possible_agents:
            sub = env.observation_space(a)
            keys = [k for k in sub.spaces if k != "action_mask"]
            lo = np.concatenate([np.broadcast_to(sub[k].low, sub[k].shape).ravel() for k in keys])
            hi = np.concatenate([np.broadcast_to(sub[k].high, sub[k].shape).ravel() for k in keys])
            box = spaces.Box(lo.astype(np.float32), hi.astype(np.float32), dtype=np.float32)
            self._keys[a] = keys
            self._spaces[a] = spaces.Dict({"observation": box, "action_mask": sub["action_mask"]})

    def observation_space(self, agent: str) -> spaces.Dict:
        """The flat ``Dict`` space of ``agent`` (the same object every call)."""
        return self._spaces[agent]

    def _flat(self, obs: dict[str, Any]) -> dict[str, Any]:
        out = {}
        for a, o in obs.items():
            parts = [np.asarray(o[k], dtype=np.float32).ravel() for k in self._keys[a]]
            out[a] = {"observation": np.concatenate(parts), "action_mask": o["action_mask"]}
        return out

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """The env's reset with flat observations."""
        obs, infos = self.env.reset(seed=seed, options=options)
        return self._flat(obs), infos

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        """The env's step with flat observations."""
        obs, rew, term, trunc, infos = self.env.step(actions)
        return self._flat(obs), rew, term, trunc, infos


class PadActions(BaseParallelWrapper):
    """Every agent gets ``Discrete(n_max)``; extra actions are masked out and act as the
    agent's no-op (module docstring)."""

    def __init__(self, env: ParallelEnv) -> None:
        super().__init__(env)
        self.metadata = _with_mode(env, {})
        self._n = {a: int(env.action_space(a).n) for a in env.possible_agents}
        n_max = max(self._n.values())
        self._action_space = spaces.Discrete(n_max)
        self._n_max = n_max
        self._spaces = {}
        for a in env.possible_agents:
            sub = env.observation_space(a)
            fields = dict(sub.spaces)
            fields["action_mask"] = spaces.Box(0, 1, (n_max,), np.int8)
            self._spaces[a] = spaces.Dict(fields)

    def observation_space(self, agent: str) -> spaces.Dict:
        """The agent's space with an ``n_max`` action mask."""
        return self._spaces[agent]

    def action_space(self, agent: str) -> spaces.Discrete:
        """``Discrete(n_max)``, one object shared by every agent."""
        return self._action_space

    def _pad(self, obs: dict[str, Any]) -> dict[str, Any]:
        out = {}
        for a, o in obs.items():
            o = dict(o)
            mask = np.zeros(self._n_max, dtype=np.int8)
            mask[: self._n[a]] = o["action_mask"]
            o["action_mask"] = mask
            out[a] = o
        return out

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """The env's reset with padded masks."""
        obs, infos = self.env.reset(seed=seed, options=options)
        return self._pad(obs), infos

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        """The env's step; an extra action leaves the agent out (its no-op)."""
        n = self._n
        kept = {a: x for a, x in actions.items() if x is None or int(x) < n[a]}
        obs, rew, term, trunc, infos = self.env.step(kept)
        return self._pad(obs), rew, term, trunc, infos


class HumanRender(BaseParallelWrapper):
    """``render_mode="human"`` for an env made with ``render_mode="rgb_array"``."""

    def __init__(self, env: ParallelEnv) -> None:
        if getattr(env, "render_mode", None) != "rgb_array":
            raise EnvError("render_mode: HumanRender needs an env made with 'rgb_array'")
        super().__init__(env)
        meta = getattr(env, "metadata", {})
        modes = list(meta.get("render_modes", ["rgb_array"]))
        self.metadata = _with_mode(env, {"render_modes": modes + ["human"]})
        self.render_mode = "human"
        name = str(meta.get("name", "fcplan"))
        #: the pygame window (opened by the first frame)
        self.window = HumanWindow(name, float(meta.get("render_fps", 10)))

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """The env's reset, then its frame in the window."""
        out = self.env.reset(seed=seed, options=options)
        self.window.show(self.env.render())
        return out

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        """The env's step, then its frame in the window."""
        out = self.env.step(actions)
        self.window.show(self.env.render())
        return out

    def render(self) -> None:
        """Show the current frame again; returns None (human mode)."""
        self.window.show(self.env.render())

    def close(self) -> None:
        """Close the window and the env."""
        self.window.close()
        self.env.close()


def wrap(
    env: ParallelEnv, *, obs_layout: str = "dict", pad_actions: bool = False, human: bool = False
) -> ParallelEnv:
    """Apply the wrappers an env was asked for (none by default: ``env`` itself).

    Raises
    ------
    EnvError
        For an unknown ``obs_layout``.
    """
    if obs_layout not in OBS_LAYOUTS:
        raise EnvError(f"obs_layout: must be one of {', '.join(OBS_LAYOUTS)} (got {obs_layout!r})")
    if human:
        env = HumanRender(env)
    if pad_actions:
        env = PadActions(env)
    if obs_layout == "flat":
        env = FlatObservations(env)
    return env


def split_options(render_mode: str | None) -> tuple[str | None, bool]:
    """The render mode to make the env with, and whether to show it in a window."""
    if render_mode == "human":
        return "rgb_array", True
    return render_mode, False
