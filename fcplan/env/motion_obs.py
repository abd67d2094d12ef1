"""Observations of the motion-level environment: agent vectors, action masks, crops and state.

:class:`MotionObs` builds what :class:`fcplan.env.motion.MotionEnv` hands its agents each tick
(the observation and state spaces are documented there):

* the ``"agent"`` vector (15 floats: position, altitude in its range, battery, tank, battery
  needed to fly home, mode one-hot, roles, time, sensing confidence, speed);
* the ``"action_mask"``: which moves stay on the map, which altitude changes stay in range,
  whether a dump is possible, and nothing but ``stay`` for an agent flown home;
* the ``"fov"`` crop of the coarse maps (:class:`fcplan.env.motion_grid.CoarseMaps`);
* the global :meth:`MotionObs.state` for centralised critics.

Agent vectors and masks come from a plain Python loop for small teams (up to
:data:`_PY_AGENTS` agents: a few numpy calls cost more than the whole loop there) and from numpy
beyond; both give identical results. The per-episode constants they need are computed once by
:meth:`MotionObs.reset`.

Examples
--------
>>> from fcplan.env.motion import MotionEnv
>>> env = MotionEnv("practice")
>>> obs, _ = env.reset(seed=0)
>>> vec, masks, cx, cy = env.observations.agent_arrays()
>>> vec.shape, [m.tolist() for m in masks][2], (cx[0], cy[0])
((4, 15), [1, 1, 1, 1, 1, 1], (3, 21))
"""

from __future__ import annotations

import math

import numpy as np

from fcplan.env.motion_grid import FACILITY, KNOWN_N, LAKE, PRUNED_N, CoarseMaps
from fcplan.scenario import Scenario
from fcplan.team import DRAIN_PER_PX
from fcplan.world import StepInfo, World

__all__ = ["MotionObs", "N_AGENT_FEATURES", "N_FOV", "N_STATE", "NEVER"]

N_AGENT_FEATURES = 15
N_FOV = 7
N_STATE = 8
#: the column of the legality table that is never true (actions an agent does not have)
NEVER = 8
_N_AGENT_FEATURES, _N_FOV, _N_STATE = N_AGENT_FEATURES, N_FOV, N_STATE
#: teams up to this size build agent vectors and masks in a Python loop (faster than numpy)
_PY_AGENTS = 16
# team modes (fcplan.team.Mode)
_IDLE, _ACTIVE = 0, 1
#: mode one-hot features (idle, active, returning, homing) per team mode
_ONE_HOT = tuple(tuple(float(m == k) for k in range(4)) for m in range(4))
#: stay, west, east, north, south of an agent flown home (only stay is legal)
_HOMING_MOVES = (True, False, False, False, False)


