"""Exact optimum of tiny models by enumeration: the tests' ground truth."""

from __future__ import annotations

import itertools

import numpy as np

from solvers.milp_model.types import AUX, MilpModel

__all__ = ["brute_force_optimum"]


def brute_force_optimum(
    model: MilpModel, max_combinations: int = 2_000_000, chunk: int = 65_536
) -> tuple[np.ndarray, float]:
    """Exact optimum of a tiny model by enumeration (ground truth for tests).

    Every agent picks, in each slot, one of its variables of that slot or nothing; all such
    combinations are enumerated (vectorised, in chunks) and checked against every row. The
    auxiliary ``z`` variables have positive objective coefficients and appear only with
    coefficient +1 in rows of their own (at most one ``z`` per row), so for fixed primary
    variables the best ``z`` is 1 exactly when each of its rows has slack >= 1: it is set that way.

    Parameters
    ----------
    model : MilpModel
    max_combinations : int
        Refuse (``ValueError``) models with more combinations than this.
    chunk : int
        Combinations checked per numpy batch.

    Returns
    -------
    x : ndarray, (n,) float64
        An optimal solution (the first in enumeration order among ties).
    objective : float
    """
    n = model.n_vars
    aux = model.var_kind == AUX
    prim = np.flatnonzero(~aux)
    auxi = np.flatnonzero(aux)
    if np.any(model.c[auxi] < 0):
        raise ValueError("auxiliary variables must have non-negative objective coefficients")
    mat = model.A_ub.tocsc()
    a_p = mat[:, prim].toarray()
    a_z = mat[:, auxi].toarray()
    if np.any((a_z != 0) & (a_z != 1)) or np.any((a_z != 0).sum(axis=1) > 1):
        raise ValueError("auxiliary variables must appear with +1, at most one per row")
    groups = [
        np.flatnonzero((model.var_agent[prim] == a) & (model.var_slot[prim] == s))
        for a, s in sorted(
            set(zip(model.var_agent[prim].tolist(), model.var_slot[prim].tolist(), strict=True))
        )
    ]
    total = int(np.prod([g.size + 1 for g in groups], dtype=np.float64)) if groups else 1
    if total > max_combinations:
        raise ValueError(f"{total} combinations exceed max_combinations={max_combinations}")
    choice_lists = [np.r_[-1, g] for g in groups]  # -1: nothing in that slot
    c_p, c_z = model.c[prim], model.c[auxi]
    best_val, best_x = -np.inf, None
    combos = itertools.product(*choice_lists)
    while True:
        block = np.array(list(itertools.islice(combos, chunk)), dtype=np.int64)
        if block.size == 0:
            break
        block = block.reshape(-1, len(groups))
        xs = np.zeros((block.shape[0], prim.size))
        r, col = np.nonzero(block >= 0)
        xs[r, block[r, col]] = 1.0
        slack = model.b_ub[None, :] - xs @ a_p.T  # (N, m)
        feas = np.all(slack >= -1e-9, axis=1)
        if auxi.size:
            # z can be 1 iff every row holding it keeps slack >= 1
            rows_with = a_z.T != 0  # (n_z, m)
            zok = np.all(
                np.where(rows_with[None, :, :], slack[:, None, :] >= 1 - 1e-9, True), axis=2
            )
            zs_ = zok & (c_z[None, :] > 0)
        else:
            zs_ = np.zeros((block.shape[0], 0), dtype=bool)
        val = xs @ c_p + zs_ @ c_z
        val = np.where(feas, val, -np.inf)
        i = int(np.argmax(val))
        if val[i] > best_val + 1e-12:
            best_val = float(val[i])
            best_x = np.zeros(n)
            best_x[prim] = xs[i]
            best_x[auxi] = zs_[i]
    if best_x is None:  # pragma: no cover - the all-zero vector is always feasible
        raise ValueError("no feasible combination")
    return best_x, best_val
