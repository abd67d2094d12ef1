"""Replay frames of a recording: what the world looked like at any tick, from the file alone.

A recording holds the fire events tick by tick (cells that ignited, were first sensed, were put
out), the agents' states and every command, so a frame is rebuilt without simulating: the fire
grid is the cumulative ignitions minus the prunes, the known fire the sensed cells still burning,
and the route still ahead of each agent the last route it was commanded, from the goal it flies
to (agents going home show their home). Frames are :class:`fcplan.render.FrameData`, drawn by
:func:`fcplan.render.render_frame` (``fcplan replay``, :mod:`fcplan.video`).

Examples
--------
>>> from fcplan import load_scenario
>>> from fcplan.mission import Mission
>>> from fcplan.recording import Recorder
>>> sc = load_scenario("practice")
>>> rec = Recorder(sc, 0, source="human")
>>> Mission(sc, seed=0, observers=[rec]).advance(30)
30
>>> [f.tick for f in rec.recording().frames(10, 30, 10)]
[10, 20, 30]
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from fcplan.fire import BURNING, PRUNED
from fcplan.metrics import compute_metrics
from fcplan.recording.schema import EVENTS, HOME, PATROL, ROUTE
from fcplan.render import FrameData
from fcplan.scenario import Scenario
from fcplan.trace import Trace

__all__ = ["recording_frames"]

#: an agent's command history: (tick the command takes effect, route or None for home, patrol)
History = list[tuple[int, np.ndarray | None, bool]]


def recording_frames(
    scenario: Scenario,
    arrays: Mapping[str, np.ndarray],
    trace: Trace | None,
    start: int = 1,
    end: int | None = None,
    step: int = 1,
) -> Iterator[FrameData]:
    """:class:`fcplan.render.FrameData` for ticks ``start, start + step, ... <= end``.

    Tick ``t`` (1..T) shows the world after ``t`` steps: true fire (cumulative ignitions minus
    prunes), known fire (cells sensed and still burning), pruned cells, agents, the routes still
    ahead of each agent (from the last command it got) and, given the recording's ``trace``, the
    online manual scores.

    Parameters
    ----------
    scenario : Scenario
        The recorded scenario.
    arrays : mapping of str -> ndarray
        The recording's entries (:data:`fcplan.recording.schema.SCHEMA`).
    trace : Trace or None
        The recording's trace, for the scores (None: no scores).
    start, end, step : int
        Ticks to show (``end`` None: the last).
    """
    a, sc = arrays, scenario
    end = len(a["active"]) if end is None else min(int(end), len(a["active"]))
    start, step = max(int(start), 1), max(int(step), 1)
    w = sc.world_size
    state = np.zeros(w * w, dtype=np.uint8)
    sensed = np.zeros(w * w, dtype=bool)
    offs = {k: np.concatenate([[0], np.cumsum(a[f"{k}_count"], dtype=np.int64)]) for k in EVENTS}
    roles = np.array([int(x.role) for x in sc.agents])
    can_sense, can_act = roles != 1, roles != 0
    homes = np.array([x.start for x in sc.agents], np.float64).reshape(-1, 2)
    history = _route_history(a, len(sc.agents))
    done = 0  # ticks folded into the grids
    for t in range(start, end + 1, step):
        for k in EVENTS:
            cells = a[f"{k}_cells"][offs[k][done] : offs[k][t]]
            if k == "ignited":
                state[cells] = BURNING
            elif k == "sensed":
                sensed[cells] = True
            else:
                state[cells] = PRUNED
        done = t
        row = t - 1
        mode = a["agent_mode"][row]
        routes = [
            homes[i : i + 1] if mode[i] in (2, 3) else _ahead(a, history[i], row, i, t)
            for i in range(len(sc.agents))
        ]
        fire = state.reshape(w, w).copy()
        yield FrameData(
            tick=t,
            time_s=t / sc.ticks_per_second,
            fire=fire,
            known=(sensed.reshape(w, w) & (fire == BURNING)),
            pruned=fire == PRUNED,
            agent_pos=a["agent_xyz"][row, :, :2].copy(),
            agent_z=a["agent_xyz"][row, :, 2].copy(),
            agent_can_sense=can_sense,
            agent_can_act=can_act,
            agent_battery=a["agent_battery"][row].copy(),
            agent_tank=a["agent_tank"][row].copy(),
            agent_mode=mode.copy(),
            routes=tuple(routes),
            scores=_online_scores(trace, t) if trace is not None else {},
        )


def _ahead(a: Mapping[str, np.ndarray], history: History, row: int, i: int, t: int) -> np.ndarray:
    """(k, 2) goals still ahead of agent ``i`` at tick ``t`` (trace row ``row``)."""
    k = int(a["agent_goal_index"][row, i])
    route, patrol = _route_at(history, t)
    if k < 0 or route is None or k >= len(route):
        return np.zeros((0, 2))
    ahead = route[k:]
    if patrol and k > 0:
        ahead = np.concatenate([ahead, route[:k]])
    return ahead


def _route_history(a: Mapping[str, np.ndarray], n_agents: int) -> list[History]:
    """Per agent, (tick the command takes effect, route or None for home, patrol)."""
    hist: list[History] = [[] for _ in range(n_agents)]
    ends = np.cumsum(a["command_route_len"])
    starts = ends - a["command_route_len"]
    for c in range(len(a["command_tick"])):
        flags = int(a["command_flags"][c])
        i = int(a["command_agent"][c])
        if flags & HOME:
            hist[i].append((int(a["command_tick"][c]) + 1, None, False))
        elif flags & ROUTE:
            route = a["command_route_xy"][starts[c] : ends[c]]
            hist[i].append((int(a["command_tick"][c]) + 1, route, bool(flags & PATROL)))
    return hist


def _route_at(history: History, t: int) -> tuple[np.ndarray | None, bool]:
    """The route in force at tick ``t`` from an agent's command history."""
    route: np.ndarray | None = None
    patrol = False
    for tick, r, p in history:
        if tick > t:
            break
        route, patrol = r, p
    return route, patrol


def _online_scores(trace: Trace, t: int) -> dict[str, Any]:
    m = compute_metrics(trace, "manual", upto=t)
    return {
        "final score": m.final_score,
        "negative reward": -m.total_negative_reward,
        "firefighting (OFS)": m.overall_firefighting,
        "perception (PS)": m.perception,
        "action (AS)": m.action,
        "facilities (FPS)": m.facility_protection,
        "neg. reward ratio": m.negative_reward_ratio,
    }
