"""Feasibility helpers shared by the built-in schedulers (battery, altitude bounds)."""

from __future__ import annotations

import numpy as np

from fcplan.taskgraph import TaskGraph
from fcplan.team import Mode

__all__ = ["start_positions", "start_budget", "round_trip_ok", "clip_altitude"]


def start_positions(graph: TaskGraph) -> np.ndarray:
    """(A, 2) where each agent's next route starts: its depot slot if it is being forced home
    (it will recharge first), else where it is."""
    forced = graph.agent_mode == Mode.RETURNING
    return np.where(forced[:, None], graph.agent_home, graph.agent_pos)


def start_budget(graph: TaskGraph) -> np.ndarray:
    """(A,) px of flight each agent has for its next route (full battery if going to recharge)."""
    forced = graph.agent_mode == Mode.RETURNING
    return np.where(forced, graph.agent_full_range, graph.agent_battery / 0.1)


def round_trip_ok(graph: TaskGraph) -> np.ndarray:
    """(A, K) bool: the task is within a round trip from the agent's depot slot on a full battery."""
    return 2.0 * graph.task_home_distance <= graph.agent_full_range[:, None]


def clip_altitude(graph: TaskGraph, i: int, z: float) -> float:
    """Altitude ``z`` clipped to agent ``i``'s bounds."""
    lo, hi = graph.agent_alt_range[i]
    return float(min(max(z, lo), hi))
