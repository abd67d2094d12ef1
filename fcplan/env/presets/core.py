"""The base of the reference presets: PettingZoo plumbing and the RF1 team-structure penalty.

:class:`PresetEnv` is what every preset shares: the agents (``perception_0..P-1`` then
``action_0..A-1``), cached ``Discrete`` action spaces and ``Dict(fov, agent, action_mask)``
observation spaces, seeding (a seed starts a new stream; ``reset()`` without one continues it),
action checking, the end of an episode and the ``rgb_array`` render of the state grid. A preset
subclasses it and writes ``reset``, ``step``, ``state``, ``_observe``, ``_progress`` and
``_render_codes``; this module knows no concrete preset (the registry is
:data:`fcplan.env.presets.PRESETS`).

RF1, the reference's team-structure reward, is shared too: :func:`rf1_structure_penalty` (numpy)
and :func:`rf1_penalty_small` (the same value on Python lists, for a handful of agents).

Examples
--------
>>> rf1_structure_penalty(np.array([[0, 0], [9, 9], [1, 1]]), np.array([True, True, False]), 5)
4.0
>>> rf1_penalty_small([[0, 0], [9, 9], [1, 1]], [True, True, False], 5)
4.0
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
from pettingzoo import ParallelEnv

from fcplan.errors import EnvError
from fcplan.shared_views import KeepsViews

if TYPE_CHECKING:
    from gymnasium import spaces

__all__ = ["MOVES", "PresetEnv", "StepResult", "rf1_structure_penalty", "rf1_penalty_small"]

#: What ``step`` returns: observations, rewards, terminations, truncations and infos per agent.
StepResult: TypeAlias = tuple[
    dict[str, Any], dict[str, float], dict[str, bool], dict[str, bool], dict[str, dict[str, Any]]
]

#: The reference presets' moves, by action 0-3: x-1, x+1, y-1, y+1 (spec section 6).
MOVES = np.array([[-1, 0], [1, 0], [0, -1], [0, 1]], dtype=np.int64)


def rf1_structure_penalty(pos: np.ndarray, is_perception: np.ndarray, comm_range: float) -> float:
    """RF1's team-structure term: 1 per agent with no neighbour plus 3 per agent in no
    perception-action neighbour pair (neighbours: Chebyshev distance <= ``comm_range``).

    Parameters
    ----------
    pos : ndarray, (N, 2)
    is_perception : ndarray, (N,) bool
        False for action agents.
    comm_range : float

    Returns
    -------
    float
        The penalty magnitude (RF1 subtracts it).
    """
    d = np.abs(pos[:, None, :] - pos[None, :, :]).max(axis=2)
    near = d <= comm_range
    np.fill_diagonal(near, False)
    lonely = ~near.any(axis=1)
    other_role = is_perception[:, None] != is_perception[None, :]
    unpaired = ~(near & other_role).any(axis=1)
    return float(lonely.sum() + 3 * unpaired.sum())


def rf1_penalty_small(pos: list[list[int]], is_perception: list[bool], comm_range: float) -> float:
    """:func:`rf1_structure_penalty` for a small team, on Python lists (the same value; a
    double loop over the agents beats numpy's setup for a handful of them).

    Parameters
    ----------
    pos : list of [x, y]
    is_perception : list of bool
    comm_range : float

    Returns
    -------
    float
        The penalty magnitude (RF1 subtracts it).
    """
    n = len(pos)
    near = [False] * n
    paired = [False] * n
    c = comm_range
    for i in range(n):
        xi, yi = pos[i]
        for j in range(i + 1, n):  # (each pair once: the relation is symmetric)
            dx, dy = pos[j][0] - xi, pos[j][1] - yi
            if -c <= dx <= c and -c <= dy <= c:  # Chebyshev distance <= c
                near[i] = near[j] = True
                if is_perception[i] != is_perception[j]:
                    paired[i] = paired[j] = True
    return float((n - sum(near)) + 3 * (n - sum(paired)))


class PresetEnv(KeepsViews, ParallelEnv):
    """PettingZoo plumbing shared by the presets: agents, cached spaces, seeding, render.

    A preset's ``__init__`` calls :meth:`_setup_agents`, :meth:`_check_common` and
    :meth:`_setup_spaces`, and sets ``_default_action`` (per agent), ``_palette`` (RGB per
    render code), ``render_mode`` and ``render_size``; ``reset`` sets ``_pos``. It defines
    ``reset``, ``step`` (ending with :meth:`_finish`), ``state``, :meth:`_progress` and
    :meth:`_render_codes`.
    """

    metadata = {"name": "fcplan_preset_v0", "render_modes": ["rgb_array"], "render_fps": 10}

    render_mode: str | None
    render_size: int
    _default_action: np.ndarray  # (N,) int: the action of an agent missing from ``step``
    _palette: np.ndarray  # (codes, 3) uint8 render colour per state code
    _pos: np.ndarray  # (N, 2) int64 agent cells, set by ``reset``

    def _progress(self) -> dict[str, float]:
        """The ``infos`` entries of every agent (``perception_complete``, ...)."""
        raise NotImplementedError

    def _render_codes(self) -> np.ndarray:
        """``(W, W)`` int state codes (rows of ``_palette``) of the grid to render."""
        raise NotImplementedError

    def _setup_agents(self, n_perception: int, n_action: int) -> None:
        if n_perception < 1 or n_action < 1:
            raise EnvError(
                f"team: needs at least one perception and one action agent "
                f"(got {n_perception} and {n_action})"
            )
        self.n_perception, self.n_action = int(n_perception), int(n_action)
        self.possible_agents = [f"perception_{i}" for i in range(self.n_perception)] + [
            f"action_{i}" for i in range(self.n_action)
        ]
        self.agents: list[str] = []
        self.n = len(self.possible_agents)
        self.is_perception = np.arange(self.n) < self.n_perception
        self._reseed: np.random.Generator | None = None

    def _setup_spaces(
        self,
        n_actions: np.ndarray,
        fov_shape: tuple[int, ...],
        agent_dim: int,
        state_space: spaces.Box,
    ) -> None:
        """Cached ``Discrete`` action and ``Dict(fov, agent, action_mask)`` observation spaces
        (every action is always legal in the presets: moves are clipped, as in the reference)."""
        from gymnasium import spaces

        self._n_actions = n_actions
        self._n_actions_list = n_actions.tolist()
        self._default_list: list[int] | None = None  # (from self._default_action, on first use)
        pairs = list(zip(self.possible_agents, self._n_actions_list, strict=True))
        self._action_spaces = {a: spaces.Discrete(k) for a, k in pairs}
        self._obs_spaces = {
            a: spaces.Dict(
                {
                    "fov": spaces.Box(0.0, 1.0, fov_shape, np.float32),
                    "agent": spaces.Box(0.0, 1.0, (agent_dim,), np.float32),
                    "action_mask": spaces.Box(0, 1, (k,), np.int8),
                }
            )
            for a, k in pairs
        }
        self.state_space = state_space
        self._masks = [np.ones(k, dtype=np.int8) for _, k in pairs]

    @staticmethod
    def _check_common(reward: str, max_steps: int, render_mode: str | None) -> None:
        if reward not in ("rf1", "rf2", "rf3"):
            raise EnvError(f"reward: must be one of rf1, rf2, rf3 (got {reward!r})")
        if int(max_steps) < 1:
            raise EnvError(f"max_steps: must be >= 1 (got {max_steps})")
        if render_mode not in (None, "rgb_array"):
            raise EnvError(f"render_mode: must be None or 'rgb_array' (got {render_mode!r})")

    def _finish(
        self, obs: dict[str, Any], rewards: dict[str, float], success: bool, timeout: bool
    ) -> StepResult:
        """The step's five dicts; on success or timeout ``success`` goes into ``infos`` and
        the agents leave."""
        agents = self.agents
        terms = dict.fromkeys(agents, bool(success))
        truncs = dict.fromkeys(agents, bool(timeout))
        progress = self._progress()
        infos = {a: dict(progress) for a in agents}
        if success or timeout:
            for a in agents:
                infos[a]["success"] = bool(success)
            self.agents = []
        return obs, rewards, terms, truncs, infos

    def observation_space(self, agent: str) -> spaces.Dict:
        """The observation space of ``agent`` (the same object every call)."""
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> spaces.Discrete:
        """The action space of ``agent`` (the same object every call)."""
        return self._action_spaces[agent]

    def _next_seed(self, seed: int | None) -> np.random.SeedSequence:
        """``seed`` as a SeedSequence; without one, continue from the last seed."""
        if seed is not None:
            self._reseed = np.random.default_rng(seed)
            return np.random.SeedSequence(seed)
        if self._reseed is None:
            self._reseed = np.random.default_rng()
        return np.random.SeedSequence(int(self._reseed.integers(2**63)))

    def _actions(self, actions: dict[str, Any]) -> list[int]:
        """Each agent's action from ``{agent: action}`` (missing agents take their default),
        checked, as Python ints in agent order."""
        defaults = self._default_list
        if defaults is None:
            defaults = self._default_list = np.asarray(self._default_action).tolist()
        acts = []
        for a, d, k in zip(self.possible_agents, defaults, self._n_actions_list, strict=True):
            v = actions.get(a, d)
            if not (isinstance(v, (int, np.integer)) and 0 <= v < k):
                raise EnvError(f"action of {a}: must be an integer in 0..{k - 1} (got {v!r})")
            acts.append(int(v))
        return acts

    def render(self) -> np.ndarray | None:
        """An ``(H, W, 3)`` uint8 image of the state grid (``render_mode="rgb_array"``)."""
        if self.render_mode != "rgb_array" or not hasattr(self, "_pos"):
            return None
        codes = self._render_codes()
        colours = self._palette[np.minimum(codes, len(self._palette) - 1)]
        scale = max(1, self.render_size // codes.shape[0])
        img = np.repeat(np.repeat(colours, scale, axis=0), scale, axis=1)
        return np.ascontiguousarray(img.transpose(1, 0, 2))  # rows = y, columns = x

    def close(self) -> None:
        """Nothing to release."""
