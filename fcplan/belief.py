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

import numpy as np

__all__ = ["Belief"]


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
        return np.stack([k // self.world_size, k % self.world_size], axis=1)

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
        c = self.coverage_px
        nc = self.coverage.shape[0]
        # coarse cell j has centre (j + 0.5) c; inside [a, b] iff ceil(a/c - 0.5) <= j <= floor(b/c - 0.5)
        j0 = np.ceil(fov[:, [0, 2]] / c - 0.5).astype(np.int64)
        j1 = np.floor(fov[:, [1, 3]] / c - 0.5).astype(np.int64)
        j0 = np.clip(j0, 0, nc)
        j1 = np.clip(j1 + 1, 0, nc)
        for k in self._sensing_rows:
            self.coverage[j0[k, 0] : j1[k, 0], j0[k, 1] : j1[k, 1]] = tick

    def coverage_age_s(self, block_px: int) -> np.ndarray:
        """(B, B) mean seconds since the coarse cells of each ``block_px`` block were covered.

        ``B = ceil(W / block_px)``; a coarse cell belongs to the block holding its centre, and a
        block smaller than a coarse cell takes the age of the coarse cell under its centre.
        Never-covered cells count as covered one minute before the start, so unexplored areas are
        the stalest.
        """
        c = self.coverage_px
        nc = self.coverage.shape[0]
        nb = -(-self.world_size // int(block_px))
        ticks = np.where(self.coverage >= 0, self.coverage, -60 * self.ticks_per_second)
        age = (self.tick - ticks).astype(np.float64) / self.ticks_per_second
        bi = np.minimum(((np.arange(nc) + 0.5) * c // block_px).astype(np.int64), nb - 1)
        key = (bi[:, None] * nb + bi[None, :]).ravel()
        sums = np.bincount(key, weights=age.ravel(), minlength=nb * nb)
        counts = np.bincount(key, minlength=nb * nb)
        out = sums / np.maximum(counts, 1)
        empty = np.flatnonzero(counts == 0)
        if empty.size:
            centre = (np.arange(nb) + 0.5) * block_px
            ci = np.minimum((centre // c).astype(np.int64), nc - 1)
            out[empty] = age[ci[empty // nb], ci[empty % nb]]
        return out.reshape(nb, nb)
