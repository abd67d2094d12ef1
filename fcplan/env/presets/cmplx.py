"""Presets ``cmplx1`` and ``cmplx2``: the reference ``FireCommanderHard`` / ``Extreme``, seeded.

``fcplan.env.motion.parallel_env(preset="cmplx1" | "cmplx2", **kwargs)`` returns a
:class:`CmplxEnv` of that variant (:class:`~fcplan.env.presets.cmplx1.Cmplx1Env`,
:class:`~fcplan.env.presets.cmplx2.Cmplx2Env`). FIRECOMMANDER.md section 6.2 is the reference;
cells are ``[x, y]``.

World
    A ``W x W`` grid (100) with ``n_regions`` (2) FARSITE fire regions run by
    :class:`fcplan.fire.Fire`: centres drawn in ``[20, W - 21]`` per axis, 5..14 fronts each in
    the centre's +-5 box, fuel 5, wind speed 5, wind direction one of 0/45/90/135/180 degrees,
    no delay, one fire step per env step (dt = 1). No facilities, battery, tank or depot.

Agents
    ``perception_0..P-1`` then ``action_0..A-1`` (``P = A = 2``), all starting at
    ``(W - 10, W / 10)`` at altitude ``init_alt`` (10).

Action space
    Perception ``Discrete(6)``: 0 ``x - 5``, 1 ``x + 5``, 2 ``y - 5``, 3 ``y + 5`` (clipped to
    ``[0, W-1]``; speeds ``p_vel``/``a_vel``), 4 ``z + 2``, 5 ``z - 2`` (clipped to ``[5, 15]``).
    Action ``Discrete(4)`` in ``cmplx1`` (moves only: action agents try to prune every step),
    ``Discrete(5)`` in ``cmplx2`` (4 = dump: the only way to prune). That is the only difference
    between the two presets, as in the reference.

Step (reference order)
    Agents move; the fire propagates; each perception agent senses ``round(c n)`` of the ``n``
    burning cells in its box ``+-z`` (drawn without replacement), ``c = 1 - 0.06 (z - 10)``
    clipped to ``[0, 1]``; each pruning action agent draws ``round(0.8 n)`` of the burning cells
    in its ``+-z`` box and, if one of them is sensed, puts out all of them.

Observation space
    ``Dict``: ``"fov"`` ``Box(0, 1, (6, 2 max_alt + 1, 2 max_alt + 1), float32)`` crop centred
    on the agent: 0 inside its current ``+-z`` box and the map, 1 cells it sensed (perception) or
    pruned (action) this step (the reference ``get_FOV``), 2 known fire (sensed, burning),
    3 pruned, 4 outside the map, 5 other agents; ``"agent"`` ``Box(0, 1, (4,))``: ``x / (W-1)``,
    ``y / (W-1)``, ``(z - min_alt) / (max_alt - min_alt)``, is perception; ``"action_mask"``
    (all ones: moves and altitude changes are clipped, as in the reference).

State
    ``state()``: ``(W, W)`` float32 codes as the reference state: 0 none, 1 sensed fire,
    2 pruned, 3 perception location, 4 perception scope, 5 action location, 6 action scope,
    written scopes, then locations (perception, then action), then sensed fire, then pruned.

Reward (shared scalar, ``reward="rf1" | "rf2" | "rf3"``, default ``"rf1"``)
    RF1 = ``2 |sensed| + 20 |pruned|`` on the cumulative counts (``rf1_mode="cumulative"``, our
    reading of the spec; ``rf1_mode="change"`` uses their change per step like ``base``) minus
    :func:`fcplan.env.presets.core.rf1_structure_penalty` with ``comm_range`` 30; RF2 = -1
    while a cell burns; RF3 = ``-0.1 |burning|``. On success ``success_bonus`` (1000) is added.

Termination and truncation
    Terminated (success) once ``|pruned| / (|burning| + |pruned|) >= a_c_threshold``; the
    reference default 1.5 can never be reached, so episodes end by truncation at ``max_steps``
    (200, the reference's conventional episode length). ``infos`` carry
    ``perception_complete`` (``|sensed| / (|burning| + |pruned|)``) and ``action_complete``.

Deviations from the reference
    Seeded (``reset(seed)``, one generator per concern) instead of the global ``np.random`` /
    ``random``; PettingZoo API with spaces, ``state()`` and ``render()``; the sensing confidence
    is clipped to ``<= 1`` (the reference raised ``ValueError`` below z = 10, crashing most
    random episodes); truncation at ``max_steps`` (the reference had no time limit and an
    unreachable default threshold); fixed-size, padded FOV crops for every agent (the reference
    returned an unpadded, variable-shape map for perception agents only); the fire is
    :class:`fcplan.fire.Fire`, which fixes the reference's fire defects (ignition cells burn,
    fronts leaving the map die instead of a phantom cell at (0, 0), a shared terrain field);
    ``round`` is numpy's round-half-to-even, as Python's.

Examples
--------
>>> env = CmplxEnv(variant="cmplx2")
>>> obs, infos = env.reset(seed=0)
>>> [int(env.action_space(a).n) for a in env.agents]
[6, 6, 5, 5]
>>> obs["action_0"]["fov"].shape, env.state().shape
((6, 31, 31), (100, 100))
>>> obs, rewards, terms, truncs, infos = env.step({a: 0 for a in env.agents})
>>> sorted(set(rewards.values())) == [rewards["action_1"]]  # one shared reward
True
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from fcplan.env.presets.core import (
    MOVES,
    PresetEnv,
    StepResult,
    rf1_penalty_small,
    rf1_structure_penalty,
)
from fcplan.errors import EnvError

__all__ = ["CmplxEnv", "WIND_DIRECTIONS"]

# render colours by state code: none, sensed fire, pruned, P, P scope, A, A scope
_PALETTE = np.array(
    [[235, 235, 220], [255, 90, 0], [70, 70, 70], [30, 90, 255],
     [190, 210, 255], [0, 160, 60], [190, 235, 200]],
    dtype=np.uint8,
)  # fmt: skip

#: Wind directions (degrees) the reference draws from.
WIND_DIRECTIONS = (0, 45, 90, 135, 180)
_N_FOV = 6
# fov channels
_BOX, _THIS_STEP, _KNOWN, _PRUNED, _OUTSIDE, _AGENTS = range(_N_FOV)
_MOVES = [tuple(m) for m in MOVES.tolist()]
#: teams up to this size compute the RF1 structure penalty in Python
_PY_AGENTS = 16


class CmplxEnv(PresetEnv):
    """The ``cmplx1`` / ``cmplx2`` presets (module docstring: spaces, rules, deviations)."""

    metadata = {"name": "fcplan_cmplx_v0", "render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        *,
        variant: str = "cmplx1",
        world_size: int = 100,
        n_regions: int = 2,
        n_perception: int = 2,
        n_action: int = 2,
        comm_range: float = 30.0,
        init_alt: int = 10,
        p_vel: int = 5,
        a_vel: int = 5,
        vert_vel: int = 2,
        min_alt: int = 5,
        max_alt: int = 15,
        prune_confidence: float = 0.8,
        a_c_threshold: float = 1.5,
        reward: str = "rf1",
        rf1_mode: str = "cumulative",
        success_bonus: float = 1000.0,
        max_steps: int = 200,
        render_mode: str | None = None,
        render_size: int = 400,
    ) -> None:
        from gymnasium import spaces

        if variant not in ("cmplx1", "cmplx2"):
            raise EnvError(f"variant: must be cmplx1 or cmplx2 (got {variant!r})")
        self._setup_agents(n_perception, n_action)
        w = int(world_size)
        if w < 41:
            raise EnvError(f"world_size: must be >= 41 (fire centres lie in 20..W-21; got {w})")
        if int(n_regions) < 1:
            raise EnvError(f"n_regions: must be >= 1 (got {n_regions})")
        if not 0 <= min_alt <= init_alt <= max_alt:
            raise EnvError(
                f"init_alt: must satisfy 0 <= min_alt <= init_alt <= max_alt "
                f"(got {min_alt}, {init_alt}, {max_alt})"
            )
        self._check_common(reward, max_steps, render_mode)
        if rf1_mode not in ("cumulative", "change"):
            raise EnvError(f"rf1_mode: must be cumulative or change (got {rf1_mode!r})")
        if not 0.0 <= prune_confidence <= 1.0:
            raise EnvError(f"prune_confidence: must be in 0..1 (got {prune_confidence})")
        self.variant, self.world_size, self.n_regions = variant, w, int(n_regions)
        self.comm_range, self.init_alt = float(comm_range), int(init_alt)
        self.vert_vel, self.min_alt, self.max_alt = int(vert_vel), int(min_alt), int(max_alt)
        self.prune_confidence, self.a_c_threshold = float(prune_confidence), float(a_c_threshold)
        self.reward_name, self.rf1_mode = reward, rf1_mode
        self.success_bonus, self.max_steps = float(success_bonus), int(max_steps)
        self.render_mode, self.render_size = render_mode, int(render_size)
        self._speed = np.where(self.is_perception, int(p_vel), int(a_vel)).astype(np.int64)
        a_actions = 5 if variant == "cmplx2" else 4
        n_actions = np.where(self.is_perception, 6, a_actions)
        self._default_action = np.zeros(self.n, dtype=np.int64)
        side = 2 * self.max_alt + 1
        self._setup_spaces(
            n_actions, (_N_FOV, side, side), 4, spaces.Box(0.0, 6.0, (w, w), np.float32)
        )
        self._palette = _PALETTE
        self._speed_l = self._speed.tolist()
        self._is_p = self.is_perception.tolist()
        self._p_rows = np.flatnonzero(self.is_perception).tolist()
        self._a_rows = np.flatnonzero(~self.is_perception).tolist()
        # the map padded by max_alt on every side, one layer per fov channel: channels 2-4 are
        # kept up to date by the step (known fire and pruned cells change in a few cells), 5
        # marks the cells with an agent; 0-1 stay zero (each crop gets its own); a crop is a
        # window of it
        h = w + 2 * self.max_alt
        self._h = h
        self._grid = np.zeros((_N_FOV, h, h), dtype=np.float32)
        self._windows = sliding_window_view(self._grid, (side, side), axis=(1, 2))
        self._flat = [self._grid[k].reshape(-1) for k in range(_N_FOV)]
        r = self.max_alt
        cx = np.arange(w, dtype=np.int64) + r
        #: flat map cell x * W + y -> flat index in a padded layer
        self._lut = (cx[:, None] * h + cx[None, :]).reshape(-1)
        #: the windows with the channel axis third: ``[xs, ys]`` gathers (N, 6, side, side)
        self._windows_t = np.moveaxis(self._windows, 0, 2)
        xs = np.arange(w, dtype=np.int64)
        #: flat map cell x * W + y -> x * side + y
        self._side_lut = (xs[:, None] * side + xs[None, :]).reshape(-1)

    # ------------------------------------------------------------------ episode
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
        """Draw fire regions, start the team; return ``(observations, infos)``."""
        from fcplan.fire import Fire
        from fcplan.scenario import FireRegion

        ss = self._next_seed(seed)
        rng_layout, rng_fire, self._rng_sense, self._rng_prune = (
            np.random.default_rng(s) for s in ss.spawn(4)
        )
        w = self.world_size
        regions = []
        for _ in range(self.n_regions):
            cx, cy = rng_layout.integers(20, w - 20, size=2)
            regions.append(
                FireRegion(
                    center=(float(cx), float(cy)),
                    fronts=int(rng_layout.integers(5, 15)),
                    delay_s=0.0,
                    fuel=5.0,
                    wind_speed=5.0,
                    wind_dir_deg=float(rng_layout.choice(WIND_DIRECTIONS)),
                    half_width=5.0,
                )
            )
        self.regions = tuple(regions)
        self.fire = Fire(regions, w, 10, rng_fire)
        self.sensed = np.zeros((w, w), dtype=bool)
        self._pos = np.tile(np.array([w - 10, w // 10], dtype=np.int64), (self.n, 1))
        self._z = np.full(self.n, self.init_alt, dtype=np.int64)
        self._this_step = [np.zeros(0, dtype=np.int64) for _ in range(self.n)]
        g, r = self._grid, self.max_alt
        g[:] = 0.0
        g[_OUTSIDE] = 1.0
        g[_OUTSIDE, r : r + w, r : r + w] = 0.0
        self._agent_cells: list[int] = []
        self._shared: list[float] = []
        self._score = 0.0
        self._n_sensed = 0
        self.steps = 0
        self.agents = list(self.possible_agents)
        return self._observe(), {a: self._progress() for a in self.agents}

    def step(self, actions: dict[str, Any]) -> StepResult:
        """One step with ``{agent: action}`` (missing agents take action 0)."""
        if not self.agents:
            raise EnvError("step: the episode is over; call reset()")
        from fcplan.fire import BURNING

        acts = self._actions(actions)
        w = self.world_size
        # 1. move (a loop over a few agents on Python ints: cheaper than numpy here)
        pos, zs = self._pos.tolist(), self._z.tolist()
        lo, hi, vz = self.min_alt, self.max_alt, self.vert_vel
        for i, (a, sp, is_p) in enumerate(zip(acts, self._speed_l, self._is_p, strict=True)):
            if a < 4:
                dx, dy = _MOVES[a]
                x, y = pos[i][0] + dx * sp, pos[i][1] + dy * sp
                pos[i] = [min(max(x, 0), w - 1), min(max(y, 0), w - 1)]
            z = zs[i]
            if is_p and a == 4:
                z += vz
            elif is_p and a == 5:
                z -= vz
            zs[i] = min(max(z, lo), hi)
        self._pos = np.array(pos, dtype=np.int64).reshape(self.n, 2)
        self._z = np.array(zs, dtype=np.int64)
        # 2. fire
        self.fire.step()
        state = self.fire.state
        known, pruned = self._flat[_KNOWN], self._flat[_PRUNED]
        lut = self._lut
        sensed = self.sensed.reshape(-1)
        # 3. sensing by each perception agent
        for i in self._p_rows:
            cells = self._burning_in_box(self._box_of(pos[i], zs[i]), state, BURNING)
            c = min(1.0, max(0.0, 1.0 - 0.06 * (zs[i] - 10)))
            k = round(c * cells.size)  # (half to even, as np.round)
            got = self._rng_sense.choice(cells, size=k, replace=False) if k else cells[:0]
            if got.size:
                self._n_sensed += int(np.count_nonzero(~sensed[got]))
                sensed[got] = True
                known[lut[got]] = 1.0  # (sensed cells burn: pruned ones are never sensed)
            self._this_step[i] = got
        # 4. pruning by each action agent (every step in cmplx1, on dump in cmplx2)
        every = self.variant == "cmplx1"
        for i in self._a_rows:
            got = _EMPTY
            if every or acts[i] == 4:
                cells = self._burning_in_box(self._box_of(pos[i], zs[i]), state, BURNING)
                k = round(self.prune_confidence * cells.size)
                pick = self._rng_prune.choice(cells, size=k, replace=False) if k else cells[:0]
                if pick.size and sensed[pick].any():
                    got = self.fire.prune(pick)
                    idx = lut[got]
                    known[idx] = 0.0
                    pruned[idx] = 1.0
            self._this_step[i] = got
        self.steps += 1
        n_burn, n_pruned = int(self.fire.n_burning), int(self.fire.n_pruned)
        total = n_burn + n_pruned
        success = total > 0 and n_pruned / total >= self.a_c_threshold
        r = self._reward(n_burn, n_pruned, pos) + (self.success_bonus if success else 0.0)
        timeout = self.steps >= self.max_steps and not success
        obs = self._observe()
        return self._finish(obs, dict.fromkeys(self.agents, r), success, timeout)

    def _box_of(self, p: Sequence[int], z: int) -> tuple[int, int, int, int]:
        """The ``+-z`` box around position ``p`` (Python ints), clipped to the map."""
        x, y = p
        w = self.world_size
        return max(x - z, 0), min(x + z + 1, w), max(y - z, 0), min(y + z + 1, w)

    def _box(self, i: int | np.integer[Any]) -> tuple[int, int, int, int]:
        x, y = self._pos[i]
        z, w = int(self._z[i]), self.world_size
        return max(x - z, 0), min(x + z + 1, w), max(y - z, 0), min(y + z + 1, w)

    def _burning_in_box(
        self, box: tuple[int, int, int, int], state: np.ndarray, burning: int
    ) -> np.ndarray:
        """Flat indices of the burning cells in the cell range ``box`` (``x0, x1, y0, y1``), in
        row-major order."""
        x0, x1, y0, y1 = box
        # only the part inside the fire's bounding box (inclusive) can hold burning cells
        bx0, bx1, by0, by1 = self.fire.burn_box
        x0, x1 = max(x0, bx0), min(x1, bx1 + 1)
        y0, y1 = max(y0, by0), min(y1, by1 + 1)
        if x1 <= x0 or y1 <= y0:
            return _EMPTY
        bx, by = np.nonzero(state[x0:x1, y0:y1] == burning)
        return (bx + x0) * self.world_size + (by + y0)

    def _reward(self, n_burn: int, n_pruned: int, pos: list[list[int]]) -> float:
        if self.reward_name == "rf2":
            return -1.0 if n_burn > 0 else 0.0
        if self.reward_name == "rf3":
            return -0.1 * n_burn
        score = 2.0 * self._n_sensed + 20.0 * n_pruned
        if self.rf1_mode == "change":
            score, self._score = score - self._score, score
        if self.n <= _PY_AGENTS:
            return score - rf1_penalty_small(pos, self._is_p, self.comm_range)
        return score - rf1_structure_penalty(self._pos, self.is_perception, self.comm_range)

    def _progress(self) -> dict[str, float]:
        total = int(self.fire.n_burning) + int(self.fire.n_pruned)
        return {
            "perception_complete": self._n_sensed / total if total else 0.0,
            "action_complete": float(self.fire.n_pruned / total) if total else 0.0,
        }

    # ------------------------------------------------------------------ observations
    def state(self) -> np.ndarray:
        """``(W, W)`` float32 reference state codes (module docstring)."""
        return self._render_codes().astype(np.float32)

    def _render_codes(self) -> np.ndarray:
        from fcplan.fire import BURNING, PRUNED

        w = self.world_size
        codes = np.zeros((w, w), dtype=np.int64)
        for scope, rows in (
            (4, np.flatnonzero(self.is_perception)),
            (6, np.flatnonzero(~self.is_perception)),
        ):
            for i in rows:
                x0, x1, y0, y1 = self._box(i)
                codes[x0:x1, y0:y1] = scope
        for loc, mask in ((3, self.is_perception), (5, ~self.is_perception)):
            codes[self._pos[mask, 0], self._pos[mask, 1]] = loc
        state = self.fire.state
        codes[(state == BURNING) & self.sensed] = 1
        codes[state == PRUNED] = 2
        return codes

    def _observe(self) -> dict[str, Any]:
        w, r = self.world_size, self.max_alt
        side = 2 * r + 1
        n = self.n
        pos = self._pos.tolist()
        zs = self._z.tolist()
        # the agents layer: 1 at every agent's cell; each crop's centre says whether another
        # agent shares the cell
        h = self._h
        cells = [(x + r) * h + y + r for x, y in pos]
        if cells != self._agent_cells:
            layer = self._flat[_AGENTS]
            for c in self._agent_cells:
                layer[c] = 0.0
            for c in cells:
                layer[c] = 1.0
            count: dict[int, int] = {}
            for c in cells:
                count[c] = count.get(c, 0) + 1
            self._shared = [1.0 if count[c] > 1 else 0.0 for c in cells]
            self._agent_cells = cells
        xs, ys = [p[0] for p in pos], [p[1] for p in pos]
        fov = self._windows_t[xs, ys]  # (one gather of the agents' windows, a fresh array)
        flat = fov.reshape(-1)
        area = side * side
        vec: list[float] = []
        dz = max(self.max_alt - self.min_alt, 1)
        for i, ((x, y), z) in enumerate(zip(pos, zs, strict=True)):
            bx0, bx1, by0, by1 = self._box_of((x, y), z)
            fov[i, _BOX, bx0 - x + r : bx1 - x + r, by0 - y + r : by1 - y + r] = 1.0
            got = self._this_step[i]
            if got.size:  # (map cell -> its place in the crop, through the cell's x * side + y)
                flat[
                    self._side_lut[got]
                    + ((i * _N_FOV + _THIS_STEP) * area - (x - r) * side - (y - r))
                ] = 1.0
            vec += (x / (w - 1), y / (w - 1), (z - self.min_alt) / dz, float(self._is_p[i]))
        fov[:, _AGENTS, r, r] = self._shared
        agent = np.array(vec, dtype=np.float32).reshape(n, 4)
        masks = self._masks
        return {
            a: {"fov": fov[i], "agent": agent[i], "action_mask": masks[i].copy()}
            for i, a in enumerate(self.possible_agents)
        }


_EMPTY = np.zeros(0, dtype=np.int64)
