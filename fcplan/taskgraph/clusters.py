"""Connected fires: labelling the occupied fire tiles by 8-connectivity.

Fire tasks are tiles of known burning cells; tiles that touch (sides or corners) belong to one
connected fire, :attr:`fcplan.taskgraph.TaskGraph.task_cluster`. Labels are numbered as
:func:`scipy.ndimage.label` numbers them: by the first tile of each component in raster order
(``tx`` major, then ``ty``), from 0.

Few tiles are labelled without building a grid: up to ``_CLOSURE_CLUSTER`` tiles by the
transitive closure of their adjacency matrix (boolean matrix squaring), up to
``_SMALL_CLUSTER`` by min-label propagation with pointer jumping, more by
:func:`scipy.ndimage.label` on the tile grid. :class:`TileClusters` keeps the last few answers
(a fire often keeps its tiles for several replans).

Examples
--------
>>> import numpy as np
>>> tx, ty = np.array([0, 0, 1, 5]), np.array([0, 1, 2, 5])  # raster order
>>> label_tiles(tx, ty, 8, 8).tolist()
[0, 0, 0, 1]
"""

from __future__ import annotations

import numpy as np

__all__ = ["EIGHT_CONNECTED", "TileClusters", "label_tiles"]

#: 8-connectivity structure for :func:`scipy.ndimage.label`
EIGHT_CONNECTED = np.ones((3, 3), dtype=bool)
EIGHT_CONNECTED.flags.writeable = False

_CLOSURE_CLUSTER = 24  # up to this many tiles, label by closure (few, cheap matrix products)
_SMALL_CLUSTER = 256  # up to this many tiles, label by pairwise adjacency (no scipy call)


def label_tiles(tx: np.ndarray, ty: np.ndarray, nx_: int, ny_: int) -> np.ndarray:
    """(n,) int64 connected-fire labels of occupied tiles ``(tx, ty)`` (sorted in raster order,
    within an ``nx_ x ny_`` grid), numbered like :func:`scipy.ndimage.label` from 0."""
    n = len(tx)
    if n == 1:
        return np.zeros(1, dtype=np.int64)
    if n > _SMALL_CLUSTER:
        from scipy.ndimage import label

        grid = np.zeros((nx_ + 1, ny_ + 1), dtype=bool)
        grid[tx, ty] = True
        labels, _ = label(grid, structure=EIGHT_CONNECTED)
        out: np.ndarray = labels[tx, ty].astype(np.int64) - 1
        return out
    adj = np.abs(tx[:, None] - tx) <= 1
    adj &= np.abs(ty[:, None] - ty) <= 1
    idx = np.arange(n)
    if n <= _CLOSURE_CLUSTER:
        # transitive closure by boolean matrix squaring (reflexive: it only grows); the first
        # tile reached from a tile is the first tile of its component
        m, count = adj, np.count_nonzero(adj)
        while True:
            m = m @ m
            c = np.count_nonzero(m)
            if c == count:
                break
            count = c
        lab = m.argmax(axis=1)
    else:
        # min-label propagation with pointer jumping: each tile ends up pointing at the first
        # (lowest-index) tile of its component
        lab = np.where(adj, idx, n).min(axis=1)
        while True:
            nxt = np.where(adj, lab, n).min(axis=1)
            nxt = nxt[nxt]
            if np.array_equal(nxt, lab):
                break
            lab = nxt
    # components are numbered in the order of their first tiles
    labelled: np.ndarray = (np.cumsum(lab == idx) - 1)[lab]
    return labelled


class TileClusters:
    """:func:`label_tiles` with the last ``size`` answers kept (read-only) for tiles asked again.

    Parameters
    ----------
    size : int
        Answers kept (the oldest is dropped first).

    Examples
    --------
    >>> import numpy as np
    >>> clusters = TileClusters()
    >>> tx, ty = np.array([0, 3]), np.array([0, 3])
    >>> clusters(tx, ty, 4, 4).tolist(), clusters(tx.copy(), ty.copy(), 4, 4).tolist()
    ([0, 1], [0, 1])
    """

    def __init__(self, size: int = 8) -> None:
        self.size = int(size)
        #: tiles (dtypes, then x and y coordinates as bytes; equal lengths) -> labels
        self._memo: dict[tuple[str, str, bytes], np.ndarray] = {}

    def __call__(self, tx: np.ndarray, ty: np.ndarray, nx_: int, ny_: int) -> np.ndarray:
        """Labels of the tiles (see :func:`label_tiles`); treat the answer as read-only."""
        if len(tx) == 1:
            return np.zeros(1, dtype=np.int64)
        key = (tx.dtype.str, ty.dtype.str, tx.tobytes() + ty.tobytes())
        hit = self._memo.get(key)
        if hit is not None:
            return hit
        out = label_tiles(tx, ty, nx_, ny_)
        if len(self._memo) >= self.size:
            self._memo.pop(next(iter(self._memo)))
        out.flags.writeable = False
        self._memo[key] = out
        return out
