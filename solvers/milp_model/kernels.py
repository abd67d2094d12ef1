"""Fast kernels of the route model's build, bit-identical to the readable rules they replace.

Building the model at 50-100 agents spent most of its time in two places (``python
bench/bench_milp_build.py``; figures in ``bench/README.md``):

* **Swept blocks** (:func:`discounted_pairs`): the readable rule,
  :func:`solvers.milp_model.sensing.discounted_share`, works on dense (segments x blocks) arrays,
  a dozen temporaries each, although a straight flight sweeps only the blocks along its track.
  The kernel finds the (segment, block) pairs whose block centre lies in the segment's bounding
  box grown by ``a + h + s`` (the swath's half extents along and across the track plus a block
  side: no block outside can overlap the swath, see below) through a bucket grid of the block
  centres (:func:`box_pairs`: the buckets the box overlaps, then only the centres of each column
  near the swath), keeps those whose block overlaps the swath in the segment's frame, and
  applies exactly the readable rule's arithmetic to those pairs only; every other pair's value
  is ``0.0``, which is what the rule gives there. Each segment has its own altitude, altitude
  bounds and speed, and its own radius around a point (the agent's reach) beyond which no block
  is taken; the kernel returns the pairs (the build across agents,
  :mod:`solvers.milp_model.batch`). :func:`discounted_coverage` is the same kernel for one
  agent's segments, scattered into the rule's dense array.
* **Known cells near each block** (:func:`near_cells`): the readable rule,
  :func:`solvers.milp_model.objective.near_known_cells`, tests every (block, fire) pair of every
  snapshot of recent fire. The search blocks' centres lie on a grid, so the kernel finds along
  each axis the run of grid lines within reach of each fire (``searchsorted``, then the rule's
  own test at the run's ends), adds the fire's cells to that rectangle of a difference array
  per snapshot and sums it with two ``cumsum`` (sums of whole numbers, exact in any order).
  Centres off a grid take the pairs from :func:`box_pairs` instead and sum them with
  ``bincount``. In a whole ``scale``-tier episode of the MILP the rule and the bucketed pairs
  cost 15-35 ms per build (24 snapshots of 5,700 fires over 2,116 blocks at the median).
* **Dominated routes** (:func:`dominated`): the readable rule,
  :func:`solvers.milp_model.prune.dominated`, compares the routes of each group in a Python
  loop with a sparse row selection per group; the kernel compares every (earlier, later) pair of
  the same group in one pass over dense covers restricted to the blocks some route covers.

Why the box is safe: in the segment's frame a block of side ``s`` centred at ``(w, c)`` overlaps
the swath only if ``|c| < h + s / 2`` and ``-a - s / 2 < w < |PQ| + a + s / 2``; that rectangle's
corners lie within ``(a + s / 2) + (h + s / 2)`` of the segment's ends along each world axis.

The kernels do per element the same IEEE operations in the same order as the readable rules,
so their results are equal bit for bit (``tests/solvers/test_milp_kernels.py``, hypothesis).
:func:`dominated_sparse` is :func:`dominated` with the covers compared through a sparse
difference of each pair's rows, for route sets of many agents at once (no dense copy of every
route's covers).

Examples
--------
>>> import numpy as np
>>> p, q = np.array([[0.0, 0.0]]), np.array([[400.0, 0.0]])
>>> centres = np.array([[100.0, 0.0], [100.0, 900.0]])
>>> out = discounted_coverage(p, q, centres, 100.0, 100.0, 10.0, 100.0, 200.0,
...                           np.zeros(1), 60.0)
>>> bool(out[0, 0] > 0), float(out[0, 1])
(True, 0.0)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import scipy.sparse as sp

from solvers.milp_model.prune import group_order
from solvers.milp_model.sensing import TAN_Y, detection_probability

__all__ = [
    "box_pairs",
    "discounted_coverage",
    "discounted_pairs",
    "dominated",
    "dominated_sparse",
    "near_cells",
    "near_cells_each",
    "whole_counts",
]


def discounted_coverage(
    p: np.ndarray,
    q: np.ndarray,
    centres: np.ndarray,
    block: float,
    z: float,
    lo: float,
    hi: float,
    speed: float,
    t_start: np.ndarray,
    horizon: float,
) -> np.ndarray:
    """(S, B) ``share * (H - t)+ / H`` of ``centres`` under the segments ``p -> q`` started at
    ``t_start`` (S,): :func:`~solvers.milp_model.sensing.discounted_share`, computed along the
    tracks only: :func:`discounted_pairs` with the scalars given to every segment and no
    radius, scattered into a dense array."""
    n_s, n_b = len(p), len(centres)
    out = np.zeros((n_s, n_b))
    if n_s == 0 or n_b == 0:
        return out

    def each(v: float) -> np.ndarray:
        return np.full(n_s, v, dtype=np.float64)

    si, bi, val = discounted_pairs(
        np.asarray(p, np.float64), np.asarray(q, np.float64), each(z), each(lo), each(hi),
        each(speed), np.broadcast_to(np.asarray(t_start, np.float64), (n_s,)), centres, block,
        horizon, np.zeros((n_s, 2)), each(np.inf),
    )  # fmt: skip
    out[si, bi] = val
    return out


def _ordered_pairs(
    keys: np.ndarray, value: np.ndarray, cover: sp.csr_array
) -> tuple[np.ndarray, np.ndarray]:
    """Every (i, j) of routes with the same ``keys`` row, ``i`` before ``j`` in
    :func:`~solvers.milp_model.prune.group_order`'s order: the candidate dominations."""
    n = len(value)
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    order, starts = group_order(keys, value, cover)
    sizes = np.diff(np.r_[starts, n])
    # as positions in ``order``
    pos_start = np.repeat(starts, sizes)  # (n,) start of each position's group
    rank = np.arange(n) - pos_start  # (n,) place within its group
    later = np.repeat(np.arange(n), rank)  # j, once per earlier member
    earlier = pos_start[later] + (np.arange(later.size) - np.repeat(np.cumsum(rank) - rank, rank))
    return order[earlier], order[later]


