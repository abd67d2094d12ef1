"""Spatial decomposition of one role's routing model, for big teams.

One prize-collecting routing model over every vehicle of a big team is slow to build and
barely searched within a replan's limit (on 100 agents, two models of 50 vehicles x 100 nodes
used the whole 0.1 s for OR-Tools' first solution). A role with more than ``size`` vehicles is
therefore split into groups of at most ``size`` vehicles that lie close together, each group
with the tasks nearest to it, and each group is one small model (:func:`spatial_groups`):

* **vehicles**: recursive coordinate bisection of their start positions: a group larger than
  ``size`` is cut at the median of the coordinate with the larger spread into two halves whose
  sizes differ by at most one (ties by vehicle order, so the cut is deterministic), until every
  group holds at most ``size`` vehicles;
* **tasks**: each goes to the group of the nearest vehicle start among the vehicles allowed to
  serve it (ties: the lower vehicle index); a task no vehicle may serve is left out.

Groups share no vehicle and no task, so their routes together are a plan with every task
visited at most once. The price is at group borders: a vehicle never serves a task that is
nearer to another group's vehicle. ``bench/README.md`` measures the decomposition against one
model at 50 and 100 agents.

Examples
--------
>>> import numpy as np
>>> starts = np.array([[0, 0], [10, 0], [1000, 0], [1010, 0]], dtype=float)
>>> tasks = np.array([[5, 5], [1005, 5], [990, 0]], dtype=float)
>>> groups = spatial_groups(starts, tasks, np.ones((4, 3), dtype=bool), size=2)
>>> [(v.tolist(), t.tolist()) for v, t in groups]
[([0, 1], [0]), ([2, 3], [1, 2])]
>>> bisection_sizes(5, 2)
[2, 1, 2]
"""

from __future__ import annotations

import numpy as np

__all__ = ["bisection_sizes", "spatial_groups"]


def _bisect(starts: np.ndarray, rows: np.ndarray, size: int) -> list[np.ndarray]:
    """Vehicle rows cut into groups of at most ``size`` (module docstring), in cut order."""
    if rows.size <= size:
        return [rows]
    pts = starts[rows]
    axis = int(np.argmax(pts.max(axis=0) - pts.min(axis=0)))
    order = rows[np.lexsort((rows, pts[:, axis]))]
    half = rows.size // 2
    return _bisect(starts, np.sort(order[:half]), size) + _bisect(
        starts, np.sort(order[half:]), size
    )


def bisection_sizes(n: int, size: int) -> list[int]:
    """Group sizes that the bisection of ``n`` vehicles into groups of at most ``size`` makes
    (whatever their positions)."""
    if n <= size:
        return [n] if n else []
    return bisection_sizes(n // 2, size) + bisection_sizes(n - n // 2, size)


def spatial_groups(
    starts: np.ndarray, task_pos: np.ndarray, allowed: np.ndarray, size: int
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(vehicle rows, task rows)`` of each group (module docstring).

    Parameters
    ----------
    starts : ndarray, (V, 2)
        Start position of each vehicle.
    task_pos : ndarray, (K, 2)
        Position of each task.
    allowed : ndarray of bool, (V, K)
        Which vehicle may serve which task.
    size : int
        Most vehicles per group (>= 1).
    """
    n_v = starts.shape[0]
    groups = _bisect(starts, np.arange(n_v), max(int(size), 1))
    if len(groups) == 1:
        return [(groups[0], np.flatnonzero(allowed.any(axis=0)))]
    d = np.hypot(*(starts[:, None, :] - task_pos[None, :, :]).transpose(2, 0, 1))  # (V, K)
    d = np.where(allowed, d, np.inf)
    nearest = np.argmin(d, axis=0)
    served = np.isfinite(d[nearest, np.arange(task_pos.shape[0])])
    group_of = np.empty(n_v, dtype=np.int64)
    for g, rows in enumerate(groups):
        group_of[rows] = g
    owner = np.where(served, group_of[nearest], -1)
    return [(rows, np.flatnonzero(owner == g)) for g, rows in enumerate(groups)]
