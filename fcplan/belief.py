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
from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.shared_views import KeepsViews

if TYPE_CHECKING:
    from fcplan.scenario import Scenario
    from fcplan.world import StepInfo

__all__ = ["Belief", "ClairvoyantBelief"]


class Belief(KeepsViews):
    """The team's knowledge, updated from each tick's :class:`fcplan.world.StepInfo`.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    coverage_px : int
        Side of the coarse coverage cells in px.
    """

    def __init__(self, scenario: Scenario, coverage_px: int = 20) -> None:
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
        self._coverage = np.full((nc, nc), -1, dtype=np.int32)
        n_s = sum(1 for a in scenario.agents if a.role.can_sense)
        #: per sensing agent: its last field of view, the coarse box it covered, and the tick of
        #: a deferred write of that box (None: nothing deferred)
        self._last_rect: list[list[float] | None] = [None] * n_s
        self._last_box: list[tuple[int, int, int, int]] = [(0, 0, 0, 0)] * n_s
        self._pending: list[int | None] = [None] * n_s
        self._lazy = True
        self.n_pruned = 0
        self.tick = 0
        self._tick_covered = 0
        #: rows of the agents that carry a camera (perception and hybrid)
        self._sensing_rows = [i for i, a in enumerate(scenario.agents) if a.role.can_sense]

    @property
    def known(self) -> np.ndarray:
        """(k,) int64 flat indices of cells known to be burning, in the order first sensed."""
        if self._dirty:
            self._known = self._known[self._known_mask[self._known]]
            self._dirty = False
        return self._known

    def last_seen_at(self, cells: np.ndarray) -> np.ndarray:
        """(n,) int32 :attr:`last_seen` of the flat ``cells``: the tick each was last sensed, -1
        if never (what the task graph builder reads; the batched belief answers the same).

        Examples
        --------
        >>> from fcplan import World, load_scenario
        >>> world = World().reset(load_scenario(1), seed=0)
        >>> belief = Belief(world.scenario)
        >>> belief.last_seen_at(np.array([0])).tolist()
        [-1]
        """
        return self._last_seen_flat[cells]

    def known_xy(self) -> np.ndarray:
        """(k, 2) int64 ``[x, y]`` of the known burning cells."""
        k = self.known
        out = np.empty((k.size, 2), dtype=np.int64)
        np.divmod(k, self.world_size, out=(out[:, 0], out[:, 1]))
        return out

    def update(self, info: StepInfo) -> None:
        """Fold one tick's observations (a :class:`fcplan.world.StepInfo`) into the belief."""
        self.tick = info.tick
        if info.sensed.size:
            self._last_seen_flat[info.sensed] = info.tick
            fresh = info.sensed[~self._known_mask[info.sensed]]
            if fresh.size:
                self._known_mask[fresh] = True
                self._known = np.concatenate([self._known, fresh])
        if info.pruned.size:
            self._known_mask[info.pruned] = False
            self.n_pruned += int(info.pruned.size)
            self._dirty = True
        self._cover(info.fov_rects, info.tick)

    @property
    def coverage(self) -> np.ndarray:
        """(nc, nc) int32: the tick each coarse cell's centre was last inside a sensing agent's
        field of view (-1: never)."""
        self._flush()
        return self._coverage

    def _cover(self, rects: list, tick: int) -> None:
        """Mark coarse cells whose centres lie inside a sensing agent's field of view (``rects``:
        every agent's ``[x0, x1, y0, y1]`` as :attr:`fcplan.world.StepInfo.fov_rects`; read only).

        An agent whose field of view is exactly the last tick's (hovering) would rewrite the same
        cells: the write is deferred until it moves or the coverage is read. Ticks never
        decrease, so a cell's value is the largest tick of the writes covering it, and a deferred
        write is applied as a maximum (if time ever goes backwards, writes are eager again).
        """
        rows = self._sensing_rows
        if not rows:
            return
        if tick < self._tick_covered:  # time went backwards: no deferral from here on
            self._flush()
            self._lazy = False
        self._tick_covered = tick
        c = self.coverage_px
        cov = self._coverage
        nc = cov.shape[0]
        last, boxes, pending = self._last_rect, self._last_box, self._pending
        lazy = self._lazy
        for slot, k in enumerate(rows):
            rect = rects[k]
            if lazy and rect == last[slot]:
                pending[slot] = tick
                continue
            t = pending[slot]
            if t is not None:
                _raise_to(cov, boxes[slot], t)
                pending[slot] = None
            i0, i1, j0, j1 = box = _coarse_box(rect, c, nc)
            cov[i0:i1, j0:j1] = tick
            last[slot], boxes[slot] = rect, box

    def _flush(self) -> None:
        """Apply the deferred coverage writes."""
        pending = self._pending
        for slot, t in enumerate(pending):
            if t is not None:
                _raise_to(self._coverage, self._last_box[slot], t)
                pending[slot] = None

    def coverage_age_s(self, block_px: int) -> np.ndarray:
        """(B, B) mean seconds since the coarse cells of each ``block_px`` block were covered.

        ``B = ceil(W / block_px)``; a coarse cell belongs to the block holding its centre, and a
        block smaller than a coarse cell takes the age of the coarse cell under its centre.
        Never-covered cells count as covered one minute before the start, so unexplored areas are
        the stalest.
        """
        cov = self.coverage
        nb, key, counts, empty, centre_cells, perm = _block_layout(
            self.world_size, self.coverage_px, cov.shape[0], int(block_px)
        )
        # never-covered cells (-1) count as covered at tick -60 s: as uint32, -1 is above every
        # tick and min(., -60 s as uint32) turns exactly the negative values >= -60 s (here -1)
        # into -60 s and keeps the ticks (one pass instead of a compare and a select)
        never = np.uint32(2**32 - 60 * self.ticks_per_second)
        if perm is not None:
            # every block holds m coarse cells: gathered as (m, B * B), row j = the j-th cell of
            # each block in raster order, so the sum down the columns adds each block's cells
            # one after the other in raster order (what bincount does)
            if isinstance(perm, int):  # square blocks of perm x perm coarse cells: a view
                m = perm
                blocks = cov.view(np.uint32).reshape(nb, m, nb, m).transpose(1, 3, 0, 2)
                ticks = np.empty((m, m, nb, nb), dtype=np.uint32)
                np.minimum(blocks, never, out=ticks)
            else:
                ticks = cov.take(perm).view(np.uint32)
                np.minimum(ticks, never, out=ticks)
            # int - int is exact in float64 (ticks << 2**53): one pass, no int32 temporary
            age = np.subtract(self.tick, ticks.view(np.int32), dtype=np.float64)
            age /= self.ticks_per_second
            out = np.add.reduce(age.reshape(-1, nb * nb), axis=0)
            out /= int(counts[0])  # every block's count (the same divisor as dividing by counts)
            return out.reshape(nb, nb)
        ticks = np.minimum(cov.view(np.uint32), never).view(np.int32)
        age = np.subtract(self.tick, ticks, dtype=np.float64)
        age /= self.ticks_per_second
        sums = np.bincount(key, weights=age.ravel(), minlength=nb * nb)
        out = sums / counts
        if empty.size:
            out[empty] = age.ravel()[centre_cells]
        return out.reshape(nb, nb)


