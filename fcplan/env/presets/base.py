"""Preset ``base``: the reference ``FireCommanderEasy`` (10 x 10 grid, static fire), seeded.

``fcplan.env.motion.parallel_env(preset="base", **kwargs)`` (or
``fcplan.env.presets.make_preset("base", **kwargs)``) returns a :class:`BaseEnv`.
FIRECOMMANDER.md section 6.1 is the reference; cells are ``[x, y]``, ``0 <= x, y < W``.

World
    ``n_fires`` distinct burning cells that never move (or the reference's fixed flat indices
    ``[39, 5, 22, 81, 69]`` with ``stationary_fire=True``, read as ``x = i // W, y = i % W``).
    Agents start on random cells with all x distinct and all y distinct (``2 (P + A) <= W``
    values drawn without replacement), or all at the centre (``center_init=True``).

Agents
    ``perception_0..P-1`` then ``action_0..A-1`` (default ``P = A = 2``).

Action space
    Perception ``Discrete(5)`` (``Discrete(4)`` with ``no_op=False``), action ``Discrete(6)``:
    0 ``x - 1``, 1 ``x + 1``, 2 ``y - 1``, 3 ``y + 1`` (clipped to the grid); perception 4 no-op;
    action 4 dump water, 5 no-op. With ``water_dump=False`` action agents try to prune every
    step whatever they choose (4 then does nothing else).

Step
    Agents move; every perception agent senses every fire cell in its scope (Chebyshev
    distance <= ``vision``); then every action agent that dumps (or every one, without
    ``water_dump``) prunes the cell it stands on if that cell is sensed and burning.

Observation space
    ``Dict``: ``"fov"`` ``Box(0, 1, (4 + 2P + A, 2v+1, 2v+1), float32)`` one-hot crop centred on
    the agent (the reference ``get_FOV`` channels: 0 outside the grid, 1 unseen fire, 2 seen
    fire, 3 pruned, then one location layer per perception agent, one scope layer per
    perception agent, one location layer per action agent); ``"agent"`` ``Box(0, 1, (3,))``:
    ``x / (W-1)``, ``y / (W-1)``, is perception; ``"action_mask"`` (all actions are always
    legal, as in the reference, where moves are clipped).

State
    ``state()``: ``(1 + P + A, W, W)`` float32, the reference ``env_step`` state: layer 0 fire
    (0 none, 1 burning unseen, 2 sensed, 3 pruned), one layer per perception agent (2 in its
    scope, 1 at its cell), one per action agent (1 at its cell).

Reward (``reward="rf1" | "rf2" | "rf3"``, default ``"rf3"``)
    Global: RF1 = change in ``2 |sensed| + 20 |pruned|`` minus
    :func:`fcplan.env.presets.core.rf1_structure_penalty` (``comm_range`` 5); RF2 = -1 while
    a fire cell is not pruned; RF3 = ``global_penalty * #unpruned + A_penalty * #dumping``
    (-0.1 and -0.05). Local: ``global_penalty`` (if fire remains) + ``local_p_reward`` (or
    ``local_a_reward``) * contribution + ``a_penalty`` if dumping, where the contribution is the
    number of fire cells the agent sensed (all unpruned fire in its scope) or pruned *this step*
    (the reference overwrites its accumulator). Per agent:
    ``local_reward_ratio * local + (1 - local_reward_ratio) * global``.

Termination and truncation
    Terminated (success) once ``|pruned| / n_fires >= a_c_threshold`` (1.0); truncated at
    ``max_steps`` (1000). With ``termination_reward=True`` every agent also gets
    ``+10 n_fires`` on success and ``-10 * #unpruned`` on truncation. ``infos`` carry
    ``perception_complete``, ``action_complete`` and, at the end, ``success``.

Deviations from the reference
    Seeded (``reset(seed)``; the reference used the unseeded global ``np.random``); PettingZoo
    API with spaces, ``state()`` and ``render()``; the FOV crop works for any ``W`` (the
    reference hard-codes 10 x 10) and is given to every agent (the reference built it for
    perception agents); ``"agent"`` vector and ``action_mask`` added; the failure penalty is read
    as gated by ``termination_reward`` like the success bonus; step ``max_steps`` truncates (a
    time limit) rather than terminates.

Examples
--------
>>> env = BaseEnv(stationary_fire=True, reward="rf3")
>>> obs, infos = env.reset(seed=0)
>>> obs["perception_0"]["fov"].shape, int(env.action_space("action_0").n)
((10, 3, 3), 6)
>>> env.state().shape
(5, 10, 10)
>>> obs, rewards, terms, truncs, infos = env.step({a: 4 for a in env.agents})  # P no-op, A dump
>>> rewards["perception_0"]  # 0.5 * (-0.1) + 0.5 * (-0.1 * 5 - 0.05 * 2)
-0.35
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.env.presets.core import (
    MOVES,
    PresetEnv,
    StepResult,
    rf1_penalty_small,
    rf1_structure_penalty,
)
from fcplan.errors import EnvError

__all__ = ["BaseEnv", "STATIONARY_FIRE"]

# render colours by state code: empty, unseen fire, seen fire, pruned, P, (P scope), A
_PALETTE = np.array(
    [[235, 235, 220], [255, 90, 0], [200, 0, 0], [70, 70, 70],
     [30, 90, 255], [140, 180, 255], [0, 160, 60]],
    dtype=np.uint8,
)  # fmt: skip

#: The reference's fixed firespots (flat indices; ``x = i // W``, ``y = i % W``).
STATIONARY_FIRE = (39, 5, 22, 81, 69)
_MOVES = [tuple(m) for m in MOVES.tolist()]
#: teams up to this size compute the RF1 structure penalty in Python
_PY_AGENTS = 16


class BaseEnv(PresetEnv):
    """The ``base`` preset (module docstring: spaces, rules, rewards, deviations)."""

    metadata = {"name": "fcplan_base_v0", "render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        *,
        world_size: int = 10,
        n_fires: int = 5,
        n_perception: int = 2,
        n_action: int = 2,
        vision: int = 1,
        stationary_fire: bool = False,
        center_init: bool = False,
        no_op: bool = True,
        water_dump: bool = True,
        reward: str = "rf3",
        local_reward_ratio: float = 0.5,
        termination_reward: bool = False,
        comm_range: float = 5.0,
        a_c_threshold: float = 1.0,
        global_penalty: float = -0.1,
        local_p_reward: float = 0.1,
        local_a_reward: float = 0.1,
        a_penalty: float = -0.05,
        max_steps: int = 1000,
        render_mode: str | None = None,
        render_size: int = 320,
    ) -> None:
        from gymnasium import spaces

        self._setup_agents(n_perception, n_action)
        w = int(world_size)
        if w < 2:
            raise EnvError(f"world_size: must be >= 2 (got {world_size})")
        if vision not in (1, 2):
            raise EnvError(f"vision: must be 1 or 2 (got {vision})")
        if not center_init and 2 * self.n > w:
            raise EnvError(
                f"world_size: random starts need 2 (P + A) = {2 * self.n} <= W = {w}; "
                "use center_init=True or a larger grid"
            )
        if stationary_fire:
            cells = np.array(STATIONARY_FIRE, dtype=np.int64)
            if cells.max() >= w * w:
                raise EnvError("stationary_fire: the reference cells need world_size >= 10")
            n_fires = len(cells)
        if not 1 <= n_fires <= w * w:
            raise EnvError(f"n_fires: must be in 1..{w * w} (got {n_fires})")
        self._check_common(reward, max_steps, render_mode)
        if not 0.0 <= local_reward_ratio <= 1.0:
            raise EnvError(f"local_reward_ratio: must be in 0..1 (got {local_reward_ratio})")
        self.world_size, self.n_fires, self.vision = w, int(n_fires), int(vision)
        self.stationary_fire, self.center_init = bool(stationary_fire), bool(center_init)
        self.no_op, self.water_dump = bool(no_op), bool(water_dump)
        self.reward_name, self.local_reward_ratio = reward, float(local_reward_ratio)
        self.termination_reward, self.comm_range = bool(termination_reward), float(comm_range)
        self.a_c_threshold, self.max_steps = float(a_c_threshold), int(max_steps)
        self.global_penalty, self.a_penalty = float(global_penalty), float(a_penalty)
        self.local_reward = np.where(self.is_perception, local_p_reward, local_a_reward)
        self.render_mode, self.render_size = render_mode, int(render_size)
        p_actions = 5 if self.no_op else 4
        n_actions = np.where(self.is_perception, p_actions, 6)
        self._default_action = np.where(self.is_perception, 4 if self.no_op else 0, 5)
        v = 2 * self.vision + 1
        self.n_channels = 4 + 2 * self.n_perception + self.n_action
        self._setup_spaces(
            n_actions,
            (self.n_channels, v, v),
            3,
            spaces.Box(0.0, 3.0, (1 + self.n, w, w), np.float32),
        )
        self._palette = _PALETTE
        self._is_p = self.is_perception.tolist()
        self._p_rows = np.flatnonzero(self.is_perception).tolist()
        self._a_rows = np.flatnonzero(~self.is_perception).tolist()
        self._local = self.local_reward.tolist()
        # the one-hot layers of the observation over the whole grid, padded by the vision
        # (then every crop is a plain slice); channel 0 (outside) never changes
        self._layers = np.zeros((self.n_channels, w + 2 * v, w + 2 * v), dtype=np.float32)
        self._layers[0] = 1.0
        self._inner = self._layers[:, self.vision : self.vision + w, self.vision : self.vision + w]
        self._inner[0] = 0.0

    # ------------------------------------------------------------------ episode
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        """Place fire and agents; return ``(observations, infos)``."""
        rng = np.random.default_rng(self._next_seed(seed))
        w = self.world_size
        if self.stationary_fire:
            flat = np.array(STATIONARY_FIRE, dtype=np.int64)
        else:
            flat = rng.choice(w * w, size=self.n_fires, replace=False)
        self.fire = np.zeros((w, w), dtype=bool)
        self.fire.reshape(-1)[flat] = True
        self.sensed = np.zeros((w, w), dtype=bool)
        self.pruned = np.zeros((w, w), dtype=bool)
        if self.center_init:
            self._pos = np.full((self.n, 2), w // 2, dtype=np.int64)
        else:
            vals = rng.choice(w, size=2 * self.n, replace=False)
            self._pos = np.stack([vals[: self.n], vals[self.n :]], axis=1).astype(np.int64)
        self.steps = 0
        self._score = 0.0  # 2 |sensed| + 20 |pruned| for RF1
        self._dumping = [False] * self.n
        self.agents = list(self.possible_agents)
        return self._observe(), {a: self._progress() for a in self.agents}

    def step(self, actions: dict[str, Any]) -> StepResult:
        """One step with ``{agent: action}`` (missing agents take their no-op)."""
        if not self.agents:
            raise EnvError("step: the episode is over; call reset()")
        acts = self._actions(actions)
        w, v = self.world_size, self.vision
        # a loop over a few agents on Python ints: cheaper than numpy here
        pos = self._pos.tolist()
        for i, a in enumerate(acts):
            if a < 4:
                dx, dy = _MOVES[a]
                x, y = pos[i][0] + dx, pos[i][1] + dy
                pos[i] = [min(max(x, 0), w - 1), min(max(y, 0), w - 1)]
        self._pos[:] = pos
        # sensing: every fire cell in each perception agent's scope
        contrib = [0] * self.n
        burning = self.fire & ~self.pruned
        for i in self._p_rows:
            x, y = pos[i]
            x0, y0 = max(x - v, 0), max(y - v, 0)
            box = burning[x0 : x + v + 1, y0 : y + v + 1]
            contrib[i] = int(np.count_nonzero(box))
            if contrib[i]:
                self.sensed[x0 : x + v + 1, y0 : y + v + 1] |= box
        # pruning: the sensed burning cell under each dumping action agent
        fire, sensed, pruned = self.fire, self.sensed, self.pruned
        dumping = [False] * self.n
        for i in self._a_rows:
            dumping[i] = acts[i] == 4
            if dumping[i] or not self.water_dump:
                x, y = pos[i]
                if fire[x, y] and sensed[x, y] and not pruned[x, y]:
                    pruned[x, y] = True
                    contrib[i] = 1
        self._dumping = dumping
        self.steps += 1
        n_pruned = int(np.count_nonzero(pruned))
        remaining = self.n_fires - n_pruned
        glob = self._global_reward(remaining, pos)
        gp = self.global_penalty if remaining > 0 else 0.0
        ratio = self.local_reward_ratio
        success = n_pruned / self.n_fires >= self.a_c_threshold
        timeout = self.steps >= self.max_steps and not success
        bonus = 10.0 * self.n_fires if success else 0.0
        malus = 10.0 * remaining if timeout else 0.0
        ap = self.a_penalty
        rewards = {}
        for agent, lr, c, d in zip(self.agents, self._local, contrib, dumping, strict=True):
            # (the operations of the reference's array expression, element by element)
            rew = ratio * (gp + lr * c + ap * d) + (1.0 - ratio) * glob
            if self.termination_reward:
                rew = rew + bonus
                rew = rew - malus
            rewards[agent] = rew
        obs = self._observe()
        return self._finish(obs, rewards, success, timeout)

    def _global_reward(self, remaining: int, pos: list[list[int]]) -> float:
        if self.reward_name == "rf2":
            return -1.0 if remaining > 0 else 0.0
        if self.reward_name == "rf3":
            return self.global_penalty * remaining + self.a_penalty * sum(self._dumping)
        score = 2.0 * int(np.count_nonzero(self.sensed)) + 20.0 * int(np.count_nonzero(self.pruned))
        delta, self._score = score - self._score, score
        if self.n <= _PY_AGENTS:
            return delta - rf1_penalty_small(pos, self._is_p, self.comm_range)
        return delta - rf1_structure_penalty(self._pos, self.is_perception, self.comm_range)

    def _progress(self) -> dict[str, float]:
        return {
            "perception_complete": float(self.sensed.sum() / self.n_fires),
            "action_complete": float(self.pruned.sum() / self.n_fires),
        }

    # ------------------------------------------------------------------ observations
    def state(self) -> np.ndarray:
        """``(1 + P + A, W, W)`` float32 reference state (module docstring)."""
        w, v = self.world_size, self.vision
        s = np.zeros((1 + self.n, w, w), dtype=np.float32)
        s[0] = self._render_codes(fire_only=True)
        for i, (x, y) in enumerate(self._pos.tolist()):
            if self.is_perception[i]:
                s[1 + i, max(x - v, 0) : x + v + 1, max(y - v, 0) : y + v + 1] = 2.0
            s[1 + i, x, y] = 1.0
        return s

    def _render_codes(self, fire_only: bool = False) -> np.ndarray:
        codes = np.where(self.pruned, 3, np.where(self.sensed & self.fire, 2, self.fire * 1))
        if fire_only:
            return codes
        codes = codes.astype(np.int64)
        p, a = self.is_perception, ~self.is_perception
        codes[self._pos[p, 0], self._pos[p, 1]] = 4
        codes[self._pos[a, 0], self._pos[a, 1]] = 6
        return codes

    def _observe(self) -> dict[str, Any]:
        w, v = self.world_size, self.vision
        side = 2 * v + 1
        layers, inner = self._layers, self._inner
        fire, sensed, pruned = self.fire, self.sensed, self.pruned
        live = fire & ~pruned
        np.logical_and(live, ~sensed, out=inner[1], casting="unsafe")
        np.logical_and(live, sensed, out=inner[2], casting="unsafe")
        inner[3] = pruned
        layers[4:] = 0.0
        np_ = self.n_perception
        pos = self._pos.tolist()
        for i, (x, y) in enumerate(pos):
            if i < np_:
                inner[4 + i, x, y] = 1.0
                inner[4 + np_ + i, max(x - v, 0) : x + v + 1, max(y - v, 0) : y + v + 1] = 1.0
            else:
                inner[4 + 2 * np_ + (i - np_), x, y] = 1.0
        fov = np.empty((self.n, self.n_channels, side, side), dtype=np.float32)
        vec: list[float] = []
        for i, (x, y) in enumerate(pos):
            fov[i] = layers[:, x : x + side, y : y + side]
            vec += (x / (w - 1), y / (w - 1), float(self._is_p[i]))
        agent = np.array(vec, dtype=np.float32).reshape(self.n, 3)
        masks = self._masks
        return {
            a: {"fov": fov[i], "agent": agent[i], "action_mask": masks[i].copy()}
            for i, a in enumerate(self.possible_agents)
        }