def dominated(keys: np.ndarray, value: np.ndarray, cover: sp.csr_array) -> np.ndarray:
    """(P,) bool: :func:`solvers.milp_model.prune.dominated` in one pass over every (earlier,
    later) pair of routes with the same ``keys`` row."""
    out = np.zeros(len(value), dtype=bool)
    i, j = _ordered_pairs(keys, value, cover)
    if j.size == 0:
        return out
    ok = value[i] >= value[j]
    used = np.unique(cover.indices)
    if used.size:
        dense = cover[:, used].toarray()
        pair = np.flatnonzero(ok)
        ok[pair] = np.all(dense[i[pair]] >= dense[j[pair]], axis=1)
    out[j[ok]] = True
    return out


def box_pairs(
    lo_xy: np.ndarray,
    hi_xy: np.ndarray,
    centres: np.ndarray,
    cell: float,
    band: tuple[np.ndarray, ...] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate (box, centre) pairs: every centre inside the closed box ``lo_xy[s] ..
    hi_xy[s]`` (S, 2 each) and some near it. The centres are sorted into a grid of buckets of
    side ``cell`` (at least; wider when they are spread thin), numbered column by column, so the
    buckets of one column of a box hold one contiguous run of centres. With ``band = (p, unit,
    length, across, along)`` (each box's segment start, unit direction, length and the
    rectangle's half extents across the track and beyond its ends) only the centres of each
    column within a y-range that holds the rectangle over the column (+1 px) are taken: only
    centres outside the rectangle are left out. Returns ``(si, bi)``, ordered by box, then
    by column."""
    n_s, n_b = len(lo_xy), len(centres)
    if n_s == 0 or n_b == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    origin = centres.min(axis=0)
    extent = centres.max(axis=0) - origin
    cell = max(float(cell), float(np.sqrt(extent[0] * extent[1] / max(n_b, 1)) / 2.0), 1e-9)
    nx, ny = (int(v) for v in (np.floor(extent / cell).astype(np.int64) + 1).tolist())
    top = np.array([nx - 1, ny - 1])
    ix = np.minimum(np.floor((centres - origin) / cell).astype(np.int64), top)
    by_bucket = np.argsort(ix[:, 0] * ny + ix[:, 1], kind="stable")
    run = np.r_[0, np.cumsum(np.bincount(ix[:, 0] * ny + ix[:, 1], minlength=nx * ny))]
    # a millionth of a bucket of slack each side: a centre's bucket index is computed with the
    # same rounding, so no centre inside a box falls in a bucket outside its range
    b_lo = np.clip(np.floor((lo_xy - origin) / cell - 1e-6).astype(np.int64), 0, top)
    b_hi = np.clip(np.floor((hi_xy - origin) / cell + 1e-6).astype(np.int64), 0, top)
    cols = np.where((hi_xy < lo_xy).any(axis=1), 0, np.maximum(b_hi[:, 0] - b_lo[:, 0] + 1, 0))
    s_col = np.repeat(np.arange(n_s), cols)
    x = np.repeat(b_lo[:, 0] - (np.cumsum(cols) - cols), cols) + np.arange(s_col.size)
    y_lo, y_hi = b_lo[s_col, 1], b_hi[s_col, 1]
    if band is not None:
        y_min, y_max = _band_rows(band, s_col, origin[0] + x * cell - 1.0,
                                  origin[0] + (x + 1) * cell + 1.0)  # fmt: skip
        # (a strip that misses the rectangle has y_min = inf > y_max = -inf: no rows)
        row_lo = np.clip(np.floor((y_min - origin[1]) / cell - 1e-6), -1, ny)
        row_hi = np.clip(np.floor((y_max - origin[1]) / cell + 1e-6), -1, ny)
        y_lo = np.maximum(y_lo, row_lo.astype(np.int64))
        y_hi = np.minimum(y_hi, row_hi.astype(np.int64))
    start = run[x * ny + y_lo]
    k = np.maximum(run[x * ny + np.maximum(y_hi, y_lo - 1) + 1] - start, 0)
    si = np.repeat(s_col, k)
    bi = by_bucket[np.repeat(start - (np.cumsum(k) - k), k) + np.arange(si.size)]
    return si, bi


def _band_rows(
    band: tuple[np.ndarray, ...], seg: np.ndarray, x0: np.ndarray, x1: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A y-range that holds each segment's rectangle ``|c| <= across``,
    ``-along <= w <= length + along`` (its own frame) over the strip ``x0 <= x <= x1``: the
    rectangle is the meet of the band across the track and the band along it, so the
    intersection of the two bands' y-ranges over the strip holds it (an empty range,
    ``lo > hi``, when the strip misses it)."""
    p, unit, length, across, along = (a[seg] for a in band)
    u0, u1 = unit[:, 0], unit[:, 1]
    dx0, dx1 = x0 - p[:, 0], x1 - p[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        # across: c = (y - py) u0 - (x - px) u1, |c| <= across
        m = u1 / u0
        mid_lo, mid_hi = np.minimum(dx0 * m, dx1 * m), np.maximum(dx0 * m, dx1 * m)
        spread = across / np.abs(u0)
        lo = np.where(u0 != 0, mid_lo - spread, -np.inf)
        hi = np.where(u0 != 0, mid_hi + spread, np.inf)
        # along: w = (x - px) u0 + (y - py) u1, -along <= w <= length + along
        k = u0 / u1
        w_lo, w_hi = -along / u1, (length + along) / u1
        ends_lo, ends_hi = np.minimum(w_lo, w_hi), np.maximum(w_lo, w_hi)
        lo2 = ends_lo - np.maximum(dx0 * k, dx1 * k)
        hi2 = ends_hi - np.minimum(dx0 * k, dx1 * k)
    lo = np.maximum(lo, np.where(u1 != 0, lo2, -np.inf)) + p[:, 1] - 1.0
    hi = np.minimum(hi, np.where(u1 != 0, hi2, np.inf)) + p[:, 1] + 1.0
    return lo, hi


def discounted_pairs(
    p: np.ndarray,
    q: np.ndarray,
    z: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    speed: np.ndarray,
    t_start: np.ndarray,
    centres: np.ndarray,
    block: float,
    horizon: float,
    origin: np.ndarray,
    radius: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`discounted_coverage` for segments with their own altitude ``z``, altitude bounds
    ``lo`` / ``hi`` and ``speed`` (all (S,)), over the blocks within ``radius`` (S,) of
    ``origin`` (S, 2) only (``hypot(centre - origin) <= radius``, as
    :meth:`solvers.milp_model.context.BuildContext.near_blocks` tests it).

    Returns ``(si, bi, value)``: the pairs of a segment and a block that overlaps its swath, and
    the value :func:`~solvers.milp_model.sensing.discounted_share` gives them, bit for bit
    (every other pair's value is ``0.0``).
    """
    d = q - p
    length = np.hypot(d[:, 0], d[:, 1])
    unit = d / np.maximum(length, 1e-9)[:, None]
    still = length <= 1e-9
    unit[still] = (1.0, 0.0)
    along_h = z * (np.abs(unit[:, 0]) + TAN_Y * np.abs(unit[:, 1]))
    across_h = z * (np.abs(unit[:, 1]) + TAN_Y * np.abs(unit[:, 0]))
    prob = np.where(still, 0.0, detection_probability(z, lo, hi, speed, unit))
    reach = along_h + across_h + block + 1.0
    # the segment's box, cut to the square around ``origin`` that holds its radius (+1 px)
    lo_xy = np.maximum(np.minimum(p, q) - reach[:, None], origin - (radius + 1.0)[:, None])
    hi_xy = np.minimum(np.maximum(p, q) + reach[:, None], origin + (radius + 1.0)[:, None])
    half = 0.5 * block
    band = (p, unit, length, across_h + half + 1.0, along_h + half + 1.0)
    si, bi = box_pairs(lo_xy, hi_xy, centres, block, band)
    cx, cy = centres[bi, 0], centres[bi, 1]
    rel0 = cx - p[si, 0]
    rel1 = cy - p[si, 1]
    u0, u1 = unit[si, 0], unit[si, 1]
    w = rel0 * u0 + rel1 * u1
    c = rel1 * u0 - rel0 * u1
    hh, ah, ln = across_h[si], along_h[si], length[si]
    hit = np.flatnonzero(
        (c + half > -hh) & (c - half < hh) & (w + half > -ah) & (w - half < ln + ah)
    )
    si, bi, w, c, hh, ah, ln = si[hit], bi[hit], w[hit], c[hit], hh[hit], ah[hit], ln[hit]
    cx, cy = cx[hit], cy[hit]
    near = np.flatnonzero(np.hypot(cx - origin[si, 0], cy - origin[si, 1]) <= radius[si])
    si, bi, w, c, hh, ah, ln = si[near], bi[near], w[near], c[near], hh[near], ah[near], ln[near]
    cross = np.clip(np.minimum(c + half, hh) - np.maximum(c - half, -hh), 0.0, block)
    along = np.clip(np.minimum(w + half, ln + ah) - np.maximum(w - half, -ah), 0.0, block)
    share = (cross / block) * (along / block) * prob[si]
    when = np.clip(w, 0.0, ln) / np.maximum(speed[si], 1e-9)
    late = t_start[si] + when
    return si, bi, share * np.maximum(horizon - late, 0.0) / horizon


def dominated_sparse(keys: np.ndarray, value: np.ndarray, cover: sp.csr_array) -> np.ndarray:
    """(P,) bool: :func:`dominated`, each candidate pair's covers compared through the sparse
    difference of their rows (a later route is kept when it sees some block more)."""
    out = np.zeros(len(value), dtype=bool)
    i, j = _ordered_pairs(keys, value, cover)
    if j.size == 0:
        return out
    ok = value[i] >= value[j]
    pair = np.flatnonzero(ok)
    if pair.size and cover.nnz:
        diff = sp.csr_array(cover[j[pair]] - cover[i[pair]])
        rows = np.repeat(np.arange(pair.size), np.diff(diff.indptr))
        ok[pair[np.unique(rows[diff.data > 0])]] = False
    out[j[ok]] = True
    return out


def near_cells(
    centres: np.ndarray, snapshots: Sequence[tuple[np.ndarray, np.ndarray]], reach: float
) -> np.ndarray:
    """:func:`solvers.milp_model.objective.near_known_cells` for cell counts that are whole
    numbers (their sums are then exact in any order): the most over the snapshots of
    :func:`near_cells_each`, at least 0.

    Raises
    ------
    ValueError
        If a cell count is not a whole number, or the counts are too large to sum exactly.
    """
    per = near_cells_each(centres, snapshots, reach)
    if per.shape[0] == 0:
        return np.zeros(len(centres))
    out: np.ndarray = np.maximum(per.max(axis=0), 0.0)
    return out


def near_cells_each(
    centres: np.ndarray, snapshots: Sequence[tuple[np.ndarray, np.ndarray]], reach: float
) -> np.ndarray:
    """(S, B) per snapshot ``(positions (F, 2), cells (F,))``, the known cells within ``reach``
    (px, along each axis) of each of ``centres`` (B, 2), for whole cell counts.

    When the block centres lie on a grid (their distinct x and y values span at most a few
    times as many grid points as there are centres, as the task graph's search blocks do), each
    fire adds its cells to a rectangle of grid points through a difference array summed with
    two ``cumsum``; otherwise the (fire, block) pairs come from :func:`box_pairs`.

    Raises
    ------
    ValueError
        If a cell count is not a whole number, or the counts are too large to sum exactly.
    """
    n_b = len(centres)
    out = np.zeros((len(snapshots), n_b))
    rows = [i for i, (_, cells) in enumerate(snapshots) if len(cells)]
    snaps = [(np.asarray(snapshots[i][0], np.float64).reshape(-1, 2),
              np.asarray(snapshots[i][1], np.float64)) for i in rows]  # fmt: skip
    if not whole_counts(snaps):
        raise ValueError("near_cells sums whole cell counts only; use near_known_cells")
    if not snaps or n_b == 0:
        return out
    pos = np.concatenate([q[0] for q in snaps])
    cells = np.concatenate([q[1] for q in snaps])
    snap = np.repeat(np.arange(len(snaps)), [len(q[1]) for q in snaps])
    centres = np.asarray(centres, np.float64)
    xs, ix = np.unique(centres[:, 0], return_inverse=True)
    ys, iy = np.unique(centres[:, 1], return_inverse=True)
    if (xs.size + 1) * (ys.size + 1) <= 4 * n_b + 64:
        per = _grid_sums(xs, ys, pos, cells, snap, len(snaps), reach)[:, iy.ravel(), ix.ravel()]
    else:
        si, bi = box_pairs(pos - reach, pos + reach, centres, reach)
        ok = (np.abs(centres[bi, 0] - pos[si, 0]) <= reach) & (
            np.abs(centres[bi, 1] - pos[si, 1]) <= reach
        )
        si, bi = si[ok], bi[ok]
        flat = np.bincount(snap[si] * n_b + bi, weights=cells[si], minlength=len(snaps) * n_b)
        per = flat.reshape(len(snaps), n_b)
    out[rows] = per
    return out


def _axis_range(grid: np.ndarray, f: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``f``, the indices ``lo <= k < hi`` of the sorted distinct ``grid`` values
    with ``|grid[k] - f| <= reach``, computed as the rule computes it. ``grid[k] - f`` rounds
    monotonically in ``grid[k]``, so they are one run; ``searchsorted`` guesses its ends and
    the exact test moves each guess to the end of the run."""
    n = grid.size

    def settle(k: np.ndarray, inside: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        # the first k whose value passes ``inside`` (a test that is False, then True, along k)
        while True:
            down = (k > 0) & inside(np.maximum(k - 1, 0))
            if not down.any():
                break
            k = k - down
        while True:
            up = (k < n) & ~inside(np.minimum(k, n - 1))
            if not up.any():
                return k
            k = k + up

    lo = settle(np.searchsorted(grid, f - reach), lambda k: grid[k] - f >= -reach)
    hi = settle(np.searchsorted(grid, f + reach, side="right"), lambda k: grid[k] - f > reach)
    return lo, hi


def _grid_sums(
    xs: np.ndarray,
    ys: np.ndarray,
    pos: np.ndarray,
    cells: np.ndarray,
    snap: np.ndarray,
    n_snap: int,
    reach: float,
) -> np.ndarray:
    """(S, Y, X) per snapshot, the cells of the fires within ``reach`` of each grid point (each
    axis apart), through a difference array: every partial sum is a whole number no larger
    than the snapshot's total, so the result is exact."""
    x_lo, x_hi = _axis_range(xs, pos[:, 0], reach)
    y_lo, y_hi = _axis_range(ys, pos[:, 1], reach)
    hit = (x_lo < x_hi) & (y_lo < y_hi)
    nx, ny = xs.size + 1, ys.size + 1
    base = snap[hit] * (nx * ny)
    xl, xh, yl, yh, w = x_lo[hit], x_hi[hit], y_lo[hit] * nx, y_hi[hit] * nx, cells[hit]
    corners = np.concatenate([base + yl + xl, base + yl + xh, base + yh + xl, base + yh + xh])
    weights = np.concatenate([w, -w, -w, w])
    diff = np.bincount(corners, weights=weights, minlength=n_snap * nx * ny)
    sums = diff.reshape(n_snap, ny, nx).cumsum(axis=2).cumsum(axis=1)
    out: np.ndarray = sums[:, :-1, :-1]
    return out


def whole_counts(snapshots: Sequence[tuple[np.ndarray, np.ndarray]]) -> bool:
    """True when every snapshot's cell counts are whole numbers whose sum is exact in float64
    (:func:`near_cells`); one pass over all the snapshots' cells."""
    cells = [np.asarray(c, np.float64).ravel() for _, c in snapshots]
    if not cells:
        return True
    flat = np.concatenate(cells)
    if not np.all(flat == np.round(flat)):
        return False
    per = np.bincount(np.repeat(np.arange(len(cells)), [c.size for c in cells]),
                      weights=np.abs(flat), minlength=len(cells))  # fmt: skip
    return bool(np.all(per < 2.0**52))
