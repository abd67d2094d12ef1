"""The model's rows, all ``A_ub x <= b_ub`` with integral entries, by family (see
:mod:`solvers.milp_model`): ``agent``, ``dump_once``, ``watch_once``, ``search_once``, ``cover``,
``freeze_dump`` and ``freeze_watch``.

Examples
--------
>>> import numpy as np
>>> agent = np.array([0, 0, 1]); tasks = np.array([[0], [1], [0]])
>>> dump = np.ones((3, 1), bool); cl = np.zeros((3, 1), np.int64)
>>> mat, b, fam = model_rows(agent, tasks, np.zeros((3, 0), np.int64), cl, dump,
...                          np.zeros((3, 1), bool), np.zeros(0, np.int64), np.zeros(3, bool))
>>> fam, mat.toarray().tolist(), b.tolist()
(('agent', 'dump_once'), [[1.0, 1.0, 0.0], [1.0, 0.0, 1.0]], [1.0, 1.0])
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["model_rows"]


class _Rows:
    """Constraint rows collected family by family (in COO form)."""

    def __init__(self) -> None:
        self.rows_i: list[np.ndarray] = []
        self.cols_j: list[np.ndarray] = []
        self.vals: list[np.ndarray] = []
        self.rhs: list[np.ndarray] = []
        self.fam: list[str] = []
        self.n_rows = 0

    def add(
        self, group: np.ndarray, cols: np.ndarray, coef: np.ndarray, rhs: float, name: str,
        *, min_terms: int = 1,
    ) -> None:  # fmt: skip
        """Rows from a group label per entry (entries with the same label share a row); rows
        with fewer than ``min_terms`` entries are left out (they cannot bind)."""
        if group.size == 0:
            return
        labels, inv, counts = np.unique(group, return_inverse=True, return_counts=True)
        keep = counts >= min_terms
        if not keep.any():
            return
        new_id = np.cumsum(keep) - 1
        sel = keep[inv]
        self.rows_i.append(self.n_rows + new_id[inv[sel]])
        self.cols_j.append(cols[sel])
        self.vals.append(np.asarray(coef, dtype=np.float64)[sel])
        n = int(keep.sum())
        self.rhs.append(np.full(n, float(rhs)))
        self.fam.extend([name] * n)
        self.n_rows += n

    def matrix(self, n: int) -> tuple[sp.csr_array, np.ndarray]:
        """The (rows, n) matrix and the right-hand sides."""
        if not self.rows_i:
            return sp.csr_array((0, n)), np.zeros(0)
        mat = sp.csr_array(
            (
                np.concatenate(self.vals),
                (np.concatenate(self.rows_i), np.concatenate(self.cols_j)),
            ),
            shape=(self.n_rows, n),
        )
        mat.sum_duplicates()
        return mat, np.concatenate(self.rhs)


def model_rows(
    agent: np.ndarray,
    tasks: np.ndarray,
    cover: np.ndarray,
    cluster: np.ndarray,
    dump: np.ndarray,
    sees: np.ndarray,
    labels: np.ndarray,
    search: np.ndarray,
) -> tuple[sp.csr_array, np.ndarray, tuple[str, ...]]:
    """The constraint matrix, right-hand sides and row families.

    Parameters
    ----------
    agent : ndarray, (R,)
        Agent row of each route.
    tasks : ndarray, (R, L)
        Task rows of each route (-1 padded).
    cover : ndarray or sparse array, (R, B) int
        Detected share (in ``1 / cover_levels``) of each cover variable's block by each route.
    cluster, dump, sees : ndarray, (R, L)
        Connected fire of each route entry, and whether the entry dumps on it / senses it.
    labels : ndarray, (Z,)
        Connected fire of each freeze variable.
    search : ndarray, (R,) bool
        Search routes.
    """
    n_r, n_b, n_z = agent.size, cover.shape[1], labels.size
    rows = _Rows()
    r_idx = np.arange(n_r)
    # one route per agent
    rows.add(agent, r_idx, np.ones(n_r), 1, "agent", min_terms=2)
    # each fire task dumped on by at most one route
    rr, jj = np.nonzero(dump)
    rows.add(tasks[rr, jj], rr, np.ones(rr.size), 1, "dump_once", min_terms=2)
    # each connected fire watched by at most one watch route
    watch_only = sees & ~dump
    rr, jj = np.nonzero(watch_only)
    rows.add(cluster[rr, jj], rr, np.ones(rr.size), 1, "watch_once", min_terms=2)
    # each search block the first task of at most one search route
    lead = np.flatnonzero(search)
    rows.add(tasks[lead, 0], lead, np.ones(lead.size), 1, "search_once", min_terms=2)
    # cover[b] <= sum_r share[r, b] y_r
    cov = sp.coo_array(cover)
    rb, bb = cov.row.astype(np.int64), cov.col.astype(np.int64)
    rows.add(
        np.r_[np.arange(n_b), bb],
        np.r_[n_r + np.arange(n_b), rb],
        np.r_[np.ones(n_b), -cov.data.astype(np.float64)],
        0,
        "cover",
    )
    if n_z:
        z_col = n_r + n_b + np.arange(n_z)
        for name, entries in (("freeze_dump", dump), ("freeze_watch", sees)):
            rr, jj = np.nonzero(entries)
            cl = cluster[rr, jj]
            mine = np.isin(cl, labels)
            pair = np.unique(np.c_[np.searchsorted(labels, cl[mine]), rr[mine]], axis=0)
            rows.add(
                np.r_[np.arange(n_z), pair[:, 0]],
                np.r_[z_col, pair[:, 1]],
                np.r_[np.ones(n_z), -np.ones(len(pair))],
                0,
                name,
            )
    mat, b = rows.matrix(n_r + n_b + n_z)
    return mat, b, tuple(rows.fam)