def _coarse_box(rect: list[float], c: int, nc: int) -> tuple[int, int, int, int]:
    """Coarse cells ``[i0, i1) x [j0, j1)`` whose centres lie in ``rect = [x0, x1, y0, y1]``:
    cell j has centre (j + 0.5) c, inside [a, b] iff ceil(a/c - 0.5) <= j <= floor(b/c - 0.5)."""
    x0, x1, y0, y1 = rect
    i0 = math.ceil(x0 / c - 0.5)
    i1 = math.floor(x1 / c - 0.5) + 1
    j0 = math.ceil(y0 / c - 0.5)
    j1 = math.floor(y1 / c - 0.5) + 1
    # clamped to [0, nc] with conditional expressions: 4x cheaper than min(max(...)) calls
    return (
        0 if i0 < 0 else nc if i0 > nc else i0,
        0 if i1 < 0 else nc if i1 > nc else i1,
        0 if j0 < 0 else nc if j0 > nc else j0,
        0 if j1 < 0 else nc if j1 > nc else j1,
    )


def _raise_to(cov: np.ndarray, box: tuple[int, int, int, int], tick: int) -> None:
    """``cov[box] = max(cov[box], tick)``."""
    i0, i1, j0, j1 = box
    if i0 < i1 and j0 < j1:
        view = cov[i0:i1, j0:j1]
        np.maximum(view, tick, out=view)


