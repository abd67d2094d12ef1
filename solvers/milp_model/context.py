"""What building a route model needs from its graph: the routes' arrays before the variables are
laid out (:class:`RouteSet`), and what every agent's routes share (:class:`BuildContext`: roles,
fire weights, search blocks and their values, altitudes, reach). Used by the per-agent build
(:mod:`solvers.milp_model.build`) and the build across agents (:mod:`solvers.milp_model.batch`).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.milp_model.types import MilpParams
>>> g = synthetic_task_graph(3, 6, np.random.default_rng(0))
>>> ctx = BuildContext(g, MilpParams(), ())
>>> ctx.blocks.size + int(ctx.fire.sum()) == g.n_tasks
True
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fcplan.taskgraph import TaskGraph, TaskKind
from solvers.milp_model.objective import FireSnapshot, block_values, fire_weight
from solvers.milp_model.routes import AgentRoles, agent_roles
from solvers.milp_model.sensing import TAN_Y, best_search_altitude
from solvers.milp_model.types import MilpParams

__all__ = ["PROJECTION_MARGIN", "BuildContext", "RouteSet", "projected_past"]

#: A build under a deadline gives up as soon as even this share of its projected length (agents
#: and chunks of segments cost alike, within that margin) ends past the deadline, so that a
#: fallback still has the time the rest of the build would have wasted.
PROJECTION_MARGIN = 0.8


def projected_past(start: float, now: float, done: int, total: int, deadline: float) -> bool:
    """True when a build that did ``done`` of ``total`` equal steps between ``start`` and
    ``now`` (``perf_counter`` s) is projected to end past ``deadline`` (see
    :data:`PROJECTION_MARGIN`)."""
    return start + (now - start) * total / done * PROJECTION_MARGIN > deadline


@dataclass(frozen=True, eq=False)
class RouteSet:
    """The routes of a model (``R`` rows), before the variables are laid out."""

    agent: np.ndarray  # (R,) int64
    kind: np.ndarray  # (R,) int8 DUMP / WATCH / SEARCH
    tasks: np.ndarray  # (R, L) int64, -1 padded
    arrival: np.ndarray  # (R, L) float64, NaN padded
    length: np.ndarray  # (R,) float64 px
    value: np.ndarray  # (R,) float64 own objective coefficient
    altitude: np.ndarray  # (R,) float64 (NaN: no camera)
    cover: sp.csr_array  # (R, B) int64 detected share of each block, in 1 / cover_levels


class BuildContext:
    """What every agent's routes need from the graph (computed once per model)."""

    def __init__(
        self,
        graph: TaskGraph,
        p: MilpParams,
        recent_fire: Sequence[FireSnapshot | tuple[np.ndarray, np.ndarray]],
    ) -> None:
        self.graph, self.p = graph, p
        self.roles: AgentRoles = agent_roles(graph)
        self.weight = fire_weight(graph, p)
        self.fire = graph.task_kind == TaskKind.FIRE
        self.blocks = np.flatnonzero(~self.fire)
        self.block_value = block_values(graph, p, self.blocks, recent_fire)
        self.block_pos = graph.task_pos[self.blocks]
        self.width = max(p.slots, p.search_slots)

    def reach(self, agents: np.ndarray, z: np.ndarray, factor: float = 1.0) -> np.ndarray:
        """Radius (px, around each start) beyond which a flight of ``agents`` at altitudes ``z``
        sees nothing before the look-ahead ends (``factor`` times the flight): ``v (H_s - t0)+``
        plus the field of view and half a block diagonal. Nothing farther is ever in view in
        time, so its cover is provably 0."""
        g, p = self.graph, self.p
        fly = g.agent_speed[agents].astype(np.float64) * np.maximum(
            p.search_horizon_s - self.roles.t0[agents], 0.0
        )
        out: np.ndarray = factor * fly + z * (1.0 + TAN_Y) + p.search_block_px / np.sqrt(2.0)
        return out

    def near_blocks(self, agent: int, z: float, factor: float = 1.0) -> np.ndarray:
        """Positions (in ``blocks``) of the search blocks within :meth:`reach` of ``agent``'s
        start at altitude ``z``."""
        reach = self.reach(np.array([agent]), np.array([z], dtype=np.float64), factor)[0]
        d = np.hypot(*(self.block_pos - self.graph.agent_start_pos[agent]).T)
        return np.flatnonzero(d <= reach)

    def altitudes(self, agent: int) -> tuple[float, float]:
        """(fire, search) altitudes of a camera agent, clipped to its bounds. The fire altitude is
        ``dump_altitude`` (default the top of the bounds) for an agent with water, whose fire
        routes dump: a dump puts out the sensed burning cells in view, and the view grows with
        the altitude. For a camera agent without water, whose fire routes watch, it is
        ``watch_altitude`` (low: reliable sensing)."""
        g, p = self.graph, self.p
        if bool(self.roles.dumper[agent]):
            z_fire = g.dump_altitude(agent, p.dump_altitude)
        else:
            z_fire = g.clip_altitude(agent, p.watch_altitude)
        lo, hi = (float(v) for v in g.agent_alt_range[agent])
        speed = float(g.agent_speed[agent])
        z_search = (
            best_search_altitude(lo, hi, speed) if p.search_altitude is None else p.search_altitude
        )
        return z_fire, g.clip_altitude(agent, z_search)
