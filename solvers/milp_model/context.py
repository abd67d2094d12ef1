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
from solvers.milp_model.objective import block_values, fire_weight
from solvers.milp_model.routes import AgentRoles, agent_roles
from solvers.milp_model.sensing import TAN_Y, best_search_altitude
from solvers.milp_model.types import MilpParams

__all__ = ["BuildContext", "RouteSet"]


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
        self, graph: TaskGraph, p: MilpParams, recent_fire: Sequence[tuple[np.ndarray, np.ndarray]]
    ) -> None:
        self.graph, self.p = graph, p
        self.roles: AgentRoles = agent_roles(graph)
        self.weight = fire_weight(graph, p)
        self.fire = graph.task_kind == TaskKind.FIRE
        self.blocks = np.flatnonzero(~self.fire)
        self.block_value = block_values(graph, p, self.blocks, recent_fire)
        self.block_pos = graph.task_pos[self.blocks]
        self.width = max(p.slots, p.search_slots)

    def near_blocks(self, agent: int, z: float, factor: float = 1.0) -> np.ndarray:
        """Positions (in ``blocks``) of the search blocks a flight of ``agent`` at altitude ``z``
        can cover before the look-ahead ends (``factor`` times that radius): nothing farther
        from its start than ``v (H_s - t0)+`` plus the field of view and half a block diagonal
        is ever in view in time, so its cover is provably 0."""
        g, p = self.graph, self.p
        fly = float(g.agent_speed[agent]) * max(p.search_horizon_s - float(self.roles.t0[agent]), 0)
        reach = factor * fly + z * (1.0 + TAN_Y) + p.search_block_px / np.sqrt(2.0)
        d = np.hypot(*(self.block_pos - g.agent_start_pos[agent]).T)
        return np.flatnonzero(d <= reach)

    def altitudes(self, agent: int) -> tuple[float, float]:
        """(watch, search) altitudes of a camera agent, clipped to its bounds."""
        g, p = self.graph, self.p
        lo, hi = (float(v) for v in g.agent_alt_range[agent])
        speed = float(g.agent_speed[agent])
        z_search = (
            best_search_altitude(lo, hi, speed) if p.search_altitude is None else p.search_altitude
        )
        return g.clip_altitude(agent, p.watch_altitude), g.clip_altitude(agent, z_search)
