"""Motion-level PettingZoo environment: one step is one simulator tick.

``parallel_env(scenario)`` returns a :class:`MotionEnv`, a PettingZoo ``ParallelEnv`` on
:class:`fcplan.World`: every UAV of the scenario is an agent and chooses a discrete move every
tick. ``parallel_env(preset="base" | "cmplx1" | "cmplx2")`` (or the preset name in place of the
scenario) returns one of the reference MARL package's three environments instead
(:mod:`fcplan.env.motion_presets`).

Agents
    The scenario's agent ids in team order (``"P1", "P2", "A1", ...``). All agents stay until the
    episode ends.

Action space
    ``Discrete(n)`` per agent, ``n`` set by its role (a move covers the agent's speed in px;
    ``x`` grows to the right, ``y`` downward):

    ===  ==========  ==========  ==========  ===================================================
     a   perception  action      hybrid      effect
    ===  ==========  ==========  ==========  ===================================================
     0   stay        stay        stay        hover (an agent idle at its depot slot stays idle)
     1   west        west        west        ``x -= speed``
     2   east        east        east        ``x += speed``
     3   north       north       north       ``y -= speed``
     4   south       south       south       ``y += speed``
     5   climb       **dump**    climb       altitude + 5 m per 0.1 s (within the agent's range)
     6   descend                 descend     altitude - 5 m per 0.1 s
     7                           **dump**    dump this tick if a dump can do something
    ===  ==========  ==========  ==========  ===================================================

    So perception agents have ``Discrete(7)``, action agents ``Discrete(6)``, hybrids
    ``Discrete(8)``. A dump follows :mod:`fcplan.world`: each *sensed* burning cell in the agent's
    field of view is put out with its prune confidence, and only a dump that finds such a cell
    spends one tank unit (a dump that finds nothing costs nothing). The simulator's rules stay in
    force: an agent whose battery reserve runs out, or whose tank empties, is flown home
    automatically, recharges and refills there (its moves and dumps are masked meanwhile;
    altitude changes stay legal), then takes orders again; there is no go-home action. Climbing,
    descending and dumping hover for the tick. Masked (illegal) actions are executed as
    ``stay``; agents missing from the action dict stay.

Observation space
    ``Dict`` with

    * ``"fov"``: ``Box(0, 1, (7, view, view), float32)``, an egocentric crop of ``view x view``
      coarse cells of ``cell_px`` px centred on the agent's cell (:mod:`fcplan.env.motion_grid`).
      Channels: 0 known burning px / ``cell_px`` (clipped to 1), 1 pruned px / ``cell_px``
      (clipped to 1), 2 staleness ``min(1, seconds since last covered by a camera / stale_s)``
      (1 = never seen, and outside the map), 3 another agent in the cell (0/1), 4 share outside
      the map, 5 lake share, 6 facility share weighted by penalty / 5.
    * ``"agent"``: ``Box(0, 1, (15,), float32)`` own state: ``x / W``, ``y / W``, altitude in its
      range, battery / capacity, tank / capacity, battery needed to fly home / capacity,
      mode one-hot (idle, active, returning, homing), can sense, can act, time / duration,
      sensing confidence, speed / W (px per tick).
    * ``"action_mask"``: ``Box(0, 1, (n,), int8)``: 1 for legal actions. Illegal: a move or dump while
      flown home (forced return), a move leaving the map, climbing at the ceiling, descending at the floor,
      dumping with an empty tank.

State
    ``state()``: ``Box(0, inf, (8, nc, nc), float32)`` over the whole map in coarse cells
    (``nc = ceil(W / cell_px)``): true burning px / ``cell_px``, known burning, pruned (both as in
    ``fov``), staleness, perception-capable agents, action-capable agents, lakes, facilities.

Reward
    Shared by all agents: the manual's negative reward of this tick,
    ``-(0.1 |active| + sum_f PC_f n_f) / tps`` (:func:`fcplan.metrics.negative_reward_rate`), so
    the episode's return equals minus the manual's total negative reward. Optional shaping
    (off by default): ``+ sense_bonus`` per newly sensed cell, ``+ prune_bonus`` per pruned cell,
    ``- dump_cost`` per dump.

Termination and truncation
    No termination; every agent is truncated when the scenario's duration has been simulated
    (``scenario.n_ticks`` steps). The last step's ``infos[agent]["metrics"]`` holds the final
    metrics of both definitions (``{"manual": {...}, "reference2020": {...}}``).

Arguments
    ``cell_px`` (20), ``view`` (15, odd), ``stale_s`` (30.0), ``idle_rule`` (False: the
    3-second rule that sends an action agent hovering 3 s at its last goal home is switched
    off, since at this level hovering is the policy's choice), ``sense_bonus``, ``prune_bonus``,
    ``dump_cost`` (0.0), ``render_mode`` (``None`` or ``"rgb_array"``), ``render_size`` (512).

Seeding
    ``reset(seed=s)`` resets the world with :meth:`fcplan.World.reset` ``(scenario, seed=s)``, so
    the fire draws the same random numbers as ``fcplan run SCENARIO --seed s``; ``reset()``
    without a seed continues with seeds drawn from the last seed. Same seed and actions give
    identical episodes in any process. ``env.world`` is the live :class:`fcplan.World`.

Examples
--------
>>> import numpy as np
>>> from fcplan.env.motion import parallel_env
>>> env = parallel_env("practice")
>>> obs, infos = env.reset(seed=0)
>>> env.agents, int(env.action_space("P1").n), int(env.action_space("A1").n)
(['P1', 'P2', 'A1', 'A2'], 7, 6)
>>> obs["P1"]["fov"].shape, obs["P1"]["action_mask"].tolist()
((7, 15, 15), [1, 1, 1, 1, 1, 1, 1])
>>> obs, rewards, terms, truncs, infos = env.step({"P1": 2, "P2": 4, "A1": 0, "A2": 5})
>>> round(float(obs["P1"]["agent"][0] - obs["P2"]["agent"][0]) * 1200, 3)  # P1: 20 px east
20.0
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fcplan.env import EnvError
from fcplan.env.motion_grid import (
    FACILITY,
    KNOWN_N,
    LAKE,
    PRUNED_N,
    CoarseMaps,
)
from fcplan.team import CLIMB_PER_TICK, DRAIN_PER_PX

__all__ = ["MotionEnv", "parallel_env", "PRESETS", "ACTION_NAMES"]

#: Preset names accepted by :func:`parallel_env`.
PRESETS = ("base", "cmplx1", "cmplx2")

#: Action names per role letter (``P`` perception, ``A`` action, ``H`` hybrid).
ACTION_NAMES = {
    "P": ("stay", "west", "east", "north", "south", "climb", "descend"),
    "A": ("stay", "west", "east", "north", "south", "dump"),
    "H": ("stay", "west", "east", "north", "south", "climb", "descend", "dump"),
}
_MAX_ACTIONS = 8
_DIRS = {"stay": (0, 0), "west": (-1, 0), "east": (1, 0), "north": (0, -1), "south": (0, 1)}
_N_AGENT_FEATURES = 15
# columns of the legality table built by MotionEnv._masks
_COND = {
    "stay": 0,
    "west": 1,
    "north": 2,
    "east": 3,
    "south": 4,
    "climb": 5,
    "descend": 6,
    "dump": 7,
}
_NEVER = 8
_K_STAY, _K_MOVE, _K_ALTITUDE, _K_DUMP = range(4)
_STAY_SPEC = (_K_STAY, 0.0, 0.0, 0.0)
#: teams up to this size build agent vectors and masks in a Python loop (faster than numpy)
_PY_AGENTS = 16
_N_FOV = 7
_N_STATE = 8
# team modes (fcplan.team.Mode)
_IDLE, _ACTIVE = 0, 1
#: mode one-hot features (idle, active, returning, homing) per team mode
_ONE_HOT = tuple(tuple(float(m == k) for k in range(4)) for m in range(4))
#: stay, west, east, north, south of an agent flown home (only stay is legal)
_HOMING_MOVES = (True, False, False, False, False)
#: the action mask tuple of each role when every action is legal
_ALL_LEGAL = {r: (True,) * len(names) for r, names in ACTION_NAMES.items()}
#: a move sets a goal this many steps away, so the agent never arrives (see MotionEnv.step)
_GOAL_REACH = 1.5


def parallel_env(scenario=None, *, preset: str | None = None, **kwargs: Any):
    """Make a motion-level ``ParallelEnv`` on a scenario, or one of the reference presets.

    Parameters
    ----------
    scenario : Scenario, str, int or None
        A scenario or a name/path for :func:`fcplan.load_scenario`; a preset name
        (``"base"``, ``"cmplx1"``, ``"cmplx2"``) selects that preset.
    preset : {"base", "cmplx1", "cmplx2"}, optional
        The reference MARL environment to reproduce (:mod:`fcplan.env.motion_presets`).
    **kwargs
        Arguments of :class:`MotionEnv` or of the preset.

    Raises
    ------
    EnvError
        For both or neither of ``scenario`` and ``preset``, or an unknown preset.

    Examples
    --------
    >>> parallel_env(preset="cmplx2").possible_agents
    ['perception_0', 'perception_1', 'action_0', 'action_1']
    """
    if isinstance(scenario, str) and scenario in PRESETS and preset is None:
        scenario, preset = None, scenario
    if preset is not None:
        if scenario is not None:
            raise EnvError("preset: give a scenario or a preset, not both")
        from fcplan.env.motion_presets import make_preset

        return make_preset(preset, **kwargs)
    if scenario is None:
        raise EnvError("scenario: give a scenario (name, path or Scenario) or preset=")
    return MotionEnv(scenario, **kwargs)


def _parallel_base():
    from pettingzoo import ParallelEnv

    return ParallelEnv


class MotionEnv(_parallel_base()):
    """Motion-level environment on a fcplan scenario (module docstring: spaces, reward, rules)."""

    metadata = {
        "name": "fcplan_motion_v0",
        "render_modes": ["rgb_array"],
        "is_parallelizable": True,
        "render_fps": 10,
    }

    def __init__(
        self,
        scenario,
        *,
        cell_px: int = 20,
        view: int = 15,
        stale_s: float = 30.0,
        idle_rule: bool = False,
        sense_bonus: float = 0.0,
        prune_bonus: float = 0.0,
        dump_cost: float = 0.0,
        render_mode: str | None = None,
        render_size: int = 512,
    ) -> None:
        from gymnasium import spaces

        from fcplan.scenario import Scenario, load_scenario

        sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        if int(cell_px) < 1:
            raise EnvError(f"cell_px: must be >= 1 (got {cell_px})")
        if int(view) < 1 or int(view) % 2 == 0:
            raise EnvError(f"view: must be an odd number >= 1 (got {view})")
        if not stale_s > 0:
            raise EnvError(f"stale_s: must be > 0 (got {stale_s})")
        if render_mode not in (None, "rgb_array"):
            raise EnvError(f"render_mode: must be None or 'rgb_array' (got {render_mode!r})")
        self.scenario = sc
        self.cell_px, self.view, self.stale_s = int(cell_px), int(view), float(stale_s)
        self.idle_rule = bool(idle_rule)
        self.sense_bonus, self.prune_bonus = float(sense_bonus), float(prune_bonus)
        self.dump_cost = float(dump_cost)
        self.render_mode, self.render_size = render_mode, int(render_size)
        self.possible_agents = [a.id for a in sc.agents]
        self.agents: list[str] = []
        n = len(self.possible_agents)
        self._n = n
        letters = [
            "H" if (a.role.can_sense and a.role.can_act) else ("P" if a.role.can_sense else "A")
            for a in sc.agents
        ]
        self._letters = letters
        self._n_actions = np.array([len(ACTION_NAMES[r]) for r in letters], dtype=np.int64)
        # per agent and action: dx, dy (unit), dz sign, dump, is a move; and the column of the
        # condition table (see _masks) that makes it legal
        table = np.zeros((n, _MAX_ACTIONS, 5), dtype=np.float64)
        cond_of = np.full((n, _MAX_ACTIONS), _NEVER, dtype=np.int64)
        for i, r in enumerate(letters):
            for a, name in enumerate(ACTION_NAMES[r]):
                if name in _DIRS:
                    table[i, a, :2] = _DIRS[name]
                table[i, a, 2] = {"climb": 1.0, "descend": -1.0}.get(name, 0.0)
                table[i, a, 3] = name == "dump"
                table[i, a, 4] = name in _DIRS and name != "stay"
                cond_of[i, a] = _COND[name]
        self._table = table
        self._cond_of = cond_of
        self._cond = np.zeros((n, _NEVER + 1), dtype=bool)
        self._cond[:, 0] = True
        self._roles = np.array(
            [[a.role.can_sense, a.role.can_act] for a in sc.agents], dtype=np.float32
        ).reshape(n, 2)
        self._modes = np.arange(4)
        self._inv_c = 1.0 / self.cell_px  # a Python float: the fastest scalar for numpy
        self._shaping = bool(self.sense_bonus or self.prune_bonus or self.dump_cost)
        self._action_spaces = {
            a: spaces.Discrete(int(k))
            for a, k in zip(self.possible_agents, self._n_actions, strict=True)
        }
        nc = -(-sc.world_size // self.cell_px)
        self._obs_spaces = {
            a: spaces.Dict(
                {
                    "fov": spaces.Box(0.0, 1.0, (_N_FOV, self.view, self.view), np.float32),
                    "agent": spaces.Box(0.0, 1.0, (_N_AGENT_FEATURES,), np.float32),
                    "action_mask": spaces.Box(0, 1, (int(k),), np.int8),
                }
            )
            for a, k in zip(self.possible_agents, self._n_actions, strict=True)
        }
        self.state_space = spaces.Box(0.0, np.inf, (_N_STATE, nc, nc), np.float32)
        self._maps = CoarseMaps(
            sc, self.cell_px, self.view, seen_scale=1.0 / (self.stale_s * sc.ticks_per_second)
        )
        self._arange = np.arange(n)
        self._world = None
        self._reseed: np.random.Generator | None = None

    # ------------------------------------------------------------------ spaces
    def observation_space(self, agent):
        """The ``Dict`` observation space of ``agent`` (the same object every call)."""
        return self._obs_spaces[agent]

    def action_space(self, agent):
        """The ``Discrete`` action space of ``agent`` (the same object every call)."""
        return self._action_spaces[agent]

    @property
    def world(self):
        """The underlying :class:`fcplan.World` (after :meth:`reset`)."""
        return self._world

    @property
    def last_info(self):
        """The :class:`fcplan.world.StepInfo` of the last tick (None right after :meth:`reset`):
        what a scheduler-driven expert feeds its belief with
        (:mod:`fcplan.env.motion_expert`)."""
        return self._last_info

    # ------------------------------------------------------------------ episode
    def reset(self, seed: int | None = None, options: dict | None = None):
        """Start an episode; return ``(observations, infos)``."""
        from fcplan.world import World

        if seed is not None:
            self._reseed = np.random.default_rng(seed)
        elif self._reseed is None:
            self._reseed = np.random.default_rng()
            seed = int(self._reseed.integers(2**63))
        else:
            seed = int(self._reseed.integers(2**63))
        if self._world is None:
            self._world = World()
        world = self._world.reset(self.scenario, seed)
        self._team = team = world.team
        self._climb = CLIMB_PER_TICK * team.tick_scale
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
        # per agent constants for the small-team loop of _agent_arrays
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
        # per agent and action: (kind, goal dx, goal dy, altitude change)
        self._spec = [
            [
                (
                    _K_MOVE if row[4] else _K_DUMP if row[3] else _K_ALTITUDE if row[2] else 0,
                    float(row[0] * _GOAL_REACH * sp),
                    float(row[1] * _GOAL_REACH * sp),
                    float(row[2] * self._climb),
                )
                for row in self._table[i]
            ]
            for i, sp in enumerate(team.speed.tolist())
        ]
        self._n_actions_list = self._n_actions.tolist()
        #: action mask tuples -> int8 arrays (copied into each observation)
        self._mask_cache: dict[tuple, np.ndarray] = {}
        self._maps.reset()
        self._tick_rate = float(self.scenario.ticks_per_second)
        self._n_ticks = self.scenario.n_ticks
        self._penalties = world.facility_penalties
        self._fb_last = None
        self._fb_penalty = 0.0
        self._pw = self.scenario.scoring.propagation_weight
        self.agents = list(self.possible_agents)
        self._last_info = None
        return self._observe(), {a: {} for a in self.agents}

    def step(self, actions: dict):
        """Advance one tick with ``{agent: action}``; missing agents stay."""
        if not self.agents:
            raise EnvError("step: the episode is over; call reset()")
        team, world = self._team, self._world
        goal, has_goal, mode, armed = team.goal, team.has_goal, team.mode, team.armed
        pos = None
        # (each mask tuple holds exactly the agent's actions: its length bounds the action)
        for i, (a, row, spec, free) in enumerate(
            zip(self.possible_agents, self._mask_lists, self._spec, self._free_list, strict=True)
        ):
            v = actions.get(a, 0)
            try:
                if v < 0:
                    raise IndexError
                legal = row[v]
            except (IndexError, TypeError):
                raise EnvError(
                    f"action of {a}: must be an integer in 0..{len(row) - 1} (got {v!r})"
                ) from None
            kind, dx, dy, dz = spec[v] if legal else _STAY_SPEC
            if kind == _K_MOVE:
                # a goal _GOAL_REACH steps away: the agent flies exactly one step and never
                # "arrives" (an arrival would arm a dump)
                if pos is None:
                    pos = team.pos.tolist()
                x, y = pos[i]
                goal[i, 0] = x + dx
                goal[i, 1] = y + dy
                has_goal[i] = True
                mode[i] = _ACTIVE
                continue
            if free:  # hover where it is (or stay idle at its depot slot)
                has_goal[i] = False
            if kind == _K_DUMP:
                # armed for this tick; active (hovering), so an emptied tank sends it home
                armed[i] = True
                mode[i] = _ACTIVE
            elif kind == _K_ALTITUDE:
                z = float(team.z[i]) + dz
                team.z_target[i] = min(max(z, team.alt_lo[i]), team.alt_hi[i])
        if not self.idle_rule:
            team.hover_s.fill(0.0)
        info = world.step()
        team.armed.fill(False)
        self._maps.update(info, world)
        self._last_info = info
        # reward
        fb = world.facility_burning.tolist()
        if fb != self._fb_last:  # (facility counts change rarely: reuse the penalty sum)
            self._fb_last = fb
            self._fb_penalty = float(self._penalties @ world.facility_burning)
        r = -(self._pw * world.fire.n_burning + self._fb_penalty)
        r /= self._tick_rate
        if self._shaping:
            r += self.sense_bonus * info.newly_sensed.size + self.prune_bonus * info.pruned.size
            r -= self.dump_cost * len(info.dumped)
        obs = self._observe()
        agents = self.agents
        rewards = dict.fromkeys(agents, r)
        terms = dict.fromkeys(agents, False)
        if world.tick >= self._n_ticks:
            from fcplan.metrics import compute_all

            final = {k: m.as_dict() for k, m in compute_all(world.trace()).items()}
            infos = {a: {"metrics": final} for a in agents}
            truncs = dict.fromkeys(agents, True)
            self.agents = []
        else:
            infos = {a: {} for a in agents}
            truncs = dict.fromkeys(agents, False)
        return obs, rewards, terms, truncs, infos

    # ------------------------------------------------------------------ observations
    def _agent_arrays(self) -> tuple[np.ndarray, list, list, list]:
        """``(vectors (n, 15) float32, masks, coarse x, coarse y)``: ``masks[i]`` is agent
        ``i``'s fresh ``(n_actions,)`` int8 action mask. Also keeps the masks as tuples of bools
        in ``self._mask_lists`` and the agents that take orders in ``self._free_list`` (read by
        :meth:`step`). A plain Python loop over the agents for small teams (a few numpy calls
        cost more than the whole loop there), numpy beyond :data:`_PY_AGENTS` agents; both give
        identical results."""
        team = self._team
        inv_w = self._inv_w
        if self._n > _PY_AGENTS:
            vec, mask = self._agent_vectors(), self._masks()
            self._free_list = self._free.tolist()
            k = self._n_actions_list
            self._mask_lists = [tuple(row[: k[i]]) for i, row in enumerate(mask.tolist())]
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
                row = _ALL_LEGAL[letter]
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
        self._free_list = free_all
        self._mask_lists = rows
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

    def _observe(self) -> dict:
        vec, masks, cx, cy = self._agent_arrays()
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

    # ------------------------------------------------------------------ render
    def render(self):
        """An ``(H, W, 3)`` uint8 image of the map, fire, agents and fields of view
        (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array" or self._world is None:
            return None
        from fcplan.render import render_frame, snapshot

        return render_frame(self.scenario, snapshot(self._world), size=self.render_size)

    def close(self) -> None:
        """Nothing to release."""
