"""What one frame shows: :class:`FrameData`, copied out of a live world by :func:`snapshot`.

A frame is the drawable state of an episode at one instant: the true fire grid, the cells the
team knows are burning and the pruned ones, every agent's position, altitude, role, battery, tank
and mode, the goals still ahead of it, optional online scores for the panel and a highlighted
agent. It holds copies, so it stays valid while the world moves on; a recording rebuilds the same
:class:`FrameData` for any tick without a world (:meth:`fcplan.recording.Recording.frames`).

Examples
--------
>>> from fcplan import World, load_scenario
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> frame = snapshot(world)
>>> frame.tick, frame.known.shape == (world.world_size, world.world_size)
(0, True)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.fire import BURNING, PRUNED
from fcplan.team import Mode

__all__ = ["FrameData", "RenderError", "snapshot"]


class RenderError(FcplanError, ValueError):
    """A frame does not fit the scenario it is drawn on (grid or team size)."""


@dataclass(frozen=True, eq=False)
class FrameData:
    """What one frame shows: the state of an episode at one instant.

    Grids are indexed ``[x, y]`` (as :attr:`fcplan.fire.Fire.state`); agents are rows in scenario
    order (perception, action, hybrid).
    """

    tick: int
    time_s: float
    fire: np.ndarray | None  # (W, W) uint8 true fire state (fcplan.fire codes), None if unknown
    known: np.ndarray  # (W, W) bool cells the team knows are burning
    pruned: np.ndarray  # (W, W) bool cells put out
    agent_pos: np.ndarray  # (N, 2) float64 planar position (px)
    agent_z: np.ndarray  # (N,) float64 altitude (m)
    agent_can_sense: np.ndarray  # (N,) bool perception or hybrid
    agent_can_act: np.ndarray  # (N,) bool action or hybrid
    agent_battery: np.ndarray  # (N,) float64 remaining battery (capacity units)
    agent_tank: np.ndarray  # (N,) int remaining dumps
    agent_mode: np.ndarray  # (N,) int8 fcplan.team.Mode values
    routes: Sequence[np.ndarray] = ()  # N arrays (k, 2) float64: goals still ahead (may be empty)
    scores: Mapping[str, float] = field(default_factory=dict)  # online scores for the panel
    selected: int | None = None  # row of the highlighted agent


def snapshot(
    world: Any,
    belief: Any = None,
    routes: Sequence[Any] | None = None,
    scores: Mapping[str, float] | None = None,
) -> FrameData:
    """Copy the drawable state of a live world into a :class:`FrameData`.

    Parameters
    ----------
    world : fcplan.world.World
    belief : fcplan.belief.Belief, optional
        Supplies the known burning cells; without it, the world's sensed and still burning cells.
    routes : sequence of (k, 2) arrays, optional
        Goals per agent; by default the goals each agent has still ahead (home when it is
        returning).
    scores : mapping of str to float, optional
        Online scores to show in the panel.

    Returns
    -------
    FrameData

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> world = World().reset(load_scenario("practice"), seed=0)
    >>> frame = snapshot(world, scores={"score": 0.0})
    >>> frame.agent_pos.shape == (world.team.n, 2), bool(frame.known.any())
    (True, False)
    """
    team = world.team
    state = world.fire.state
    w = world.world_size
    if belief is not None:
        known = np.zeros(w * w, dtype=bool)
        known[belief.known] = True
        known = known.reshape(w, w)
    else:
        known = world.sensed & (state == BURNING)
    if routes is None:
        routes = []
        for i in range(team.n):
            if team.mode[i] in (Mode.RETURNING, Mode.HOMING):  # returning / homing: straight home
                routes.append(team.home[i : i + 1].copy())
            elif team.has_goal[i]:
                r = team.routes[i]
                k = int(team.goal_index[i])
                ahead = r[k:]
                if team.patrol[i] and k > 0:
                    ahead = np.concatenate([ahead, r[:k]])
                routes.append(np.array(ahead, dtype=np.float64).reshape(-1, 2))
            else:
                routes.append(np.zeros((0, 2)))
    else:
        routes = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in routes]
    return FrameData(
        tick=int(world.tick),
        time_s=float(world.time_s),
        fire=state.copy(),
        known=known,
        pruned=state == PRUNED,
        agent_pos=team.pos.copy(),
        agent_z=team.z.copy(),
        agent_can_sense=team.can_sense.copy(),
        agent_can_act=team.can_act.copy(),
        agent_battery=team.battery.copy(),
        agent_tank=np.asarray(team.tank).copy(),
        agent_mode=np.asarray(team.mode).copy(),
        routes=tuple(routes),
        scores=dict(scores or {}),
    )
