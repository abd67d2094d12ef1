"""Small-team kernels of :class:`fcplan.team.Team` on Python numbers.

For teams of up to :data:`fcplan.team.SMALL_TEAM` agents, :meth:`Team.move
<fcplan.team.Team.move>` runs :func:`move_small` instead of the numpy rule ``Team._move_vector``,
and ``Team._rules`` runs :func:`rules_small`. Both perform the vector rule's IEEE operations agent
by agent, in the same order, so they leave every state array bit for bit as the vector rule does:
``hypot`` is numpy's (or ``|d|`` when one component is zero, which C99 Annex F makes exact),
``max(d, tiny)`` keeps a NaN distance NaN as ``np.maximum`` does, and ``-0.0`` coordinates take the
``x + 0.0 (t - x)`` step that turns them into ``+0.0`` in the vector rule.

The kernels read the team's arrays and the per-team constants ``Team.__init__`` prepares
(``_home_list``, ``_speed_list``, ``_hover_drain``, ...), and the rule constants from the team's
class (``_drain_per_px``, ``_idle_limit``, ``_modes``, ``_fov_scale_list``): this module cannot
import :mod:`fcplan.team`, which imports it. ``tests/_fast/test_fast_team.py`` checks the
equivalence on random command sequences.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["move_small", "rules_small", "fov_rects_small", "sensing_confidence_of"]

_NO_ROWS = np.zeros(0, dtype=np.int64)
_TINY = 5e-324  # smallest positive double
_BOUND = 1.0 + 1e-9  # relative margin of rules_small's reserve bound


def move_small(team: Any) -> np.ndarray:
    """``Team._move_vector`` agent by agent on Python floats; return the rows that arrived.

    Only the agents that fly or hover are touched. Every other one would move by
    ``(d / |d|) 0.0``, the zero of ``d``'s sign: ``x + (+-0.0)`` is ``x`` unless ``x`` is a zero
    (whose sign it may change, so zero coordinates take that operation), and its battery and
    distance would change by ``+-0.0``, which leaves them as they are (a distance is never
    ``-0.0``).

    Parameters
    ----------
    team : fcplan.team.Team
        A team of at most ``SMALL_TEAM`` agents; moved in place.

    Returns
    -------
    ndarray, (k,) int
        Rows of the agents that reached a route goal this tick.
    """
    _, active, returning, _ = team._modes
    drain_px = team._drain_per_px
    mode = team.mode.tolist()
    pos = team.pos.ravel().tolist()  # flat [x0, y0, x1, y1, ...], updated in place below
    has_goal = team.has_goal.tolist()
    home = team._home_list
    goal = None
    act = []  # ACTIVE rows
    hover = []  # ACTIVE rows without a goal
    legs: list[list[Any]] = []  # flyers: [row, target x, target y, dx, dy, |d|]
    hyp_k, hyp_x, hyp_y = [], [], []  # legs that need numpy's hypot
    for i, m in enumerate(mode):
        if m == active:
            act.append(i)
            if not has_goal[i]:
                hover.append(i)
                continue
            if goal is None:
                goal = team.goal.tolist()
            tx, ty = goal[i]
        elif m >= returning:  # RETURNING or HOMING: flies home
            tx, ty = home[i]
        else:
            continue
        dx, dy = tx - pos[2 * i], ty - pos[2 * i + 1]
        if dy == 0.0:  # hypot(x, +-0) is |x| exactly (C99 Annex F)
            legs.append([i, tx, ty, dx, dy, abs(dx)])
        elif dx == 0.0:
            legs.append([i, tx, ty, dx, dy, abs(dy)])
        else:
            hyp_k.append(len(legs))
            hyp_x.append(dx)
            hyp_y.append(dy)
            legs.append([i, tx, ty, dx, dy, 0.0])
    # zero coordinates of agents that do not fly (x + 0.0 (t - x) may flip a -0.0)
    moved = bool(legs)
    if 0.0 in pos:
        for i, m in enumerate(mode):
            if m < returning and not (m == active and has_goal[i]):
                x, y = pos[2 * i], pos[2 * i + 1]
                if x == 0.0 or y == 0.0:
                    if goal is None:
                        goal = team.goal.tolist()
                    tx, ty = goal[i]
                    pos[2 * i] = x + 0.0 * (tx - x)
                    pos[2 * i + 1] = y + 0.0 * (ty - y)
                    moved = True
    battery = None
    arrived = None  # rows that reached their target
    if legs:
        if hyp_k:
            for k, d in zip(hyp_k, np.hypot(hyp_x, hyp_y).tolist(), strict=True):
                legs[k][5] = d
        speed = team._speed_list
        dist = team.distance.tolist()
        battery = team.battery.tolist()
        for i, tx, ty, dx, dy, d in legs:
            sp = speed[i]
            if d <= sp:
                pos[2 * i] = tx
                pos[2 * i + 1] = ty
                step = d
                if arrived is None:
                    arrived = [i]
                else:
                    arrived.append(i)
            else:
                # max(d, _TINY) without the call (a NaN distance stays NaN, as np.maximum)
                den = d if not d < _TINY else _TINY
                pos[2 * i] += dx / den * sp
                pos[2 * i + 1] += dy / den * sp
                step = sp
            dist[i] += step
            battery[i] -= drain_px * step
        team.distance[:] = dist
    if moved:
        team.pos = np.array(pos, dtype=np.float64).reshape(team.n, 2)
    hover_s = None  # None: every hover clock is 0
    if hover:
        if battery is None:
            battery = team.battery.tolist()
        hd, dt, old = team._hover_drain, team.dt_s, team.hover_s.tolist()
        hover_s = [0.0] * team.n
        for i in hover:
            battery[i] -= hd
            hover_s[i] = old[i] + dt
        team.hover_s = np.array(hover_s, dtype=np.float64)
    else:
        team.hover_s = np.zeros(team.n)
    if battery is not None:
        team.battery[:] = battery
    # altitude
    z, zt = team.z.tolist(), team.z_target.tolist()
    if z != zt:  # (NaN targets compare unequal, as in the vector path)
        # an agent at its target altitude moves by +0.0, which changes only a -0.0
        climb, lo, sense = team._climb, -team._climb, team._can_sense_list
        for i, (zi, t) in enumerate(zip(z, zt, strict=True)):
            if zi != t or zi == 0.0:
                z[i] = zi + min(max(t - zi, lo), climb) * sense[i]
        team.z[:] = z
    if arrived is not None:
        # docking first, then the next goals, as the vector path
        for i in arrived:
            if mode[i] >= returning:
                team._dock(i)
        rows = [i for i in arrived if mode[i] == active]
        for i in rows:
            team._next_goal(i)
        team._rules()  # docking changed modes
        return np.array(rows, dtype=np.intp) if rows else _NO_ROWS
    if act:
        rules_small(team, act, mode, pos, battery, hover_s)
    return _NO_ROWS


def rules_small(
    team: Any,
    rows: list[int],
    mode: list[int],
    pos: list[float],
    battery: list[float] | None,
    hover_s: list[float] | None,
) -> None:
    """``Team._rules`` (battery reserve, 3-second rule) of a small team on Python numbers.

    An agent whose battery is above an upper bound of its reserve (``hypot(d) <= |dx| + |dy|``,
    with a margin covering every rounding) is certainly not low; only the others need the exact
    reserve, with numpy's ``hypot`` and the vector rule's operations.

    Parameters
    ----------
    team : fcplan.team.Team
        The team (its ``mode`` and ``has_goal`` are updated in place).
    rows : list of int
        The ACTIVE rows, in order.
    mode : list of int
        The current modes (updated in place along with the team's).
    pos : list of float
        Flat positions ``[x0, y0, x1, y1, ...]``.
    battery : list of float or None
        Batteries (None: read them from the team).
    hover_s : list of float or None
        Hover clocks (None: every clock is 0).
    """
    _, active, returning, homing = team._modes
    drain_px, idle_limit = team._drain_per_px, team._idle_limit
    if battery is None:
        battery = team.battery.tolist()
    hm, home, margins = team._hover_margin, team._home_list, team._speed_margin_list
    near = None
    for i in rows:
        hx, hy = home[i]
        if (
            not battery[i]
            > (drain_px * (abs(hx - pos[2 * i]) + abs(hy - pos[2 * i + 1])) + margins[i] + hm)
            * _BOUND
        ):
            if near is None:
                near = [i]
            else:
                near.append(i)
    if near is not None:
        dx = [home[i][0] - pos[2 * i] for i in near]
        dy = [home[i][1] - pos[2 * i + 1] for i in near]
        for i, h in zip(near, np.hypot(dx, dy).tolist(), strict=True):
            if battery[i] <= drain_px * h + margins[i] + hm:
                team.mode[i] = returning
                mode[i] = returning
    if hover_s is None or not max(hover_s) >= idle_limit:  # (the usual case)
        return
    for i, (m, h, act) in enumerate(zip(mode, hover_s, team._is_action_list, strict=True)):
        if m == active and act and h >= idle_limit:
            team.mode[i] = homing
            team.has_goal[i] = False


def fov_rects_small(team: Any) -> list[list[float]]:
    """``Team.fov_rects().tolist()`` on Python floats: ``x + z (-t)`` per bound, as the rule.

    Parameters
    ----------
    team : fcplan.team.Team

    Returns
    -------
    list of list of float
        Per agent ``[x0, x1, y0, y1]``.
    """
    # (a plain loop: cheaper than a comprehension's own frame for a handful of agents)
    ax, bx, ay, by = team._fov_scale_list
    rects = []
    for (x, y), z in zip(team.pos.tolist(), team.z.tolist(), strict=True):
        rects.append([x + z * ax, x + z * bx, y + z * ay, y + z * by])
    return rects


def sensing_confidence_of(team: Any, i: int) -> float:
    """``Team.sensing_confidence()[i]`` on Python floats (same IEEE operations).

    Parameters
    ----------
    team : fcplan.team.Team
    i : int
        Agent row.

    Returns
    -------
    float
    """
    c = 1.0 - 0.6 * (float(team.z[i]) - float(team.alt_lo[i])) * float(team._inv_span[i])
    return min(max(c, 0.4), 1.0) * bool(team.can_sense[i])
