"""Exact pruning of dominated routes: fewer variables, the same optimum.

Two routes of one agent and one kind that use the same rows apart from the cover rows (the same
fire tasks in any order for dumps and watches, so the same ``dump_once``, ``watch_once`` and
freeze rows; the same first block for searches, so the same ``search_once`` row) differ only in
their own value ``D_r`` and their covers ``s_rb``. If route ``r`` has ``D_r >= D_r'`` and
``s_rb >= s_r'b`` for every block, swapping ``r'`` for ``r`` in any feasible solution keeps it
feasible (the cover rows only get looser) and does not lower the objective (every cover and
freeze coefficient is non-negative), so ``r'`` can be left out without changing the optimum.
For an agent without a camera the covers are all zero and only the best order of each task set
is kept (of the ``n!`` orders of ``n`` dumps).

Among routes that dominate each other (equal values and covers) the first in enumeration order
is kept. Dominance is transitive, so a route is dropped exactly when an earlier route in the
order (value, then total cover, both descending; then enumeration order) dominates it.

Examples
--------
>>> import numpy as np
>>> import scipy.sparse as sp
>>> keys = np.array([[0, 1], [0, 1], [0, 2]])            # routes 0 and 1: the same task set
>>> value = np.array([3.0, 5.0, 1.0])
>>> cover = sp.csr_array(np.zeros((3, 4), dtype=np.int64))
>>> dominated(keys, value, cover).tolist()
[True, False, False]
>>> cover = sp.csr_array(np.array([[2, 0, 0, 0], [1, 0, 0, 0], [0, 0, 0, 0]]))
>>> dominated(keys, value, cover).tolist()              # route 0 sees more of block 0
[False, False, False]
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["dominated", "group_order", "route_keys"]


def route_keys(tasks: np.ndarray, by_first: bool) -> np.ndarray:
    """(P, L) the row signature of each route apart from covers: its task rows sorted (a dump or
    watch: the same ``dump_once`` / ``watch_once`` / freeze rows in any order), or only its first
    task (a search: the ``search_once`` row), padded with -1."""
    if by_first:
        out = np.full_like(tasks, -1)
        out[:, 0] = tasks[:, 0]
        return out
    big = np.iinfo(np.int64).max
    srt = np.sort(np.where(tasks >= 0, tasks, big), axis=1)
    return np.where(srt == big, -1, srt)


def group_order(
    keys: np.ndarray, value: np.ndarray, cover: sp.csr_array
) -> tuple[np.ndarray, np.ndarray]:
    """The routes ordered by ``keys`` group, then value and total cover (both descending), then
    enumeration order, and where each group starts in that order: ``(order (P,), starts (G,))``."""
    n = len(value)
    total = np.asarray(cover.sum(axis=1)).ravel().astype(np.float64)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = group.ravel()
    order = np.lexsort((np.arange(n), -total, -value, group))  # by group, best first
    g_sorted = group[order]
    starts = np.flatnonzero(np.r_[True, g_sorted[1:] != g_sorted[:-1]])
    return order, starts


def dominated(keys: np.ndarray, value: np.ndarray, cover: sp.csr_array) -> np.ndarray:
    """(P,) bool: the routes some other route with the same ``keys`` row dominates (module
    docstring); ``value`` (P,) their own objective coefficients, ``cover`` (P, B) their covers."""
    n = len(value)
    out = np.zeros(n, dtype=bool)
    if n < 2:
        return out
    order, starts = group_order(keys, value, cover)
    ends = np.r_[starts[1:], n]
    has_cover = np.diff(cover.indptr) > 0
    for s, e in zip(starts.tolist(), ends.tolist(), strict=True):
        if e - s < 2:
            continue
        members = order[s:e]
        if not has_cover[members].any():
            out[members[1:]] = True  # no covers: the best value dominates the rest
            continue
        sub = cover[members].toarray()
        v = value[members]
        # dom[i, j]: member i (earlier in the order) dominates member j
        ge = np.all(sub[:, None, :] >= sub[None, :, :], axis=2) & (v[:, None] >= v[None, :])
        earlier = np.triu(np.ones((e - s, e - s), dtype=bool), k=1)
        out[members] = np.any(ge & earlier, axis=0)
    return out
