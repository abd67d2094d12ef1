"""The teams of ``B`` worlds: :class:`fcplan.team.Team`'s numpy rule with a batch axis.

Every per-agent array of :class:`fcplan.team.Team` gets a leading world axis: ``pos`` and
``goal`` are ``(B, N, 2)``, ``z``, ``battery``, ``mode``, ... ``(B, N)``; routes are padded,
``routes`` ``(B, N, R, 2)`` with ``route_len`` ``(B, N)`` (``R`` grows with the longest route
commanded). :meth:`BatchTeam.move` is ``Team._move_vector`` over the whole batch: the same
element-wise IEEE operations (numpy's ``hypot``, the divisions and the clips), so every world's
team ends each tick bit for bit as a :class:`~fcplan.team.Team` would (whose small-team kernels
are tested bit-identical to that rule). Arrivals (docking, next goal) and the battery and
3-second rules are masked array updates instead of per-agent calls. Worlds outside the ``run``
mask of a tick do not change at all (a held world).

Commands: the motion level writes ``goal``, ``has_goal``, ``mode``, ``armed`` and ``z_target``
directly (as :class:`fcplan.env.motion.MotionEnv` does on one team); route commands go through
:meth:`BatchTeam.apply`, :meth:`fcplan.team.Team.apply` for one world, or, for one-point routes
to many (world, agent) pairs at once (the task level), :meth:`BatchTeam.go_to`, the same writes
as masked array updates.

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> from fcplan.team import Command
>>> team = BatchTeam(load_scenario("practice"), 2)
>>> team.reset_worlds(np.arange(2))
>>> team.apply(1, {"A1": Command(route=((400.0, 400.0),))})
>>> arrived = team.move(np.ones(2, dtype=bool))
>>> team.pos[:, team.ids.index("A1")].round(1).tolist()  # world 0 idles, world 1 flies
[[60.0, 540.0], [78.5, 532.4]]
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from fcplan.errors import PlanError
from fcplan.scenario import Scenario
from fcplan.scenario.model import Role
from fcplan.team import (
    ACTION_IDLE_LIMIT_S,
    CLIMB_PER_TICK,
    DRAIN_PER_HOVER_TICK,
    DRAIN_PER_PX,
    Command,
    Mode,
    Team,
)

__all__ = ["BatchTeam"]

_IDLE, _ACTIVE, _RETURNING, _HOMING = (int(m) for m in Mode)
_TINY = np.float64(5e-324)
_IDLE_LIMIT = np.float64(ACTION_IDLE_LIMIT_S - 1e-9)
_FOV = np.array([-1.0, 1.0, -math.tan(math.pi / 6), math.tan(math.pi / 6)])


class BatchTeam:
    """Agents of ``num`` worlds of ``scenario`` (module docstring).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    num : int
        Worlds ``B``.
    """

    def __init__(self, scenario: Scenario, num: int) -> None:
        one = Team(scenario)  # the per-agent constants, computed once by the rule's own code
        self.num, self.n, self.ids = int(num), one.n, one.ids
        self.one = one
        self.home, self.speed = one.home, one.speed
        self.alt_lo, self.alt_hi = one.alt_lo, one.alt_hi
        self.can_sense, self.can_act = one.can_sense, one.can_act
        self.is_action = one.role == int(Role.ACTION)
        self.battery_capacity, self.tank_capacity = one.battery_capacity, one.tank_capacity
        self.prune_confidence = one.prune_confidence
        span = one.alt_hi - one.alt_lo
        self.inv_span = np.where(span > 0, 1.0 / np.where(span > 0, span, 1.0), 0.0)
        self.dt_s = one.dt_s
        self.hover_drain = DRAIN_PER_HOVER_TICK * one.tick_scale
        self.hover_margin = 2.0 * DRAIN_PER_HOVER_TICK * one.tick_scale
        self.speed_margin = 2.0 * DRAIN_PER_PX * one.speed
        self.climb = CLIMB_PER_TICK * one.tick_scale
        b, n = self.num, self.n
        self.pos = np.zeros((b, n, 2))
        self.z, self.z_target = np.zeros((b, n)), np.zeros((b, n))
        self.battery, self.hover_s, self.distance = (
            np.zeros((b, n)),
            np.zeros((b, n)),
            np.zeros((b, n)),
        )
        self.tank = np.zeros((b, n), dtype=np.int64)
        self.mode = np.zeros((b, n), dtype=np.int8)
        self.goal = np.zeros((b, n, 2))
        self.has_goal = np.zeros((b, n), dtype=bool)
        self.armed = np.zeros((b, n), dtype=bool)
        self.patrol = np.zeros((b, n), dtype=bool)
        self.dumps = np.zeros((b, n), dtype=np.int64)
        self.sorties = np.zeros((b, n), dtype=np.int64)
        self.goal_index = np.zeros((b, n), dtype=np.int64)
        self.route_len = np.zeros((b, n), dtype=np.int64)
        self.routes = np.zeros((b, n, 1, 2))

    def reset_worlds(self, worlds: np.ndarray) -> None:
        """Every agent of ``worlds`` at its depot slot, full battery and tank, idle."""
        self.pos[worlds] = self.home
        self.z[worlds] = self.one.z_start
        self.z_target[worlds] = self.one.z_start
        self.battery[worlds] = self.battery_capacity
        self.tank[worlds] = self.tank_capacity
        self.goal[worlds] = self.home
        for a in (self.mode, self.has_goal, self.armed, self.patrol, self.hover_s):
            a[worlds] = 0
        for a in (self.distance, self.dumps, self.sorties, self.goal_index, self.route_len):
            a[worlds] = 0

    # ------------------------------------------------------------------ queries
    def fov_rects(self) -> np.ndarray:
        """(B, N, 4) ``[x0, x1, y0, y1]`` of every field of view (``Team.fov_rects``)."""
        return self.pos.repeat(2, axis=2) + self.z[:, :, None] * _FOV

    def sensing_confidence(self) -> np.ndarray:
        """(B, N) probability per 10 Hz tick to sense a burning cell in view (0: no camera)."""
        c = 1.0 - 0.6 * (self.z - self.alt_lo) * self.inv_span
        return np.minimum(np.maximum(c, 0.4), 1.0) * self.can_sense

    # ------------------------------------------------------------------ commands
    def apply(self, b: int, commands: Mapping[Any, Command] | None) -> None:
        """:meth:`fcplan.team.Team.apply` of ``commands`` to world ``b``'s team."""
        if not commands:
            return
        for key, cmd in commands.items():
            i = self.one.index(key)
            if cmd.altitude is not None and self.can_sense[i]:
                self.z_target[b, i] = float(min(max(cmd.altitude, self.alt_lo[i]), self.alt_hi[i]))
            mode = int(self.mode[b, i])
            at_home = bool((self.pos[b, i] == self.home[i]).all())
            if cmd.home:
                if mode != _IDLE or not at_home:
                    self.mode[b, i] = _HOMING
                self.route_len[b, i] = self.goal_index[b, i] = 0
                self.patrol[b, i] = self.has_goal[b, i] = False
                continue
            if cmd.route is None:
                continue
            route = np.asarray(cmd.route, dtype=np.float64).reshape(-1, 2)
            if not np.isfinite(route).all():
                raise PlanError(f"agent {self.ids[i]}: route has a non-finite coordinate")
            self._set_route(b, i, route)
            self.patrol[b, i] = bool(cmd.patrol) and len(route) > 1
            self.hover_s[b, i] = 0.0
            if mode == _RETURNING:
                continue
            if len(route) == 0:
                self.has_goal[b, i] = False
                if mode != _HOMING:
                    self.mode[b, i] = _ACTIVE if not at_home else _IDLE
                continue
            self.mode[b, i] = _ACTIVE
            self.has_goal[b, i] = True
            self.goal[b, i] = route[0]

    def range_px(self) -> np.ndarray:
        """(B, N) :meth:`fcplan.team.Team.range_px` of every world (the same element-wise
        operations)."""
        d = self.home - self.pos
        return np.maximum(self.battery / DRAIN_PER_PX - np.hypot(d[..., 0], d[..., 1]), 0.0)

    def go_to(
        self, worlds: np.ndarray, agents: np.ndarray, goals: np.ndarray, altitudes: np.ndarray
    ) -> None:
        """:meth:`apply` of ``Command(route=(goals[n],), altitude=altitudes[n])`` to agent row
        ``agents[n]`` of world ``worlds[n]``, for many distinct (world, agent) pairs at once
        (NaN altitude: None). The same writes as :meth:`apply`, as masked array updates."""
        if not len(worlds):
            return
        goals = np.asarray(goals, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(goals).all():
            n = int(np.flatnonzero(~np.isfinite(goals).all(axis=1))[0])
            raise PlanError(f"agent {self.ids[agents[n]]}: route has a non-finite coordinate")
        alt = np.asarray(altitudes, dtype=np.float64)
        up = ~np.isnan(alt) & self.can_sense[agents]
        i = agents[up]
        self.z_target[worlds[up], i] = np.minimum(
            np.maximum(alt[up], self.alt_lo[i]), self.alt_hi[i]
        )
        self.routes[worlds, agents, 0] = goals  # (routes hold at least one point)
        self.route_len[worlds, agents] = 1
        self.goal_index[worlds, agents] = 0
        self.patrol[worlds, agents] = False
        self.hover_s[worlds, agents] = 0.0
        go = self.mode[worlds, agents] != _RETURNING
        w, a = worlds[go], agents[go]
        self.mode[w, a] = _ACTIVE
        self.has_goal[w, a] = True
        self.goal[w, a] = goals[go]

    def _set_route(self, b: int, i: int, route: np.ndarray) -> None:
        if len(route) > self.routes.shape[2]:
            grown = np.zeros((self.num, self.n, len(route), 2))
            grown[:, :, : self.routes.shape[2]] = self.routes
            self.routes = grown
        self.routes[b, i, : len(route)] = route
        self.route_len[b, i] = len(route)
        self.goal_index[b, i] = 0

    # ------------------------------------------------------------------ dynamics
    def move(self, run: np.ndarray) -> np.ndarray:
        """Move the agents of the worlds ``run`` one tick; return the (B, N) bool agents that
        arrived at a route goal (``Team._move_vector``, module docstring)."""
        held = not run.all()
        mode = self.mode
        active = mode == _ACTIVE
        going_home = mode >= _RETURNING
        if held:
            active &= run[:, None]
            going_home &= run[:, None]
        flying = going_home | (active & self.has_goal)
        target = np.where(going_home[:, :, None], self.home, self.goal)
        pos = self.pos
        d = target - pos
        dist = np.hypot(d[:, :, 0], d[:, :, 1])
        arrive = flying & (dist <= self.speed)
        unit = d / np.maximum(dist, _TINY)[:, :, None]
        step = np.where(arrive, dist, self.speed * flying)
        moved = pos + unit * step[:, :, None]
        new_pos = np.where(arrive[:, :, None], target, moved)
        hovering = np.greater(active, flying)
        battery = self.battery - (DRAIN_PER_PX * step + self.hover_drain * hovering)
        hover_s = np.where(hovering, self.hover_s + self.dt_s, 0.0)
        dz = np.minimum(np.maximum(self.z_target - self.z, -self.climb), self.climb)
        z = self.z + dz * self.can_sense
        if held:
            keep = ~run
            new_pos[keep] = pos[keep]
            battery[keep] = self.battery[keep]
            hover_s[keep] = self.hover_s[keep]
            z[keep] = self.z[keep]
        self.pos, self.battery, self.hover_s, self.z = new_pos, battery, hover_s, z
        self.distance += step
        if np.count_nonzero(arrive):
            self._dock(arrive & going_home)
            arrived_goal = arrive & active
            self._next_goal(arrived_goal)
        else:
            arrived_goal = arrive
        self._rules(run if held else None)
        return arrived_goal

    def _dock(self, m: np.ndarray) -> None:
        """``Team._dock`` of the agents ``m``: recharge, refill, resume or idle."""
        if not np.count_nonzero(m):
            return
        self.battery[m] = np.broadcast_to(self.battery_capacity, m.shape)[m]
        self.tank[m] = np.broadcast_to(self.tank_capacity, m.shape)[m]
        self.sorties[m] += 1
        k = np.minimum(self.goal_index, self.route_len - 1)
        resume = m & (self.mode == _RETURNING) & (k >= 0)
        stop = m & ~resume
        if np.count_nonzero(resume):
            self.goal_index[resume] = k[resume]
            self.mode[resume] = _ACTIVE
            self.has_goal[resume] = True
            wb, i = np.nonzero(resume)
            self.goal[wb, i] = self.routes[wb, i, k[resume]]
        if np.count_nonzero(stop):
            self.mode[stop] = _IDLE
            self.has_goal[stop] = False
            self.route_len[stop] = 0
            self.goal_index[stop] = 0
            self.patrol[stop] = False
        self.armed[m] = False

    def _next_goal(self, m: np.ndarray) -> None:
        """``Team._next_goal`` of the agents ``m`` (they reached a route goal)."""
        if not np.count_nonzero(m):
            return
        self.armed |= m & self.can_act & (self.tank > 0)
        k = self.goal_index + 1
        over = k >= self.route_len
        loop = m & over & self.patrol
        end = m & over & ~self.patrol
        nxt = m & ~end
        k = np.where(loop, 0, k)
        if np.count_nonzero(end):
            self.goal_index[end] = self.route_len[end]
            self.has_goal[end] = False
        if np.count_nonzero(nxt):
            self.goal_index[nxt] = k[nxt]
            wb, i = np.nonzero(nxt)
            self.goal[wb, i] = self.routes[wb, i, k[nxt]]

    def _rules(self, run: np.ndarray | None) -> None:
        """Battery reserve and the 3-second rule (``Team._rules``) in the worlds ``run``."""
        active = self.mode == _ACTIVE
        if run is not None:
            active &= run[:, None]
        if not np.count_nonzero(active):
            return
        d = self.home - self.pos
        reserve = DRAIN_PER_PX * np.hypot(d[:, :, 0], d[:, :, 1]) + self.speed_margin
        reserve += self.hover_margin
        low = active & (self.battery <= reserve)
        if np.count_nonzero(low):
            self.mode[low] = _RETURNING
            active &= ~low
        idle_action = active & self.is_action & (self.hover_s >= _IDLE_LIMIT)
        if np.count_nonzero(idle_action):
            self.mode[idle_action] = _HOMING
            self.has_goal[idle_action] = False

    def record_dumps(self, m: np.ndarray) -> None:
        """``Team.record_dump`` of the agents ``m`` ((B, N) bool)."""
        self.tank -= m
        self.dumps += m
        self.armed &= ~m
        empty = m & (self.tank <= 0) & (self.mode == _ACTIVE)
        if np.count_nonzero(empty):
            self.mode[empty] = _RETURNING