@lru_cache(maxsize=32)
def _block_layout(w: int, c: int, nc: int, block_px: int) -> tuple[Any, ...]:
    """How coarse coverage cells fall into ``block_px`` blocks (constant per map): block count
    per side, block of each coarse cell, coarse cells per block (at least 1: divisors), blocks
    holding no coarse cell centre, for those the coarse cell under the block's centre, and when
    every block holds the same number ``m`` of coarse cells, the (m * B * B,) flat coarse cells
    ordered by position within the block (raster order), then by block, or, when the blocks are
    squares of ``s x s`` coarse cells tiling the grid, just ``s`` (else None)."""
    nb = -(-w // block_px)
    bi = np.minimum(((np.arange(nc) + 0.5) * c // block_px).astype(np.int64), nb - 1)
    key = (bi[:, None] * nb + bi[None, :]).ravel()
    counts = np.bincount(key, minlength=nb * nb)
    empty = np.flatnonzero(counts == 0)
    counts = np.maximum(counts, 1)  # divisors (empty blocks are filled apart)
    centre = (np.arange(nb) + 0.5) * block_px
    ci = np.minimum((centre // c).astype(np.int64), nc - 1)
    centre_cells = ci[empty // nb] * nc + ci[empty % nb]
    perm: np.ndarray | int | None = None
    if empty.size == 0 and (counts == counts[0]).all():
        by_block = np.argsort(key, kind="stable")  # blocks in order, raster order within
        perm = by_block.reshape(nb * nb, -1).T.ravel().copy()
        perm.flags.writeable = False
        m = block_px // c
        if block_px % c == 0 and nb * m == nc:
            # square sub-blocks: the gather is a transposed view of the (nc, nc) grid (no index
            # array to read); checked against the general order
            view = np.arange(nc * nc).reshape(nb, m, nb, m).transpose(1, 3, 0, 2).ravel()
            if np.array_equal(view, perm):
                perm = m
    for a in (key, counts, empty, centre_cells):
        a.flags.writeable = False
    return nb, key, counts, empty, centre_cells, perm


class ClairvoyantBelief:
    """The team's belief plus the true fire: what a clairvoyant planner (the ``oracle``
    reference, never a legal policy) builds its task graphs from.

    ``known`` holds every cell that is truly burning now (the team's known cells plus the ones it
    has not sensed yet); ``last_seen`` and the coverage stay the team's own, so a fire nobody has
    sensed has never been seen (its fire task is as stale as can be) and still has to be sensed
    before a dump puts it out, as the world's rules require. A read-only view: it changes nothing.

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> world = World().reset(load_scenario(1), seed=0)
    >>> belief = Belief(world.scenario)
    >>> for _ in range(30):
    ...     belief.update(world.step())
    >>> view = ClairvoyantBelief(belief, world.fire.state.reshape(-1))
    >>> bool(view.known.size >= belief.known.size), view.tick == belief.tick
    (True, True)
    """

    def __init__(self, belief: Belief, fire_state: np.ndarray) -> None:
        from fcplan.fire import BURNING

        self._belief = belief
        self.tick = belief.tick
        self.world_size = belief.world_size
        self.last_seen = belief.last_seen
        true = np.flatnonzero(fire_state == BURNING)
        k = belief.known
        self.known = np.concatenate([k, np.setdiff1d(true, k, assume_unique=True)])

    def last_seen_at(self, cells: np.ndarray) -> np.ndarray:
        """The team's own :meth:`Belief.last_seen_at` (-1 at the cells it has never sensed)."""
        return self._belief.last_seen_at(cells)

    def coverage_age_s(self, block_px: int) -> np.ndarray:
        """The team's own coverage ages (:meth:`Belief.coverage_age_s`)."""
        return self._belief.coverage_age_s(block_px)
