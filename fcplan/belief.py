"""What the team knows, kept apart from the true world state.

The team never sees the fire directly: it knows the burning cells its agents have sensed (with the
tick each was last seen), the cells it has put out, and which parts of the map its cameras have
covered recently. Schedulers plan from this belief only (through :mod:`fcplan.taskgraph`).

* ``known``: flat indices of sensed cells not yet pruned (kept compact, no grid scans).
* ``last_seen``: (W, W) int32, the tick each cell was last sensed burning (-1: never).
* ``coverage``: a coarse grid (``coverage_px`` cells, 20 px by default) holding the tick each
  coarse cell's centre was last inside some sensing agent's field of view (-1: never). Search
  tasks are valued by how long ago their area was covered.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.belief import Belief
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> belief = Belief(world.scenario)
>>> for _ in range(20):
...     belief.update(world.step())
>>> belief.coverage.shape
(60, 60)
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

__all__ = ["Belief"]

_ZERO32 = np.int32(0)


class Belief:
    """The team's knowledge, updated from each tick's :class:`fcplan.world.StepInfo`.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    coverage_px : int
        Side of the coarse coverage cells in px.
    """

    def __init__(self, scenario, coverage_px: int = 20) -> None:
        w = scenario.world_size
        self.world_size = w
        self.ticks_per_second = scenario.ticks_per_second
        self.coverage_px = int(coverage_px)
        nc = -(-w // self.coverage_px)
        self.last_seen = np.full((w, w), -1, dtype=np.int32)
        self._last_seen_flat = self.last_seen.reshape(-1)
        self._known_mask = np.zeros(w * w, dtype=bool)
        self._known = np.zeros(0, dtype=np.int64)
        self._dirty = False
        self.coverage = np.full((nc, nc), -1, dtype=np.int32)
        self.n_pruned = 0
        self.tick = 0
        self.new_fire_since_plan = False
        #: rows of the agents that carry a camera (perception and hybrid)
        self._sensing_rows = [i for i, a in enumerate(scenario.agents) if a.role.can_sense]

    @property
    def known(self) -> np.ndarray:
        """(k,) int64 flat indices of cells known to be burning, in the order first sensed."""
        if self._dirty:
            self._known = self._known[self._known_mask[self._known]]
            self._dirty = False
        return self._known

    def known_xy(self) -> np.ndarray:
        """(k, 2) int64 ``[x, y]`` of the known burning cells."""
        k = self.known
        out = np.empty((k.size, 2), dtype=np.int64)
        np.divmod(k, self.world_size, out=(out[:, 0], out[:, 1]))
        return out

    def update(self, info) -> None:
        """Fold one tick's observations (a :class:`fcplan.world.StepInfo`) into the belief."""
        self.tick = info.tick
        if info.sensed.size:
            self._last_seen_flat[info.sensed] = info.tick
            fresh = info.sensed[~self._known_mask[info.sensed]]
            if fresh.size:
                self._known_mask[fresh] = True
                self._known = np.concatenate([self._known, fresh])
                self.new_fire_since_plan = True
        if info.pruned.size:
            self._known_mask[info.pruned] = False
            self.n_pruned += int(info.pruned.size)
            self._dirty = True
        self._cover(info.fov, info.tick)

    def _cover(self, fov: np.ndarray, tick: int) -> None:
        """Mark coarse cells whose centres lie inside a sensing agent's field of view."""
        if not self._sensing_rows:
            return
        c = self.coverage_px
        nc = self.coverage.shape[0]
        cov = self.coverage
        rects = fov.tolist()
        # coarse cell j has centre (j + 0.5) c; inside [a, b] iff ceil(a/c - 0.5) <= j <= floor(b/c - 0.5)
        for k in self._sensing_rows:
            x0, x1, y0, y1 = rects[k]
            i0 = min(max(math.ceil(x0 / c - 0.5), 0), nc)
            i1 = min(max(math.floor(x1 / c - 0.5) + 1, 0), nc)
            j0 = min(max(math.ceil(y0 / c - 0.5), 0), nc)
            j1 = min(max(math.floor(y1 / c - 0.5) + 1, 0), nc)
            cov[i0:i1, j0:j1] = tick

    def coverage_age_s(self, block_px: int) -> np.ndarray:
        """(B, B) mean seconds since the coarse cells of each ``block_px`` block were covered.

        ``B = ceil(W / block_px)``; a coarse cell belongs to the block holding its centre, and a
        block smaller than a coarse cell takes the age of the coarse cell under its centre.
        Never-covered cells count as covered one minute before the start, so unexplored areas are
        the stalest.
        """
        nb, key, counts, empty, centre_cells = _block_layout(
            self.world_size, self.coverage_px, self.coverage.shape[0], int(block_px)
        )
        never = np.int32(-60 * self.ticks_per_second)
        ticks = np.where(self.coverage >= _ZERO32, self.coverage, never)
        age = (self.tick - ticks).astype(np.float64) / self.ticks_per_second
        sums = np.bincount(key, weights=age.ravel(), minlength=nb * nb)
        out = sums / np.maximum(counts, 1)
        if empty.size:
            out[empty] = age.ravel()[centre_cells]
        return out.reshape(nb, nb)


@lru_cache(maxsize=32)
def _block_layout(w: int, c: int, nc: int, block_px: int):
    """How coarse coverage cells fall into ``block_px`` blocks (constant per map): block count
    per side, block of each coarse cell, coarse cells per block, blocks holding no coarse cell
    centre, and for those the coarse cell under the block's centre."""
    nb = -(-w // block_px)
    bi = np.minimum(((np.arange(nc) + 0.5) * c // block_px).astype(np.int64), nb - 1)
    key = (bi[:, None] * nb + bi[None, :]).ravel()
    counts = np.bincount(key, minlength=nb * nb)
    empty = np.flatnonzero(counts == 0)
    centre = (np.arange(nb) + 0.5) * block_px
    ci = np.minimum((centre // c).astype(np.int64), nc - 1)
    centre_cells = ci[empty // nb] * nc + ci[empty % nb]
    for a in (key, counts, empty, centre_cells):
        a.flags.writeable = False
    return nb, key, counts, empty, centre_cells
