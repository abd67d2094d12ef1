"""Motion-level PettingZoo environment: one step is one simulator tick.

``parallel_env(scenario)`` returns a :class:`MotionEnv`, a PettingZoo ``ParallelEnv`` on
:class:`fcplan.World`: every UAV of the scenario is an agent and chooses a discrete move every
tick. ``parallel_env(preset="base" | "cmplx1" | "cmplx2")`` (or the preset name in place of the
scenario) returns one of the reference MARL package's three environments instead
(:mod:`fcplan.env.presets`).

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
    Shared by all agents: ``reward_fn`` of the tick (a :class:`fcplan.env.reward.RewardFn`; by
    default :class:`~fcplan.env.reward.PenaltyReward`, the manual's negative reward of this tick,
    ``-(0.1 |active| + sum_f PC_f n_f) / tps``), so the episode's return equals minus the manual's
    total negative reward. Optional shaping (off by default): ``+ sense_bonus`` per newly sensed
    cell, ``+ prune_bonus`` per pruned cell, ``- dump_cost`` per dump.

Termination and truncation
    No termination; every agent is truncated when the scenario's duration has been simulated
    (``scenario.n_ticks`` steps). The last step's ``infos[agent]["metrics"]`` holds the final
    metrics of both definitions (``{"manual": {...}, "reference2020": {...}}``).

Arguments
    ``cell_px`` (20), ``view`` (15, odd), ``stale_s`` (30.0), ``idle_rule`` (False: the
    3-second rule that sends an action agent hovering 3 s at its last goal home is switched
    off, since at this level hovering is the policy's choice), ``sense_bonus``, ``prune_bonus``,
    ``dump_cost`` (0.0), ``reward_fn`` (None: :class:`~fcplan.env.reward.PenaltyReward`),
    ``render_mode`` (``None`` or ``"rgb_array"``), ``render_size`` (512).

Seeding
    ``reset(seed=s)`` resets the world with :meth:`fcplan.World.reset` ``(scenario, seed=s)``, so
    the fire draws the same random numbers as ``fcplan run SCENARIO --seed s``; ``reset()``
    without a seed continues with seeds drawn from the last seed. Same seed and actions give
    identical episodes in any process. ``env.world`` is the live :class:`fcplan.World`, ticked by
    ``env.mission`` (a :class:`fcplan.mission.Mission` that keeps no belief unless asked to, as
    :mod:`fcplan.env.motion_expert` does). The observations are built by
    :mod:`fcplan.env.motion_obs`.

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

from typing import Any

import numpy as np
from pettingzoo import ParallelEnv

from fcplan.env.motion_grid import CoarseMaps
from fcplan.env.motion_obs import N_AGENT_FEATURES, N_FOV, N_STATE, NEVER, MotionObs
from fcplan.env.presets import PRESETS as _PRESET_REGISTRY
from fcplan.env.presets import make_preset
from fcplan.env.reward import PenaltyReward, RewardFn
from fcplan.errors import EnvError
from fcplan.mission import Mission, ScenarioLike, as_scenario
from fcplan.scenario import Scenario
from fcplan.team import CLIMB_PER_TICK
from fcplan.world import StepInfo, World, check_seed

__all__ = ["MotionEnv", "parallel_env", "PRESETS", "ACTION_NAMES", "role_letters"]

#: Preset names accepted by :func:`parallel_env`.
#: names of the reference presets (:data:`fcplan.env.presets.PRESETS`)
PRESETS = tuple(_PRESET_REGISTRY)

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
_K_STAY, _K_MOVE, _K_ALTITUDE, _K_DUMP = range(4)
_STAY_SPEC = (_K_STAY, 0.0, 0.0, 0.0)
_ACTIVE = 1  # fcplan.team.Mode.ACTIVE
#: a move sets a goal this many steps away, so the agent never arrives (see MotionEnv.step)
_GOAL_REACH = 1.5


def parallel_env(
    scenario: ScenarioLike | None = None, *, preset: str | None = None, **kwargs: Any
) -> Any:
    """Make a motion-level ``ParallelEnv`` on a scenario, or one of the reference presets.

    Parameters
    ----------
    scenario : Scenario, str, int or None
        A scenario or a name/path for :func:`fcplan.load_scenario`; a preset name
        (``"base"``, ``"cmplx1"``, ``"cmplx2"``) selects that preset.
    preset : {"base", "cmplx1", "cmplx2"}, optional
        The reference MARL environment to reproduce (:mod:`fcplan.env.presets`).
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
        return make_preset(preset, **kwargs)
    if scenario is None:
        raise EnvError("scenario: give a scenario (name, path or Scenario) or preset=")
    return MotionEnv(scenario, **kwargs)


def role_letters(scenario: Scenario) -> list[str]:
    """Role letter of each agent (``"P"`` perception, ``"A"`` action, ``"H"`` hybrid), the key
    of :data:`ACTION_NAMES`."""
    return [
        "H" if (a.role.can_sense and a.role.can_act) else ("P" if a.role.can_sense else "A")
        for a in scenario.agents
    ]