class MotionObs:
    """The observation side of one :class:`fcplan.env.motion.MotionEnv` (module docstring).

    Parameters
    ----------
    scenario : Scenario
    letters : list of str
        Role letter of each agent (``"P"``, ``"A"``, ``"H"``).
    n_actions : ndarray, (N,) int64
        Actions of each agent.
    cond_of : ndarray, (N, 8) int64
        Per agent and action, the column of the legality table that makes it legal
        (:data:`NEVER`: an action the agent does not have).
    cell_px, view : int
        Coarse cell side and crop side.
    maps : CoarseMaps
        The coarse maps the crops and the state are read from.

    Attributes
    ----------
    mask_lists : list of tuple of bool
        Each agent's action mask of the last :meth:`agent_arrays`.
    free_list : list of bool
        Whether each agent took orders then (not flown home).
    """

    def __init__(
        self,
        scenario: Scenario,
        letters: list[str],
        n_actions: np.ndarray,
        cond_of: np.ndarray,
        cell_px: int,
        view: int,
        maps: CoarseMaps,
    ) -> None:
        n = len(letters)
        self.scenario = scenario
        self.possible_agents = [a.id for a in scenario.agents]
        self.cell_px, self.view = cell_px, view
        self._n = n
        self._letters = letters
        self._n_actions_list = n_actions.tolist()
        #: the action mask tuple of each role when every action is legal
        self._all_legal = {r: (True,) * int(k) for r, k in zip(letters, n_actions, strict=True)}
        self._cond_of = cond_of
        self._cond = np.zeros((n, NEVER + 1), dtype=bool)
        self._cond[:, 0] = True
        self._roles = np.array(
            [[a.role.can_sense, a.role.can_act] for a in scenario.agents], dtype=np.float32
        ).reshape(n, 2)
        self._modes = np.arange(4)
        self._arange = np.arange(n)
        self._maps = maps
        self.mask_lists: list[tuple[bool, ...]] = []
        self.free_list: list[bool] = []

    def reset(self, world: World) -> None:
        """Compute the per-episode constants of ``world`` (just reset)."""
        self._world = world
        self._team = team = world.team
        span = team.alt_hi - team.alt_lo
        inv_span = np.where(span > 0, 1.0 / np.where(span > 0, span, 1.0), 0.0)
        w = float(self.scenario.world_size)
        self._w1 = w - 1.0
        self._speed2 = team.speed[:, None].copy()
        self._hi_lim = self._w1 - self._speed2
        self._z_hi = team.alt_hi - 1e-9
        self._z_lo = team.alt_lo + 1e-9
        self._inv_w = 1.0 / w
        self._inv_span = inv_span
        self._inv_cap = 1.0 / team.battery_capacity
        self._inv_tank = 1.0 / np.maximum(team.tank_capacity, 1)
        self._drain_per_cap = DRAIN_PER_PX / team.battery_capacity
        self._can_sense = team.can_sense.astype(np.float64)
        vt = np.zeros((self._n, _N_AGENT_FEATURES), dtype=np.float32)
        vt[:, 10:12] = self._roles
        vt[:, 14] = team.speed / w
        self._vec_template = vt
        # per agent constants for the small-team loop of agent_arrays
        self._py = list(
            zip(
                team.home[:, 0].tolist(),
                team.home[:, 1].tolist(),
                team.alt_lo.tolist(),
                inv_span.tolist(),
                self._inv_cap.tolist(),
                self._inv_tank.tolist(),
                team.can_sense.astype(np.float64).tolist(),
                team.can_act.astype(np.float64).tolist(),
                (team.speed / w).tolist(),
                self._drain_per_cap.tolist(),
                team.speed.tolist(),
                self._hi_lim[:, 0].tolist(),
                self._z_hi.tolist(),
                self._z_lo.tolist(),
                self._letters,
                strict=True,
            )
        )
        #: action mask tuples -> int8 arrays (copied into each observation)
        self._mask_cache: dict[tuple[bool, ...], np.ndarray] = {}
        self._n_ticks = self.scenario.n_ticks
        self._maps.reset()

    def update(self, info: StepInfo) -> None:
        """Fold one tick of the world into the coarse maps."""
        self._maps.update(info, self._world)

    def agent_arrays(self) -> tuple[np.ndarray, list, list, list]:
        """``(vectors (n, 15) float32, masks, coarse x, coarse y)``: ``masks[i]`` is agent
        ``i``'s fresh ``(n_actions,)`` int8 action mask. Also keeps the masks as tuples of bools
        in ``self.mask_lists`` and the agents that take orders in ``self.free_list`` (read by
        :meth:`step`). A plain Python loop over the agents for small teams (a few numpy calls
        cost more than the whole loop there), numpy beyond :data:`_PY_AGENTS` agents; both give
        identical results."""
        team = self._team
        inv_w = self._inv_w
        if self._n > _PY_AGENTS:
            vec, mask = self._agent_vectors(), self._masks()
            self.free_list = self._free.tolist()
            k = self._n_actions_list
            self.mask_lists = [tuple(row[: k[i]]) for i, row in enumerate(mask.tolist())]
            masks = [mask[i, : k[i]] for i in range(self._n)]
            cell = (team.pos // self.cell_px).astype(np.int64)  # agents never leave the map
            return vec, masks, cell[:, 0].tolist(), cell[:, 1].tolist()
        cpx = self.cell_px
        pos, z, zt = team.pos.tolist(), team.z.tolist(), team.z_target.tolist()
        bat, tank, mode = team.battery.tolist(), team.tank.tolist(), team.mode.tolist()
        tf = self._world.tick / self._n_ticks
        cache = self._mask_cache
        vecs: list = []
        rows, masks, free_all, cxs, cys = [], [], [], [], []
        for (
            (hx, hy, lo, inv_span, inv_cap, inv_tank, sense, act, spw, drain, sp, hi_lim, z_hi,
             z_lo, letter),
            (x, y), zi, zti, bi, ti, m,
        ) in zip(self._py, pos, z, zt, bat, tank, mode, strict=True):  # fmt: skip
            zn = (zi - lo) * inv_span
            free = m <= _ACTIVE
            home = math.sqrt((hx - x) ** 2 + (hy - y) ** 2) * drain
            conf = 1.0 - 0.6 * zn
            vecs += (
                x * inv_w,
                y * inv_w,
                zn,
                bi * inv_cap,
                ti * inv_tank,
                home if home < 1.0 else 1.0,
                *_ONE_HOT[m],
                sense,
                act,
                tf,
                ((conf if conf > 0.4 else 0.4) if sense else 0.0),
                spw,
            )
            # the action table's order: stay, west, east, north, south, then role actions
            if (
                free
                and sp <= x <= hi_lim
                and sp <= y <= hi_lim
                and (letter == "A" or z_lo < zti < z_hi)
                and (letter == "P" or ti > 0)
            ):  # (the usual case: everything is legal)
                row = self._all_legal[letter]
            else:
                moves = (
                    (True, x >= sp, x <= hi_lim, y >= sp, y <= hi_lim) if free else _HOMING_MOVES
                )
                if letter == "P":
                    row = (*moves, zti < z_hi, zti > z_lo)
                elif letter == "A":
                    row = (*moves, free and ti > 0)
                else:
                    row = (*moves, zti < z_hi, zti > z_lo, free and ti > 0)
            rows.append(row)
            # (the tuple says its agent's role by its length: one cached array per tuple)
            arr = cache.get(row)
            if arr is None:
                arr = cache[row] = np.array(row, dtype=np.int8)
            masks.append(arr.copy())
            free_all.append(free)
            cxs.append(int(x // cpx))
            cys.append(int(y // cpx))
        self.free_list = free_all
        self.mask_lists = rows
        vec = np.array(vecs, dtype=np.float32).reshape(self._n, _N_AGENT_FEATURES)
        return vec, masks, cxs, cys

    def _masks(self) -> np.ndarray:
        """(n, 8) int8 legal actions, from a (n, 8) table of conditions picked per action."""
        team = self._team
        mode = team.mode
        free = mode <= _ACTIVE
        self._free = free
        cond = self._cond
        pos, speed = team.pos, self._speed2
        np.greater_equal(pos, speed, out=cond[:, 1:3])  # west, north stay inside
        np.less_equal(pos, self._hi_lim, out=cond[:, 3:5])  # east, south
        cond[:, 1:5] &= free[:, None]
        np.less(team.z_target, self._z_hi, out=cond[:, 5])
        np.greater(team.z_target, self._z_lo, out=cond[:, 6])
        np.greater(team.tank, 0, out=cond[:, 7])
        cond[:, 7] &= free
        return cond[self._arange[:, None], self._cond_of].view(np.int8)

    def _agent_vectors(self) -> np.ndarray:
        team = self._team
        v = self._vec_template.copy()
        np.multiply(team.pos, self._inv_w, out=v[:, 0:2], casting="same_kind")
        zn = team.z - team.alt_lo
        zn *= self._inv_span
        v[:, 2] = zn
        np.multiply(team.battery, self._inv_cap, out=v[:, 3], casting="same_kind")
        np.multiply(team.tank, self._inv_tank, out=v[:, 4], casting="same_kind")
        d = team.home - team.pos
        d *= d
        home = d[:, 0] + d[:, 1]
        np.sqrt(home, out=home)
        home *= self._drain_per_cap
        np.minimum(home, 1.0, out=v[:, 5], casting="same_kind")
        np.equal(team.mode[:, None], self._modes, out=v[:, 6:10], casting="unsafe")
        v[:, 12] = self._world.tick / self._n_ticks
        # sensing confidence 1 - 0.6 z' (clipped to [0.4, 1]), 0 for agents without camera
        zn *= -0.6
        zn += 1.0
        np.maximum(zn, 0.4, out=zn)
        zn *= self._can_sense
        v[:, 13] = zn
        return v

    def observe(self) -> dict[str, dict[str, np.ndarray]]:
        vec, masks, cx, cy = self.agent_arrays()
        # (N, 7, V, V), a fresh array: known and pruned come scaled and clipped, the agents
        # layer as "another agent is there", staleness clipped
        fov = self._maps.observe(cx, cy, self._world.tick, _N_FOV)
        # (indexing the arrays: iterating over them costs more)
        return {
            a: {"fov": fov[i], "agent": vec[i], "action_mask": masks[i]}
            for i, a in enumerate(self.possible_agents)
        }

    def state(self) -> np.ndarray:
        """Global state ``(8, nc, nc)`` float32 (module docstring)."""
        maps, team = self._maps, self._team
        inner = maps.inner
        nc = maps.nc
        s = np.zeros((_N_STATE, nc, nc), dtype=np.float32)
        inv_c = 1.0 / self.cell_px
        np.minimum(maps.burning_layer() * inv_c, 1.0, out=s[0])
        np.minimum(inner[KNOWN_N] * inv_c, 1.0, out=s[1])
        np.minimum(inner[PRUNED_N] * inv_c, 1.0, out=s[2])
        s[3] = maps.staleness(self._world.tick)
        cx, cy = maps.cells(team.pos)
        np.add.at(s[4], (cx[team.can_sense], cy[team.can_sense]), 1.0)
        np.add.at(s[5], (cx[team.can_act], cy[team.can_act]), 1.0)
        s[6] = inner[LAKE]
        s[7] = inner[FACILITY]
        return s
