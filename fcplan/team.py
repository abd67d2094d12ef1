"""The composite team: motion, altitude and field of view, battery, tank, depot, and agent commands.

Agents are held as arrays (one row per agent, scenario order: perception, action, hybrid) so a tick
moves the whole team with a few numpy operations. Only agents that *arrive* somewhere (a goal, the
depot) are handled one by one, which happens a few times per second at most.

The rules below are those of the FireCommander manual and the reference game (FIRECOMMANDER.md
section 4), with the manual's per-frame quantities read per tick at 10 ticks per second and
rescaled to ``ticks_per_second`` (``s = 10 / ticks_per_second``). Units: px (1 px = 1 m) on the
map, m of altitude, battery units, simulated seconds.

* **Motion.** An agent flies straight at its own speed ``v s`` px per tick (``v``: the scenario's
  px per frame) to its current goal: ``p <- p + v s (g - p) / |g - p|``; when ``|g - p| <= v s`` it
  snaps onto the goal and takes the next one. After the last goal it hovers, unless its route is
  a patrol loop, which repeats.
* **Altitude.** Perception and hybrid agents climb or descend toward their commanded altitude at
  ``5 s`` m per tick, within their altitude bounds; action agents fly at
  :data:`~fcplan.scenario.model.ACTION_ALTITUDE` (30 m).
* **Field of view.** A rectangle centred on the agent, ``2 tan(pi/4) z = 2 z`` wide (x) and
  ``2 tan(pi/6) z`` (about ``1.1547 z``) high (y); cell ``(i, j)`` is inside when ``|i - x| <= z``
  and ``|j - y| <= 0.57735 z`` (inclusive, as the reference).
* **Sensing confidence.** ``c = 1 - 0.6 (z - lo) / (hi - lo)`` (1 when ``lo == hi``): 100% at the
  lowest altitude, 40% at the highest (manual, sensing). ``c`` is the probability per 10 Hz tick
  to sense a burning cell in view; at ``r`` ticks per second a tick senses it with
  :func:`per_tick_probability` ``1 - (1 - c)^(10 / r)``, so that the probability to have sensed a
  cell after ``T`` seconds in view, ``1 - (1 - c)^(10 T)``, does not depend on the rate.
* **Battery.** Flying drains 0.1 per px and hovering ``0.05 s`` per tick (the manual's "0.1 per
  unit length, 0.05 per iteration"). An active agent heads home (and later resumes its route) as
  soon as ``B <= 0.1 |home - p| + 0.2 v s + 0.1 s``: after one more step, which can also lengthen
  the way home by one step, it must still afford the flight home plus a hover tick, so the
  battery never goes negative.
* **Tank and dumps.** Arriving at a goal arms one dump. An armed action or hybrid agent dumps as
  soon as a dump can do something (see :mod:`fcplan.world`): one tank unit per dump, so tank ``T``
  gives ``T`` dumps (the 2020 code gave ``T + 1``). An empty tank sends the agent home.
* **Depot.** At home the agent recharges and refills at once; after a forced return it resumes
  its route (or flies back to the last goal it was holding), after a commanded return (or the
  3-second rule) it stays idle.
* **3-second rule.** An action agent hovering at its last goal for 3 s goes home and idles.

Per simulated second, distance flown, climb, battery drain and the 3-second clock do not depend on
the tick rate. What does, by at most one tick: an agent snaps onto a goal within one step of it
and starts the next leg on the next tick, so each goal costs on average half a tick (0.1 s at 5 Hz,
0.05 s at 10 Hz), and the battery reserve keeps one step's margin.

Teams of up to :data:`SMALL_TEAM` agents run bit-identical kernels of these rules on Python numbers
(:mod:`fcplan._fast.team`); the numpy methods here are the rules' specification.

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> from fcplan.team import Team, Command
>>> team = Team(load_scenario("practice"))
>>> team.apply({"A1": Command(route=((400.0, 400.0),))})
>>> arrived = team.move()  # rows that reached a goal this tick (none yet)
>>> team.pos[team.index("A1")].round(1).tolist()  # 20 px toward (400, 400)
[78.5, 532.4]
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

import numpy as np

from fcplan._fast.team import fov_rects_small, move_small, rules_small
from fcplan.errors import PlanError
from fcplan.scenario.model import (
    ACTION_ALTITUDE as ACTION_ALTITUDE,
)  # (re-exported: one definition)
from fcplan.scenario.model import Role, Scenario

__all__ = ["Mode", "Command", "Team", "fov_half_extent", "sensing_confidence"]
__all__ += ["per_tick_probability"]

FOV_TAN_X = 1.0  # tan(pi/4): half-width per metre of altitude (exact, not 0.999...)
FOV_TAN_Y = math.tan(math.pi / 6)  # half-height per metre of altitude
DRAIN_PER_PX = 0.1
DRAIN_PER_HOVER_TICK = 0.05  # at 10 ticks/s
CLIMB_PER_TICK = 5.0  # m per tick at 10 ticks/s
ACTION_IDLE_LIMIT_S = 3.0
REFERENCE_TPS = 10  # the rate at which the manual's per-frame quantities hold
#: teams up to this many agents move on Python floats (:mod:`fcplan._fast.team`)
SMALL_TEAM = 16


class Mode(IntEnum):
    """What an agent is doing."""

    IDLE = 0  #: at its depot slot with nothing to do
    ACTIVE = 1  #: following its route (or hovering at its last goal)
    RETURNING = 2  #: forced home (battery or tank); resumes its route after recharging
    HOMING = 3  #: sent home (command or 3-second rule); stays idle there


@dataclass(frozen=True, slots=True)
class Command:
    """An instruction to one agent, applied at the start of a tick.

    Parameters
    ----------
    route : sequence of (x, y), optional
        New goals, replacing the current ones (``None`` keeps the route). An empty route stops
        the agent where it is (it hovers).
    patrol : bool
        Repeat the route as a loop.
    altitude : float, optional
        Target altitude for perception and hybrid agents (clipped to the agent's bounds).
    home : bool
        Fly home and stay idle there.
    """

    route: Sequence[tuple[float, float]] | None = None
    patrol: bool = False
    altitude: float | None = None
    home: bool = False


def fov_half_extent(z: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """Half width (x) and half height (y) of the field of view at altitude ``z``.

    Examples
    --------
    >>> hx, hy = fov_half_extent(30.0)
    >>> float(2 * hx), round(float(2 * hy), 1)
    (60.0, 34.6)
    """
    z = np.asarray(z, dtype=np.float64)
    return FOV_TAN_X * z, FOV_TAN_Y * z


def sensing_confidence(z: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Probability to sense a burning cell in view: 1 at the lowest altitude, 0.4 at the highest.

    ``c = 1 - 0.6 (z - lo) / (hi - lo)``, or 1 when ``lo == hi``.

    Examples
    --------
    >>> import numpy as np
    >>> sensing_confidence(np.array([10.0, 55.0, 100.0]), 10.0, 100.0).round(2).tolist()
    [1.0, 0.7, 0.4]
    """
    z, lo, hi = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (z, lo, hi)))
    span = hi - lo
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(span > 0, 1.0 - 0.6 * (z - lo) / np.where(span > 0, span, 1.0), 1.0)
    return np.clip(c, 0.4, 1.0)


