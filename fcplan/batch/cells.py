"""The cell grids of a batch: one byte per cell and world, stored by 16 x 16 blocks.

Layout. A world's ``W x W`` cells (``[x, y]``, flat index ``x W + y`` as in :mod:`fcplan.fire`)
are stored as ``nb x nb`` blocks of ``BLOCK x BLOCK`` cells (``nb = ceil(W / BLOCK)``), each block
256 contiguous bytes: :attr:`CellGrid.state` is ``(B, nb * nb, 256)`` uint8 and cell ``(x, y)``
of world ``b`` is ``state[b, (x >> 4) nb + (y >> 4), (x & 15) 16 + (y & 15)]``. One byte holds the
fire state in its two low bits (:data:`fcplan.fire.UNBURNT`, ``BURNING``, ``PRUNED``) and
whether the cell was ever sensed in bit 2 (:data:`SENSED`), so "burning and sensed" is the byte
value 5. :attr:`CellGrid.blocks` counts the burning cells of every block, ``(B, nb * nb)`` int32,
and :attr:`CellGrid.supers` those of every super-block of 4 x 4 blocks (64 px), ``(B, ns * ns)``.

Why blocks: sensing and pruning look for burning cells inside fields of view that are mostly
empty (on scenario #24 a field of view overlaps the fire's box by thousands of cells and holds a
handful of burning ones). :func:`scan_boxes` enumerates, for every (world, box) pair at once, the
super-blocks of the box, then only the blocks of super-blocks with fire that hold a burning cell,
and gathers each as one contiguous 256-byte row.

Examples
--------
>>> import numpy as np
>>> grid = CellGrid(num=2, world_size=40)
>>> g = grid.index(np.array([1]), np.array([17]), np.array([5]))
>>> grid.flat_state[g] = 1
>>> grid.count(np.array([1]), np.array([17]), np.array([5]), +1)  # its block holds fire now
>>> pair, x, y = scan_boxes(grid, np.array([1]), np.array([0]), np.array([39]), np.array([0]),
...                         np.array([39]), lambda v: v == 1)
>>> pair.tolist(), x.tolist(), y.tolist()
([0], [17], [5])
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fcplan.shared_views import KeepsViews

__all__ = ["CellGrid", "scan_boxes", "runs", "SENSED", "BLOCK", "STATE_BITS"]

#: side of a block (px); equal to :data:`fcplan.fire.BLOCK`
BLOCK = 16
_SHIFT = 4
_LOW = BLOCK - 1
#: side of a super-block, in blocks
SUPER = 4
_SUPER_SHIFT = 6  # (16 px blocks x 4)
_SUB = (np.repeat(np.arange(SUPER), SUPER), np.tile(np.arange(SUPER), SUPER))
#: bit of a cell's byte: the cell was sensed at least once
SENSED = 4
#: the bits of a cell's byte holding its fire state
STATE_BITS = 3
_LX = np.arange(BLOCK, dtype=np.int64)
_ONE = np.int32(1)


class CellGrid(KeepsViews):
    """Fire state and sensing of every cell of ``num`` worlds (module docstring: the layout).

    Parameters
    ----------
    num : int
        Worlds ``B``.
    world_size : int
        Map side ``W`` in px.

    Attributes
    ----------
    state : ndarray, (B, nb * nb, 256) uint8
    blocks : ndarray, (B, nb * nb) int32
        Burning cells per block.
    used : ndarray, (B, 4) int64
        Per world ``[bx0, bx1, by0, by1]``: the blocks touched since its reset (what a reset
        clears).
    """

    def __init__(self, num: int, world_size: int) -> None:
        self.num, self.world_size = int(num), int(world_size)
        self.nb = nb = -(-self.world_size // BLOCK)
        self.per_world = nb * nb * BLOCK * BLOCK
        self.state = np.zeros((self.num, nb * nb, BLOCK * BLOCK), dtype=np.uint8)
        # written once now: the memory is mapped here rather than page by page by the first
        # fires, inside the first steps (paged in lazily, an episode of #1 writes about a tenth
        # of the pages, but the motion level ran 2-4 % slower: bench/README.md)
        self.state.fill(0)
        self.flat_state = self.state.reshape(-1)
        self.blocks = np.zeros((self.num, nb * nb), dtype=np.int32)
        self.flat_blocks = self.blocks.reshape(-1)
        self.ns = ns = -(-nb // SUPER)
        self.supers = np.zeros((self.num, ns * ns), dtype=np.int32)
        self.flat_supers = self.supers.reshape(-1)
        self.used = np.tile(np.array([nb, -1, nb, -1], dtype=np.int64), (self.num, 1))

    def index(self, world: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Indices into :attr:`flat_state` of cells ``(x, y)`` of worlds ``world``."""
        blk = (x >> _SHIFT) * self.nb + (y >> _SHIFT)
        return (
            (world * (self.nb * self.nb) + blk) * (BLOCK * BLOCK) + ((x & _LOW) << 4) + (y & _LOW)
        )

    def block_index(self, world: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Indices into :attr:`flat_blocks` of the blocks of cells ``(x, y)`` of ``world``."""
        return world * (self.nb * self.nb) + (x >> _SHIFT) * self.nb + (y >> _SHIFT)

    def count(self, world: np.ndarray, x: np.ndarray, y: np.ndarray, sign: int) -> None:
        """Add ``sign`` per cell ``(x, y)`` of ``world`` to the burning counts of its block and
        super-block (cells that started or stopped burning)."""
        ufunc = np.add if sign > 0 else np.subtract
        # (the one as an int32 scalar: a Python int sends ufunc.at down a path 20x slower)
        ufunc.at(self.flat_blocks, self.block_index(world, x, y), _ONE)
        ns = self.ns
        ufunc.at(
            self.flat_supers,
            world * (ns * ns) + (x >> _SUPER_SHIFT) * ns + (y >> _SUPER_SHIFT),
            _ONE,
        )

    def touch(self, worlds: np.ndarray, lo: tuple, hi: tuple) -> None:
        """Note that cells of ``worlds`` (distinct) within ``[lo[0], hi[0]] x [lo[1], hi[1]]``
        were written (see :attr:`used`)."""
        used = self.used
        used[worlds, 0] = np.minimum(used[worlds, 0], lo[0] >> _SHIFT)
        used[worlds, 1] = np.maximum(used[worlds, 1], hi[0] >> _SHIFT)
        used[worlds, 2] = np.minimum(used[worlds, 2], lo[1] >> _SHIFT)
        used[worlds, 3] = np.maximum(used[worlds, 3], hi[1] >> _SHIFT)

    def clear(self, b: int) -> None:
        """Zero world ``b``'s cells and block counts (only the blocks it touched)."""
        bx0, bx1, by0, by1 = self.used[b].tolist()
        if bx1 >= bx0:
            nb = self.nb
            self.state[b].reshape(nb, nb, -1)[bx0 : bx1 + 1, by0 : by1 + 1] = 0
            self.blocks[b].reshape(nb, nb)[bx0 : bx1 + 1, by0 : by1 + 1] = 0
            ns, k = self.ns, _SUPER_SHIFT - _SHIFT
            self.supers[b].reshape(ns, ns)[bx0 >> k : (bx1 >> k) + 1, by0 >> k : (by1 >> k) + 1] = 0
        self.used[b] = (self.nb, -1, self.nb, -1)

    def world_array(self, b: int) -> np.ndarray:
        """(W, W) uint8 bytes of world ``b`` in the ``[x, y]`` layout (a fresh array)."""
        nb, w = self.nb, self.world_size
        a = self.state[b].reshape(nb, nb, BLOCK, BLOCK).transpose(0, 2, 1, 3)
        return a.reshape(nb * BLOCK, nb * BLOCK)[:w, :w].copy()


def scan_boxes(
    grid: CellGrid,
    world: np.ndarray,
    x0: np.ndarray,
    x1: np.ndarray,
    y0: np.ndarray,
    y1: np.ndarray,
    test: Callable[[np.ndarray], np.ndarray],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells passing ``test`` inside each box, box by box in ``[x, y]`` row-major order.

    Parameters
    ----------
    grid : CellGrid
    world : ndarray, (P,) int64
        World of each box.
    x0, x1, y0, y1 : ndarray, (P,) int64
        Inclusive cell ranges inside the map (non-empty).
    test : callable
        uint8 cell bytes -> bool; only cells of blocks holding a burning cell are tested.

    Returns
    -------
    pair, x, y : ndarray, (K,) int64
        Box index and cell of each hit, sorted by box, then ``x``, then ``y`` (the order in
        which :class:`fcplan.World` scans a field of view).
    """
    nb, w = grid.nb, grid.world_size
    rep, bx, by = _blocks_with_fire(grid, world, x0, x1, y0, y1)
    if rep.size == 0:
        return _EMPTY, _EMPTY, _EMPTY
    blk = world[rep] * (nb * nb) + bx * nb + by
    hit = test(grid.state.reshape(-1, BLOCK * BLOCK)[blk]).reshape(-1, BLOCK, BLOCK)
    cx = (bx << _SHIFT)[:, None] + _LX  # (K, 16) cell x of each block row
    cy = (by << _SHIFT)[:, None] + _LX
    # (only the blocks that stick out of their box need the box's bounds)
    edge = np.flatnonzero(
        (cx[:, 0] < x0[rep]) | (cx[:, -1] > x1[rep]) | (cy[:, 0] < y0[rep]) | (cy[:, -1] > y1[rep])
    )
    if edge.size:
        re = rep[edge]
        in_x = (cx[edge] >= x0[re, None]) & (cx[edge] <= x1[re, None])
        in_y = (cy[edge] >= y0[re, None]) & (cy[edge] <= y1[re, None])
        hit[edge] &= in_x[:, :, None] & in_y[:, None, :]
    at = np.flatnonzero(hit)
    if at.size == 0:
        return _EMPTY, _EMPTY, _EMPTY
    k = at >> (2 * _SHIFT)
    # one sortable key per hit: box, then x, then y, in bit fields
    shift = int(w - 1).bit_length()
    key = (rep[k] << (2 * shift)) | ((cx[k, 0] + ((at >> _SHIFT) & _LOW)) << shift)
    key |= cy[k, 0] + (at & _LOW)
    key.sort()
    mask = (1 << shift) - 1
    return key >> (2 * shift), (key >> shift) & mask, key & mask


def _blocks_with_fire(grid: CellGrid, world: np.ndarray, x0: np.ndarray, x1: np.ndarray,
                      y0: np.ndarray, y1: np.ndarray) -> tuple:  # fmt: skip
    """``(box, bx, by)`` of every block holding a burning cell inside each box: the super-blocks
    of the box first (4 x 4 blocks each, as one padded grid per box), then the blocks of the
    super-blocks with fire."""
    ns, nb = grid.ns, grid.nb
    if world.size == 0:
        return _EMPTY, _EMPTY, _EMPTY
    bx0, bx1, by0, by1 = x0 >> _SHIFT, x1 >> _SHIFT, y0 >> _SHIFT, y1 >> _SHIFT
    k = _SUPER_SHIFT - _SHIFT
    sx0, sy0 = bx0 >> k, by0 >> k
    nx, ny = (bx1 >> k) - sx0 + 1, (by1 >> k) - sy0 + 1
    kx, ky = int(nx.max()), int(ny.max())
    ax, ay = np.arange(kx), np.arange(ky)
    sx = np.minimum(sx0[:, None] + ax, ns - 1)  # (P, kx); clipped: masked out below
    sy = np.minimum(sy0[:, None] + ay, ns - 1)
    cell = ((world * ns)[:, None] + sx) * ns  # (P, kx)
    hot = grid.flat_supers[cell[:, :, None] + sy[:, None, :]] > 0
    hot &= (ax < nx[:, None])[:, :, None] & (ay < ny[:, None])[:, None, :]
    at = np.flatnonzero(hot)
    rep = at // (kx * ky)
    sx = sx0[rep] + (at // ky) % kx
    sy = sy0[rep] + at % ky
    bx = ((sx << k)[:, None] + _SUB[0]).reshape(-1)
    by = ((sy << k)[:, None] + _SUB[1]).reshape(-1)
    rep = np.repeat(rep, SUPER * SUPER)
    inside = (bx >= bx0[rep]) & (bx <= bx1[rep]) & (by >= by0[rep]) & (by <= by1[rep])
    rep, bx, by = rep[inside], bx[inside], by[inside]
    full = np.flatnonzero(grid.flat_blocks[world[rep] * (nb * nb) + bx * nb + by])
    return rep[full], bx[full], by[full]


def runs(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and lengths of the runs of equal values of a sorted 1-D array (its distinct
    values are ``a[starts]``: ``np.unique(a, return_counts=True)`` of sorted input, cheaper).

    Examples
    --------
    >>> starts, counts = runs(np.array([2, 2, 5, 7, 7, 7]))
    >>> starts.tolist(), counts.tolist()
    ([0, 2, 3], [2, 1, 3])
    """
    if a.size == 0:
        return _EMPTY, _EMPTY
    starts = np.flatnonzero(np.concatenate(([True], a[1:] != a[:-1])))
    return starts, np.diff(np.append(starts, a.size))


_EMPTY = np.zeros(0, dtype=np.int64)
