"""Fast kernels of the route model's build, bit-identical to the readable rules they replace.

Building the model at 50-100 agents spent most of its time in two places (``python
bench/bench_milp_build.py``; figures in ``bench/README.md``):

* **Swept blocks** (:func:`discounted_coverage`): the readable rule,
  :func:`solvers.milp_model.sensing.discounted_share`, works on dense (segments x blocks) arrays,
  a dozen temporaries each, although a straight flight sweeps only the blocks along its track.
  The kernel first keeps the (segment, block) pairs whose block centre lies in the segment's
  bounding box grown by ``a + h + s`` (the swath's half extents along and across the track plus
  a block side: no block outside can overlap the swath, see below), then those whose block
  overlaps the swath in the segment's frame, and applies exactly the readable rule's arithmetic
  to those pairs only; every other entry is ``0.0``, which is what the rule gives there.
* **Dominated routes** (:func:`dominated`): the readable rule,
  :func:`solvers.milp_model.prune.dominated`, compares the routes of each group in a Python
  loop with a sparse row selection per group; the kernel compares every (earlier, later) pair of
  the same group in one pass over dense covers restricted to the blocks some route covers.

Why the box is safe: in the segment's frame a block of side ``s`` centred at ``(w, c)`` overlaps
the swath only if ``|c| < h + s / 2`` and ``-a - s / 2 < w < |PQ| + a + s / 2``; that rectangle's
corners lie within ``(a + s / 2) + (h + s / 2)`` of the segment's ends along each world axis.

Both kernels do per element the same IEEE operations in the same order as the readable rules,
so their results are equal bit for bit (``tests/solvers/test_milp_kernels.py``, hypothesis).

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

import numpy as np
import scipy.sparse as sp

from solvers.milp_model.prune import group_order
from solvers.milp_model.sensing import TAN_Y, detection_probability

__all__ = ["discounted_coverage", "dominated"]


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
    tracks only."""
    n_s, n_b = len(p), len(centres)
    out = np.zeros((n_s, n_b))
    if n_s == 0 or n_b == 0:
        return out
    d = q - p  # (S, 2)
    length = np.hypot(d[:, 0], d[:, 1])
    unit = d / np.maximum(length, 1e-9)[:, None]
    still = length <= 1e-9
    unit[still] = (1.0, 0.0)
    along_h = z * (np.abs(unit[:, 0]) + TAN_Y * np.abs(unit[:, 1]))  # (S,)
    across_h = z * (np.abs(unit[:, 1]) + TAN_Y * np.abs(unit[:, 0]))
    prob = np.asarray(detection_probability(z, lo, hi, speed, unit))
    prob = np.where(still, 0.0, prob)
    reach = along_h + across_h + block + 1.0  # the box's margin (+1 px against rounding)
    lo_xy = np.minimum(p, q) - reach[:, None]
    hi_xy = np.maximum(p, q) + reach[:, None]
    cx, cy = centres[:, 0], centres[:, 1]
    box = (
        (cx[None, :] >= lo_xy[:, 0, None])
        & (cx[None, :] <= hi_xy[:, 0, None])
        & (cy[None, :] >= lo_xy[:, 1, None])
        & (cy[None, :] <= hi_xy[:, 1, None])
    )
    si, bi = np.nonzero(box)
    # the readable rule's arithmetic, element by element, on the pairs in the box
    rel0 = cx[bi] - p[si, 0]
    rel1 = cy[bi] - p[si, 1]
    u0, u1 = unit[si, 0], unit[si, 1]
    w = rel0 * u0 + rel1 * u1
    c = rel1 * u0 - rel0 * u1
    half = 0.5 * block
    # then only where the block overlaps the swath (elsewhere cross or along is 0, and so is out)
    hh, ah, ln = across_h[si], along_h[si], length[si]
    hit = np.flatnonzero(
        (c + half > -hh) & (c - half < hh) & (w + half > -ah) & (w - half < ln + ah)
    )
    si, bi, w, c, hh, ah, ln = si[hit], bi[hit], w[hit], c[hit], hh[hit], ah[hit], ln[hit]
    cross = np.clip(np.minimum(c + half, hh) - np.maximum(c - half, -hh), 0.0, block)
    along = np.clip(np.minimum(w + half, ln + ah) - np.maximum(w - half, -ah), 0.0, block)
    share = (cross / block) * (along / block) * prob[si]
    when = np.clip(w, 0.0, ln) / max(speed, 1e-9)
    late = t_start[si] + when
    out[si, bi] = share * np.maximum(horizon - late, 0.0) / horizon
    return out


def dominated(keys: np.ndarray, value: np.ndarray, cover: sp.csr_array) -> np.ndarray:
    """(P,) bool: :func:`solvers.milp_model.prune.dominated` in one pass over every (earlier,
    later) pair of routes with the same ``keys`` row."""
    n = len(value)
    out = np.zeros(n, dtype=bool)
    if n < 2:
        return out
    order, starts = group_order(keys, value, cover)
    sizes = np.diff(np.r_[starts, n])
    # every (i, j) of one group with i before j in the order, as positions in ``order``
    pos_start = np.repeat(starts, sizes)  # (n,) start of each position's group
    rank = np.arange(n) - pos_start  # (n,) place within its group
    later = np.repeat(np.arange(n), rank)  # j, once per earlier member
    earlier = pos_start[later] + (np.arange(later.size) - np.repeat(np.cumsum(rank) - rank, rank))
    if later.size == 0:
        return out
    i, j = order[earlier], order[later]
    ok = value[i] >= value[j]
    used = np.unique(cover.indices)
    if used.size:
        dense = cover[:, used].toarray()
        pair = np.flatnonzero(ok)
        ok[pair] = np.all(dense[i[pair]] >= dense[j[pair]], axis=1)
    out[j[ok]] = True
    return out