def per_tick_probability(p: Any, ticks_per_second: int) -> Any:
    """Probability per tick at ``ticks_per_second`` with the hazard of ``p`` per 10 Hz tick.

    ``1 - (1 - p)^(10 / ticks_per_second)``, and ``p`` itself (the same object) at 10 ticks per
    second. Works on floats and arrays.

    Examples
    --------
    >>> per_tick_probability(0.4, 10), round(per_tick_probability(0.4, 20), 4)
    (0.4, 0.2254)
    >>> round(1 - (1 - per_tick_probability(0.4, 40)) ** 4, 12)  # one 10 Hz tick's worth
    0.4
    """
    if ticks_per_second == REFERENCE_TPS:
        return p
    return 1.0 - (1.0 - p) ** (REFERENCE_TPS / ticks_per_second)


_IDLE, _ACTIVE, _RETURNING, _HOMING = (int(m) for m in Mode)
_ROLE_ACTION = int(Role.ACTION)
_NO_ROWS = np.zeros(0, dtype=np.int64)
_ACTIVE8, _RETURNING8 = np.int8(_ACTIVE), np.int8(_RETURNING)
_IDLE_LIMIT = np.float64(ACTION_IDLE_LIMIT_S - 1e-9)
_ZERO = np.float64(0.0)  # numpy scalars compare faster than Python numbers
_TINY = np.float64(5e-324)  # smallest positive double
_FOV_SCALE = np.array([-FOV_TAN_X, FOV_TAN_X, -FOV_TAN_Y, FOV_TAN_Y])


