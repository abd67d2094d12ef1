"""The team's belief of ``B`` worlds at once: :class:`fcplan.belief.Belief` with a batch axis.

:class:`BatchBelief` folds each tick of a :class:`fcplan.batch.BatchWorld` into the beliefs of
every world that ran it, in a handful of numpy calls whatever ``B``; world ``b``'s view
(:meth:`BatchBelief.view`) reads, for the task graph builder, exactly what a
:class:`~fcplan.belief.Belief` fed world ``b``'s ticks one by one holds (``tests/
test_belief_batch.py`` checks it bit for bit). The rules are the single belief's; only the
bookkeeping differs:

==================  ==========================  =================================================
array               shape, dtype                notes
==================  ==========================  =================================================
seen                (B, W, W) int32             one more than the tick each cell was last sensed
                                                (0: never); :meth:`BatchBelief.last_seen` gives
                                                world ``b``'s map as the single belief's
known mask          (B * W * W,) bool           sensed and not pruned
rows touched        (B, W) bool                 the map rows where a cell was ever sensed since
                                                the world's reset
known               B lists of (k,) int64       per world the cells in the order first sensed, as
                                                of its last read, plus the flat ``b W^2 + cell``
                                                cells first sensed since (one array per tick),
                                                filtered at the next read if a cell was pruned
                                                (the single belief's lazy filter, at the same
                                                reads)
``coverage``        (B, nc, nc) int32           the tick each coarse cell was last covered
``tick``            (B,) int64                  the world's tick at its last update
==================  ==========================  =================================================

Memory. The two maps are 7.2 MB of every world at 1,200 px, and only the cells the team sensed
burning are ever written. So both are created by :func:`fcplan.batch.pages.paged_zeros` (the
operating system gives their small pages, zeroed, at the first write: a map costs only the
pages holding sensed cells), and the seen map stores ``tick + 1``, so that "never" is 0 and
needs no write. A reset clears only the rows touched since the last one. The single belief's
dense ``last_seen`` of -1 is the specification; :meth:`BatchBelief.last_seen` and
:meth:`BeliefView.last_seen_at` read it back. ``bench/README.md`` ("The batched belief is paged
in only where written") measures the resident size this saves (about 6.8 MB of 9.1 per world on
#1) and what the page faults cost.

Coverage. A coarse cell's value is the largest tick of the writes covering it (ticks never
decrease within an episode). The single belief defers the rewrite of a hovering camera's box and
applies it as a maximum when it is read; here every sensing agent's box is compared with its last
one as integers: a moved camera's box is written at once (and its deferred tick first, as a
maximum), a hovering one's tick is kept and written, as a maximum, at the next read. Both give
the maximum of the ticks that covered each cell.

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> from fcplan.batch import BatchWorld
>>> sc = load_scenario("practice")
>>> batch = BatchWorld(sc, 2)
>>> batch.reset(seeds=[0, 1])
>>> beliefs = BatchBelief(sc, 2)
>>> for _ in range(20):
...     beliefs.update(batch.step(), batch.tick)
>>> view = beliefs.view(1, 100)
>>> view.tick, view.coverage_age_s(100).shape
(20, (12, 12))
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.batch.pages import PagedRows, paged_zeros
from fcplan.belief import _block_layout
from fcplan.shared_views import KeepsViews

if TYPE_CHECKING:
    from fcplan.batch import BatchStepInfo
    from fcplan.scenario import Scenario

__all__ = ["BatchBelief", "BeliefView", "coverage_ages"]


class BeliefView:
    """World ``b``'s belief as :class:`fcplan.taskgraph.TaskGraphBuilder` reads it: ``tick``,
    ``known``, ``world_size``, :meth:`last_seen_at` and :meth:`coverage_age_s` (a read-only
    snapshot of the batch at :meth:`BatchBelief.view`; do not keep it across updates)."""

    __slots__ = ("tick", "known", "world_size", "_ages", "_block_px", "_owner", "_b")

    def __init__(
        self,
        owner: BatchBelief,
        b: int,
        known: np.ndarray,
        ages: np.ndarray | None,
        block_px: int,
    ) -> None:
        self._owner, self._b = owner, b
        self.tick = int(owner.tick[b])
        self.known = known
        self.world_size = owner.world_size
        self._ages, self._block_px = ages, block_px

    def last_seen_at(self, cells: np.ndarray) -> np.ndarray:
        """(n,) int32 the tick each of the flat ``cells`` was last sensed, -1 if never
        (:meth:`fcplan.belief.Belief.last_seen_at`)."""
        return self._owner.last_seen_at(self._b, cells)

    def coverage_age_s(self, block_px: int) -> np.ndarray:
        """(nb, nb) mean seconds since the coarse cells of each block were covered
        (:meth:`fcplan.belief.Belief.coverage_age_s`)."""
        if self._ages is not None and int(block_px) == self._block_px:
            return self._ages
        return self._owner.coverage_ages(int(block_px), np.array([self._b]))[0]


class BatchBelief(KeepsViews):
    """The beliefs of ``num`` worlds of ``scenario`` (module docstring).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    num : int
        Worlds ``B``.
    coverage_px : int
        Side of the coarse coverage cells in px (as :class:`fcplan.belief.Belief`).
    """

    def __init__(self, scenario: Scenario, num: int, coverage_px: int = 20) -> None:
        w = self.world_size = int(scenario.world_size)
        self.num = b = int(num)
        self.ticks_per_second = scenario.ticks_per_second
        self.coverage_px = c = int(coverage_px)
        self._nc = nc = -(-w // c)
        self._seen = paged_zeros((b, w, w), np.int32)  # tick + 1 (0: never)
        self._seen_flat = self._seen.reshape(-1)
        self._mask = paged_zeros((b * w * w,), np.bool_)
        self._touched = np.zeros((b, w), dtype=bool)  # rows with a sensed cell since reset
        self._touched_flat = self._touched.reshape(-1)
        self._known: list[np.ndarray] = [np.zeros(0, dtype=np.int64) for _ in range(b)]
        self._fresh: list[np.ndarray] = []  # flat b W^2 + cell first sensed since the last read
        self._dirty = np.zeros(b, dtype=bool)
        self.coverage = np.full((b, nc, nc), -1, dtype=np.int32)
        self._cov_flat = self.coverage.reshape(-1)
        self.tick = np.zeros(b, dtype=np.int64)
        self.n_pruned = np.zeros(b, dtype=np.int64)
        #: rows of the agents that carry a camera
        self._rows = np.array([i for i, a in enumerate(scenario.agents) if a.role.can_sense])
        n_s = len(self._rows)
        self._box = np.zeros((b, n_s, 4), dtype=np.int64)
        self._has_box = np.zeros((b, n_s), dtype=bool)
        self._pending = np.full((b, n_s), -1, dtype=np.int64)  # deferred tick (-1: none)

    def __getstate__(self) -> dict[str, Any]:
        """The state for a copy or pickle: the paged maps as their touched rows only
        (:class:`fcplan.batch.pages.PagedRows`), the other views of shared memory as records
        (:class:`fcplan.shared_views.KeepsViews`)."""
        state = super().__getstate__()
        w = self.world_size
        state["_seen"] = PagedRows(self._seen, self._touched)
        state["_mask"] = PagedRows(self._mask.reshape(self.num, w, w), self._touched)
        del state["_seen_flat"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Restore a copied state (:meth:`__getstate__`)."""
        super().__setstate__(state)
        self._seen_flat = self._seen.reshape(-1)
        self._mask = self._mask.reshape(-1)

    def reset(self, rows: np.ndarray) -> None:
        """Empty beliefs in the worlds ``rows`` (new episodes)."""
        rows = np.asarray(rows, dtype=np.int64)
        if not rows.size:
            return
        self._take_fresh()
        w = self.world_size
        n, row = np.nonzero(self._touched[rows])  # (clearing only these keeps the rest unpaged)
        world = rows[n]
        self._seen[world, row] = 0
        self._mask.reshape(self.num, w, w)[world, row] = False
        self._touched[rows] = False
        for b in rows.tolist():
            self._known[b] = np.zeros(0, dtype=np.int64)
        self._dirty[rows] = False
        self.coverage[rows] = -1
        self.tick[rows] = 0
        self.n_pruned[rows] = 0
        self._has_box[rows] = False
        self._pending[rows] = -1

    # ------------------------------------------------------------------ updates
    def update(self, info: BatchStepInfo, ticks: np.ndarray) -> None:
        """Fold one batch tick into the beliefs of the worlds that ran it (``ticks``: (B,) every
        world's tick after it, :attr:`fcplan.batch.BatchWorld.tick`)."""
        ran = info.ran
        self.tick[ran] = ticks[ran]
        ww = self.world_size * self.world_size
        sw, sc = info.sensed
        if sw.size:
            key = sw * ww + sc
            self._seen_flat[key] = (ticks + 1)[sw]
            fresh = key[~self._mask[key]]
            if fresh.size:  # (every cell written was fresh once since its world's reset)
                self._mask[fresh] = True
                self._fresh.append(fresh)
                self._touched_flat[fresh // self.world_size] = True  # b W + x
        pw, pc = info.pruned
        if pw.size:
            self._mask[pw * ww + pc] = False
            self.n_pruned += np.bincount(pw, minlength=self.num)
            self._dirty[pw] = True
        self._cover(info.fov, ran, ticks)

    def _cover(self, fov: np.ndarray, ran: np.ndarray, ticks: np.ndarray) -> None:
        """Coverage writes of one tick: every sensing agent's box of coarse cells whose centres
        lie in its field of view (``fcplan.belief._coarse_box``, element-wise)."""
        if not len(self._rows):
            return
        c, nc = self.coverage_px, self._nc
        rect = fov[:, self._rows]  # (B, S, 4) x0, x1, y0, y1
        box = np.empty(rect.shape, dtype=np.int64)
        box[..., 0::2] = np.ceil(rect[..., 0::2] / c - 0.5)  # i0, j0
        box[..., 1::2] = np.floor(rect[..., 1::2] / c - 0.5) + 1  # i1, j1
        np.clip(box, 0, nc, out=box)
        same = (box == self._box).all(axis=2) & self._has_box
        hover = same & ran[:, None]
        moved = ~same & ran[:, None]
        self._pending[hover] = np.broadcast_to(ticks[:, None], hover.shape)[hover]
        flush = moved & (self._pending >= 0)
        if flush.any():
            self._write(self._box[flush], np.flatnonzero(flush) // len(self._rows),
                        self._pending[flush], maximum=True)  # fmt: skip
            self._pending[flush] = -1
        if moved.any():
            w = np.flatnonzero(moved) // len(self._rows)
            self._write(box[moved], w, ticks[w], maximum=False)
            self._box[moved] = box[moved]
            self._has_box[moved] = True

    def _write(self, boxes: np.ndarray, worlds: np.ndarray, ticks: np.ndarray, *,
               maximum: bool) -> None:  # fmt: skip
        """Write ``ticks[n]`` into box ``boxes[n]`` (i0, i1, j0, j1) of world ``worlds[n]`` (as
        a maximum, or plainly when the tick is the newest of its world)."""
        nc = self._nc
        ni = np.maximum(boxes[:, 1] - boxes[:, 0], 0)
        nj = np.maximum(boxes[:, 3] - boxes[:, 2], 0)
        n = ni * nj
        total = int(n.sum())
        if not total:
            return
        which = np.repeat(np.arange(len(boxes)), n)
        local = np.arange(total) - np.repeat(np.cumsum(n) - n, n)
        q, r = np.divmod(local, nj[which])
        flat = (worlds[which] * nc + boxes[which, 0] + q) * nc + boxes[which, 2] + r
        if maximum:
            np.maximum.at(self._cov_flat, flat, ticks[which].astype(np.int32))
        else:  # (duplicates hold the same tick: the order of the writes does not matter)
            self._cov_flat[flat] = ticks[which]

    def _flush(self, rows: np.ndarray) -> None:
        """Apply the deferred coverage writes of the worlds ``rows``."""
        sel = np.zeros(self.num, dtype=bool)
        sel[rows] = True
        due = (self._pending >= 0) & sel[:, None]
        if due.any():
            w = np.flatnonzero(due) // len(self._rows)
            self._write(self._box[due], w, self._pending[due], maximum=True)
            self._pending[due] = -1

    def _take_fresh(self) -> None:
        """Move the cells first sensed since the last read into the per-world lists (in the
        order sensed; the per-tick arrays are sorted by world)."""
        if not self._fresh:
            return
        keys = np.concatenate(self._fresh) if len(self._fresh) > 1 else self._fresh[0]
        self._fresh = []
        ww = self.world_size * self.world_size
        world, cell = np.divmod(keys, ww)
        order = np.argsort(world, kind="stable")
        world, cell = world[order], cell[order]
        cuts = np.searchsorted(world, np.arange(self.num + 1))
        for b in np.flatnonzero(np.diff(cuts)).tolist():
            add = cell[cuts[b] : cuts[b + 1]]
            old = self._known[b]
            self._known[b] = np.concatenate([old, add]) if old.size else add

    # ------------------------------------------------------------------ reads
    def last_seen_at(self, b: int, cells: np.ndarray) -> np.ndarray:
        """(n,) int32 the tick each of world ``b``'s flat ``cells`` was last sensed, -1 if never
        (:meth:`fcplan.belief.Belief.last_seen_at`)."""
        ww = self.world_size * self.world_size
        return self._seen_flat[b * ww + np.asarray(cells, dtype=np.int64)] - np.int32(1)

    def last_seen(self, b: int) -> np.ndarray:
        """(W, W) int32 world ``b``'s :attr:`fcplan.belief.Belief.last_seen`: the tick each cell
        was last sensed, -1 if never (a new array)."""
        return self._seen[b] - np.int32(1)

    def known(self, b: int) -> np.ndarray:
        """(k,) int64 flat indices of world ``b``'s known burning cells, in the order first
        sensed (:attr:`fcplan.belief.Belief.known`)."""
        self._take_fresh()
        if self._dirty[b]:
            k = self._known[b]
            ww = self.world_size * self.world_size
            self._known[b] = k[self._mask[b * ww + k]]
            self._dirty[b] = False
        return self._known[b]

    def coverage_ages(self, block_px: int, rows: np.ndarray) -> np.ndarray:
        """(len(rows), nb, nb) :meth:`fcplan.belief.Belief.coverage_age_s` of the worlds
        ``rows`` (:func:`coverage_ages`)."""
        rows = np.asarray(rows, dtype=np.int64)
        self._flush(rows)
        return coverage_ages(
            self.coverage[rows], self.tick[rows], self.world_size, self.coverage_px,
            self.ticks_per_second, block_px,
        )  # fmt: skip

    def views(self, rows: np.ndarray, block_px: int) -> list[BeliefView]:
        """:meth:`view` of each world of ``rows``, their coverage ages computed together."""
        rows = np.asarray(rows, dtype=np.int64)
        ages = self.coverage_ages(block_px, rows)
        return [
            BeliefView(self, b, self.known(b), ages[n], int(block_px))
            for n, b in enumerate(rows.tolist())
        ]

    def view(self, b: int, block_px: int) -> BeliefView:
        """World ``b``'s belief as the task graph builder reads it (its coverage ages for
        ``block_px`` blocks computed now)."""
        return self.views(np.array([b]), block_px)[0]


def coverage_ages(
    cov: np.ndarray, tick: np.ndarray, w: int, c: int, tps: Any, block_px: int
) -> np.ndarray:
    """(B, nb, nb) :meth:`fcplan.belief.Belief.coverage_age_s` of ``B`` coverage grids at once.

    Parameters
    ----------
    cov : ndarray, (B, nc, nc) int32
        Coverage grids (the tick each coarse cell was last covered, -1: never).
    tick : ndarray, (B,) int
        Each world's tick.
    w, c, tps, block_px : int
        Map size, coarse cell side in px, ticks per second, block side in px.

    The same operations as the single belief's, each with a batch axis in front: the sums run
    over the same cells in the same order (down a (m, nb^2) table per world, or by bincount in
    raster order), so every world's ages are bit for bit its own belief's.
    """
    n, nc = cov.shape[0], cov.shape[1]
    nb, key, counts, empty, centre_cells, perm = _block_layout(w, c, nc, int(block_px))
    never = np.uint32(2**32 - 60 * tps)
    if n == 0:
        return np.zeros((0, nb, nb))
    t = np.asarray(tick).reshape(n, 1, 1)
    if perm is not None:
        if isinstance(perm, int):
            m = perm
            blocks = cov.view(np.uint32).reshape(n, nb, m, nb, m).transpose(0, 2, 4, 1, 3)
            ticks = np.empty((n, m, m, nb, nb), dtype=np.uint32)
            np.minimum(blocks, never, out=ticks)
        else:
            ticks = cov.reshape(n, -1).take(perm, axis=1).view(np.uint32)
            np.minimum(ticks, never, out=ticks)
        age = np.subtract(t.reshape((n,) + (1,) * (ticks.ndim - 1)), ticks.view(np.int32),
                          dtype=np.float64)  # fmt: skip
        age /= tps
        out = np.add.reduce(age.reshape(n, -1, nb * nb), axis=1)
        out /= int(counts[0])
        return out.reshape(n, nb, nb)
    ticks = np.minimum(cov.view(np.uint32), never).view(np.int32)
    age = np.subtract(t, ticks, dtype=np.float64)
    age /= tps
    flat = age.reshape(n, -1)
    keys = (np.arange(n)[:, None] * (nb * nb) + key[None, :]).ravel()
    sums = np.bincount(keys, weights=flat.ravel(), minlength=n * nb * nb).reshape(n, nb * nb)
    out = sums / counts
    if empty.size:
        out[:, empty] = flat[:, centre_cells]
    return out.reshape(n, nb, nb)