class MotionEnv(ParallelEnv):
    """Motion-level environment on a fcplan scenario (module docstring: spaces, reward, rules)."""

    metadata = {
        "name": "fcplan_motion_v0",
        "render_modes": ["rgb_array"],
        "is_parallelizable": True,
        "render_fps": 10,
    }

    def __init__(
        self,
        scenario: ScenarioLike,
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
        reward_fn: RewardFn | None = None,
    ) -> None:
        from gymnasium import spaces

        sc = as_scenario(scenario)
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
        letters = role_letters(sc)
        self._letters = letters
        self._n_actions = np.array([len(ACTION_NAMES[r]) for r in letters], dtype=np.int64)
        # per agent and action: dx, dy (unit), dz sign, dump, is a move; and the column of the
        # condition table (see _masks) that makes it legal
        table = np.zeros((n, _MAX_ACTIONS, 5), dtype=np.float64)
        cond_of = np.full((n, _MAX_ACTIONS), NEVER, dtype=np.int64)
        for i, r in enumerate(letters):
            for a, name in enumerate(ACTION_NAMES[r]):
                if name in _DIRS:
                    table[i, a, :2] = _DIRS[name]
                table[i, a, 2] = {"climb": 1.0, "descend": -1.0}.get(name, 0.0)
                table[i, a, 3] = name == "dump"
                table[i, a, 4] = name in _DIRS and name != "stay"
                cond_of[i, a] = _COND[name]
        self._table = table
        self._shaping = bool(self.sense_bonus or self.prune_bonus or self.dump_cost)
        self._action_spaces = {
            a: spaces.Discrete(int(k))
            for a, k in zip(self.possible_agents, self._n_actions, strict=True)
        }
        nc = -(-sc.world_size // self.cell_px)
        self._obs_spaces = {
            a: spaces.Dict(
                {
                    "fov": spaces.Box(0.0, 1.0, (N_FOV, self.view, self.view), np.float32),
                    "agent": spaces.Box(0.0, 1.0, (N_AGENT_FEATURES,), np.float32),
                    "action_mask": spaces.Box(0, 1, (int(k),), np.int8),
                }
            )
            for a, k in zip(self.possible_agents, self._n_actions, strict=True)
        }
        self.state_space = spaces.Box(0.0, np.inf, (N_STATE, nc, nc), np.float32)
        maps = CoarseMaps(
            sc, self.cell_px, self.view, seen_scale=1.0 / (self.stale_s * sc.ticks_per_second)
        )
        #: builds the observations and the state (fcplan.env.motion_obs)
        self.observations = MotionObs(
            sc, letters, self._n_actions, cond_of, self.cell_px, self.view, maps
        )
        self.reward_fn: RewardFn = reward_fn or PenaltyReward()
        #: the episode (created by the first reset; keeps no belief unless asked to)
        self.mission: Mission | None = None
        self._world: World | None = None
        self._last_info: StepInfo | None = None
        self._reseed: np.random.Generator | None = None

    # ------------------------------------------------------------------ spaces
    def observation_space(self, agent: str) -> Any:
        """The ``Dict`` observation space of ``agent`` (the same object every call)."""
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> Any:
        """The ``Discrete`` action space of ``agent`` (the same object every call)."""
        return self._action_spaces[agent]

    @property
    def world(self) -> World | None:
        """The underlying :class:`fcplan.World` (after :meth:`reset`)."""
        return self._world

    @property
    def last_info(self) -> StepInfo | None:
        """The :class:`fcplan.world.StepInfo` of the last tick (None right after :meth:`reset`):
        what a scheduler-driven expert feeds its belief with
        (:mod:`fcplan.env.motion_expert`)."""
        return self._last_info

    # ------------------------------------------------------------------ episode
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        """Start an episode; return ``(observations, infos)``."""
        check_seed(seed, generator=False)  # (a one-line SeedError, not numpy's)
        if seed is not None:
            self._reseed = np.random.default_rng(seed)
        elif self._reseed is None:
            self._reseed = np.random.default_rng()
            seed = int(self._reseed.integers(2**63))
        else:
            seed = int(self._reseed.integers(2**63))
        if self.mission is None:
            self.mission = Mission(self.scenario, seed, event_replans=False, belief=False)
        else:
            self.mission.reset(seed)
        self._world = world = self.mission.world
        self._team = team = world.team
        self._climb = CLIMB_PER_TICK * team.tick_scale
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
        self.observations.reset(world)
        self.reward_fn.reset(world)
        self._n_ticks = self.scenario.n_ticks
        self.agents = list(self.possible_agents)
        self._last_info = None
        return self.observations.observe(), {a: {} for a in self.agents}

    def step(self, actions: dict[str, Any]) -> tuple[dict[str, Any], ...]:
        """Advance one tick with ``{agent: action}``; missing agents stay."""
        if not self.agents:
            raise EnvError("step: the episode is over; call reset()")
        team, world, view = self._team, self._world, self.observations
        assert world is not None and self.mission is not None  # (agents: reset was called)
        goal, has_goal, mode, armed = team.goal, team.has_goal, team.mode, team.armed
        pos = None
        # (each mask tuple holds exactly the agent's actions: its length bounds the action)
        for i, (a, row, spec, free) in enumerate(
            zip(self.possible_agents, view.mask_lists, self._spec, view.free_list, strict=True)
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
        info = self.mission.step()
        team.armed.fill(False)
        view.update(info)
        self._last_info = info
        r = self.reward_fn(world, info.tick - 1)
        if self._shaping:
            r += self.sense_bonus * info.newly_sensed.size + self.prune_bonus * info.pruned.size
            r -= self.dump_cost * len(info.dumped)
        obs = view.observe()
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

    def state(self) -> np.ndarray:
        """Global state ``(8, nc, nc)`` float32 (module docstring)."""
        return self.observations.state()

    # ------------------------------------------------------------------ render
    def render(self) -> np.ndarray | None:
        """An ``(H, W, 3)`` uint8 image of the map, fire, agents and fields of view
        (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array" or self._world is None:
            return None
        from fcplan.render import render_frame, snapshot

        return render_frame(self.scenario, snapshot(self._world), size=self.render_size)

    def close(self) -> None:
        """Nothing to release."""