class Team:
    """State of every agent, as arrays.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
        Supplies the agents (role, start, altitude bounds, battery, speed, tank, confidence).

    Attributes
    ----------
    ids : tuple of str
        Agent ids (``"P1"``, ``"A1"``, ``"H1"`` ...), one per row.
    role : ndarray, (N,) int8
        :class:`fcplan.scenario.Role` values.
    pos : ndarray, (N, 2) float64
        Planar position (px).
    z : ndarray, (N,) float64
        Altitude (m).
    speed : ndarray, (N,) float64
        Px per tick at this scenario's tick rate.
    battery : ndarray, (N,) float64
        Remaining battery; never negative.
    tank : ndarray, (N,) int64
        Remaining dumps (0 for perception agents).
    mode : ndarray, (N,) int8
        :class:`Mode` values.
    """

    # rule constants read by the kernels of fcplan._fast.team (which cannot import this module)
    _modes = (_IDLE, _ACTIVE, _RETURNING, _HOMING)
    _drain_per_px = DRAIN_PER_PX
    _idle_limit = float(_IDLE_LIMIT)
    _fov_scale_list = _FOV_SCALE.tolist()

    def __init__(self, scenario: Scenario) -> None:
        agents = scenario.agents
        self.ids = tuple(a.id for a in agents)
        self._index = {a: i for i, a in enumerate(self.ids)}
        n = len(agents)
        self.n = n
        self.ticks_per_second = scenario.ticks_per_second
        self.tick_scale = 10.0 / scenario.ticks_per_second  # 10 Hz quantities -> this rate
        self.dt_s = 1.0 / scenario.ticks_per_second
        self.role = np.array([int(a.role) for a in agents], dtype=np.int8)
        self.can_sense = np.isin(self.role, (int(Role.PERCEPTION), int(Role.HYBRID)))
        self.can_act = np.isin(self.role, (int(Role.ACTION), int(Role.HYBRID)))
        self.home = np.array([a.start for a in agents], dtype=np.float64).reshape(n, 2)
        self.alt_lo = np.array([a.altitude[0] for a in agents], dtype=np.float64)
        self.alt_hi = np.array([a.altitude[1] for a in agents], dtype=np.float64)
        self.z_start = np.array([a.start_altitude for a in agents], dtype=np.float64)
        self.speed = np.array([a.speed for a in agents], dtype=np.float64) * self.tick_scale
        self.battery_capacity = np.array([a.battery for a in agents], dtype=np.float64)
        self.tank_capacity = np.array([a.tank for a in agents], dtype=np.int64)
        self.prune_confidence = np.array([a.prune_confidence for a in agents], dtype=np.float64)
        span = self.alt_hi - self.alt_lo
        self._inv_span = np.where(span > 0, 1.0 / np.where(span > 0, span, 1.0), 0.0)
        # per-tick constants (same expressions, same rounding, as the rules they come from)
        self._hover_drain = DRAIN_PER_HOVER_TICK * self.tick_scale
        self._hover_margin = 2.0 * DRAIN_PER_HOVER_TICK * self.tick_scale
        self._speed_margin = 2.0 * DRAIN_PER_PX * self.speed  # (speed is fixed per team)
        self._climb = CLIMB_PER_TICK * self.tick_scale
        self._is_action = self.role == _ROLE_ACTION
        # the small-team kernels (fcplan._fast.team) read these constants as Python numbers
        self._small = 0 < n <= SMALL_TEAM
        self._home_list = [tuple(h) for h in self.home.tolist()]
        self._speed_list = self.speed.tolist()
        self._speed_margin_list = self._speed_margin.tolist()
        self._can_sense_list = self.can_sense.tolist()
        self._is_action_list = self._is_action.tolist()
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Every agent at its depot slot, full battery and tank, idle."""
        n = self.n
        self.pos = self.home.copy()
        self.z = self.z_start.copy()
        self.z_target = self.z_start.copy()
        self.battery = self.battery_capacity.copy()
        self.tank = self.tank_capacity.copy()
        self.mode = np.full(n, Mode.IDLE, dtype=np.int8)
        self.goal = self.home.copy()
        self.has_goal = np.zeros(n, dtype=bool)
        self.armed = np.zeros(n, dtype=bool)
        self.hover_s = np.zeros(n, dtype=np.float64)
        self.distance = np.zeros(n, dtype=np.float64)
        self.dumps = np.zeros(n, dtype=np.int64)
        self.sorties = np.zeros(n, dtype=np.int64)
        self.routes: list[np.ndarray] = [np.zeros((0, 2)) for _ in range(n)]
        self.goal_index = np.zeros(n, dtype=np.int64)
        self.patrol = np.zeros(n, dtype=bool)

    def index(self, agent: str | int) -> int:
        """Row of an agent given its id (``"P1"``) or row number."""
        if isinstance(agent, (int, np.integer)):
            if not 0 <= int(agent) < self.n:
                raise PlanError(f"agent index {agent} is out of range 0..{self.n - 1}")
            return int(agent)
        try:
            return self._index[agent]
        except KeyError:
            raise PlanError(
                f"unknown agent {agent!r}; this team has {', '.join(self.ids)}"
            ) from None

    @property
    def at_home(self) -> np.ndarray:
        """(N,) bool: standing on its depot slot."""
        return np.all(self.pos == self.home, axis=1)

    def fov_rects(self) -> np.ndarray:
        """(N, 4) float64 ``[x0, x1, y0, y1]`` inclusive field-of-view bounds of every agent."""
        # [x, x, y, y] + z [-tan_x, tan_x, -tan_y, tan_y]: z (-t) is exactly -(t z), and
        # x + (-h) is exactly x - h, so this equals [x - hx, x + hx, y - hy, y + hy]
        return self.pos.repeat(2, axis=1) + self.z[:, None] * _FOV_SCALE

    def fov_rects_list(self) -> list[list[float]]:
        """:meth:`fov_rects` as nested Python lists (the same values)."""
        if not self._small:
            return self.fov_rects().tolist()
        return fov_rects_small(self)

    def sensing_confidence(self) -> np.ndarray:
        """(N,) probability per 10 Hz tick to sense each burning cell in view (0 for agents that
        cannot sense)."""
        c = 1.0 - 0.6 * (self.z - self.alt_lo) * self._inv_span
        return np.minimum(np.maximum(c, 0.4), 1.0) * self.can_sense

    def sensing_probability(self) -> np.ndarray:
        """(N,) probability per tick at this rate to sense each burning cell in view:
        :func:`per_tick_probability` of :meth:`sensing_confidence`."""
        return per_tick_probability(self.sensing_confidence(), self.ticks_per_second)

    def return_cost(self) -> np.ndarray:
        """(N,) battery needed to fly straight home from where each agent is."""
        d = self.home - self.pos
        return DRAIN_PER_PX * np.hypot(d[:, 0], d[:, 1])

    # ------------------------------------------------------------------ commands
    def apply(self, commands: Mapping[str | int, Command] | None) -> None:
        """Apply commands (by agent id or row). A forced return keeps going; the new route is
        what the agent resumes after recharging."""
        if not commands:
            return
        for key, cmd in commands.items():
            i = self.index(key)
            if cmd.altitude is not None and self.can_sense[i]:
                # np.clip on one value: min(max(a, lo), hi), NaN propagating
                self.z_target[i] = float(min(max(cmd.altitude, self.alt_lo[i]), self.alt_hi[i]))
            mode = int(self.mode[i])
            if cmd.home:
                if mode != _IDLE or not self._at_home(i):
                    self.mode[i] = _HOMING
                self.routes[i] = np.zeros((0, 2))
                self.goal_index[i] = 0
                self.patrol[i] = False
                self.has_goal[i] = False
                continue
            if cmd.route is None:
                continue
            route = np.asarray(cmd.route, dtype=np.float64).reshape(-1, 2)
            if len(route) <= 4:  # (a few goals: the check on Python floats is cheaper)
                finite = all(map(math.isfinite, route.ravel().tolist()))
            else:
                finite = bool(np.isfinite(route).all())
            if not finite:
                raise PlanError(f"agent {self.ids[i]}: route has a non-finite coordinate")
            self.routes[i] = route
            self.goal_index[i] = 0
            self.patrol[i] = bool(cmd.patrol) and len(route) > 1
            self.hover_s[i] = 0.0
            if mode == _RETURNING:
                continue
            if len(route) == 0:
                self.has_goal[i] = False
                if mode == _HOMING:
                    continue
                self.mode[i] = _ACTIVE if not self._at_home(i) else _IDLE
                continue
            self.mode[i] = _ACTIVE
            self.has_goal[i] = True
            self.goal[i] = route[0]

    def _at_home(self, i: int) -> bool:
        """Row ``i`` of :attr:`at_home`."""
        p, h = self.pos[i], self.home[i]
        return bool(p[0] == h[0] and p[1] == h[1])

    # ------------------------------------------------------------------ dynamics
    def move(self) -> np.ndarray:
        """Move every agent one tick; return the rows that arrived at a route goal this tick.

        Teams of up to :data:`SMALL_TEAM` agents take :func:`fcplan._fast.team.move_small` (the
        same IEEE operations on Python floats), larger ones :meth:`_move_vector`, the rule; both
        give bit-identical states.
        """
        if self._small:
            return move_small(self)
        return self._move_vector()

    def _move_vector(self) -> np.ndarray:
        """:meth:`move` with numpy on the whole team: the motion, hover, altitude and arrival
        rules of the module docstring, in that order, then the battery and 3-second rules."""
        # (np.count_nonzero is the cheapest "any" on these tiny arrays)
        mode = self.mode
        active = mode == _ACTIVE8
        going_home = mode >= _RETURNING8  # RETURNING or HOMING
        flying = going_home | (active & self.has_goal)
        # (a zero coordinate also takes the full path, which turns -0.0 into +0.0 exactly as
        # moving by a zero step does)
        if np.count_nonzero(flying) or np.count_nonzero(self.pos == _ZERO):
            arrive = self._fly(flying, going_home, active)
        else:  # nobody flies: positions stay, hovering agents drain and their hover clocks run
            arrive = None
            if np.count_nonzero(active):
                self.battery -= self._hover_drain * active
                self.hover_s = np.where(active, self.hover_s + self.dt_s, 0.0)
            else:
                self.hover_s = np.zeros(self.n)
        # altitude
        z, zt = self.z, self.z_target
        if np.count_nonzero(zt != z):
            dz = np.minimum(np.maximum(zt - z, -self._climb), self._climb)
            self.z += dz * self.can_sense

        if arrive is not None and np.count_nonzero(arrive):
            for i in (arrive & going_home).nonzero()[0].tolist():
                self._dock(i)
            arrived_goal = (arrive & active).nonzero()[0]
            for i in arrived_goal.tolist():
                self._next_goal(i)
            self._rules()  # docking changed modes
        else:
            arrived_goal = _NO_ROWS
            self._rules(active)
        return arrived_goal

    def _fly(self, flying: np.ndarray, going_home: np.ndarray, active: np.ndarray) -> np.ndarray:
        """One step toward each flying agent's target; return the (N,) bool rows that arrived."""
        if np.count_nonzero(going_home):
            target = np.where(going_home[:, None], self.home, self.goal)
        else:
            target = self.goal  # only read below
        pos = self.pos
        d = target - pos
        dist = np.hypot(d[:, 0], d[:, 1])
        speed = self.speed
        arrive = flying & (dist <= speed)
        # dist == 0 implies d == 0, and any positive double is >= the smallest one, so this is
        # d / dist, or the zero direction where dist == 0
        unit = d / np.maximum(dist, _TINY)[:, None]
        step = np.where(arrive, dist, speed * flying)
        moved = pos + unit * step[:, None]
        self.pos = np.where(arrive[:, None], target, moved) if np.count_nonzero(arrive) else moved
        self.distance += step
        hovering = np.greater(active, flying)  # active & ~flying, in one call
        if np.count_nonzero(hovering):
            self.battery -= DRAIN_PER_PX * step + self._hover_drain * hovering
            self.hover_s = np.where(hovering, self.hover_s + self.dt_s, 0.0)
        else:  # x + 0.0 == x: the hover term adds nothing
            self.battery -= DRAIN_PER_PX * step
            self.hover_s = np.zeros(self.n)
        return arrive

    def _next_goal(self, i: int) -> None:
        if self.can_act[i] and self.tank[i] > 0:
            self.armed[i] = True
        route = self.routes[i]
        k = self.goal_index[i] + 1
        if k >= len(route):
            if self.patrol[i]:
                k = 0
            else:
                self.goal_index[i] = len(route)
                self.has_goal[i] = False
                return
        self.goal_index[i] = k
        self.goal[i] = route[k]

    def _dock(self, i: int) -> None:
        self.battery[i] = self.battery_capacity[i]
        self.tank[i] = self.tank_capacity[i]
        self.sorties[i] += 1
        route = self.routes[i]
        # after a forced return the agent resumes: the goal it was heading to, or its last goal
        # (a post it was holding) if it had finished the route
        k = min(int(self.goal_index[i]), len(route) - 1)
        if self.mode[i] == _RETURNING and k >= 0:
            self.goal_index[i] = k
            self.mode[i] = Mode.ACTIVE
            self.has_goal[i] = True
            self.goal[i] = route[k]
        else:
            self.mode[i] = Mode.IDLE
            self.has_goal[i] = False
            self.routes[i] = np.zeros((0, 2))
            self.goal_index[i] = 0
            self.patrol[i] = False
        self.armed[i] = False

    def _rules(self, active: np.ndarray | None = None) -> None:
        """Battery reserve, and the 3-second rule for action agents (``active``: the rows in
        ACTIVE mode, if the caller has them). Small teams take
        :func:`fcplan._fast.team.rules_small`."""
        if self._small:
            mode = self.mode.tolist()
            rows = [i for i, m in enumerate(mode) if m == _ACTIVE]
            if rows:  # (without ACTIVE agents neither rule applies)
                rules_small(
                    self,
                    rows,
                    mode,
                    self.pos.ravel().tolist(),
                    self.battery.tolist(),
                    self.hover_s.tolist(),
                )
            return
        if active is None:
            active = self.mode == _ACTIVE8
        if not np.count_nonzero(active):
            return
        # Reserve: after one more step (which can also lengthen the way home by one step) the
        # agent must still afford the flight home, plus one hover tick of margin.
        reserve = self.return_cost() + self._speed_margin + self._hover_margin
        low = active & (self.battery <= reserve)
        if np.count_nonzero(low):
            self.mode[low] = _RETURNING
            active = self.mode == _ACTIVE8
        long_hover = self.hover_s >= _IDLE_LIMIT
        if not np.count_nonzero(long_hover):  # (the usual case)
            return
        idle_action = active & self._is_action & long_hover
        if np.count_nonzero(idle_action):
            self.mode[idle_action] = _HOMING
            self.has_goal[idle_action] = False

    def record_dump(self, i: int) -> None:
        """Spend one tank unit for a dump by agent ``i``; an empty tank sends it home."""
        self.tank[i] -= 1
        self.dumps[i] += 1
        self.armed[i] = False
        if self.tank[i] <= 0 and self.mode[i] == Mode.ACTIVE:
            self.mode[i] = Mode.RETURNING

    def range_px(self) -> np.ndarray:
        """(N,) px each agent can still fly away from home and back (battery / drain, minus the
        current way home)."""
        d = self.home - self.pos
        return np.maximum(self.battery / DRAIN_PER_PX - np.hypot(d[:, 0], d[:, 1]), 0.0)
