"""The assignment model's settings, variable kinds and arrays (:class:`MilpModel`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

__all__ = ["AUX", "DUMP", "KIND_NAMES", "SEARCH", "WATCH", "MilpModel", "MilpParams"]

#: Variable kinds (:attr:`MilpModel.var_kind`).
DUMP, WATCH, SEARCH, AUX = 0, 1, 2, 3
KIND_NAMES = ("dump", "watch", "search", "aux")


@dataclass(frozen=True, slots=True)
class MilpParams:
    """Settings of the assignment model (shared by both MILP schedulers).

    Parameters
    ----------
    slots : int
        Ordered task slots per agent (the planning horizon in tasks).
    fresh_s : float
        A fire sensed within this many seconds is fresh: dumping on it needs no watcher (a stale
        one is worth nothing without one).
    tau_s : float
        Time constant of the travel-time discount ``1 / (1 + eta / tau_s)``.
    slot_delay_s : float
        Estimated extra arrival time per earlier slot (see the module docstring).
    search_weight : float
        Weight of a search block's coverage-age value against fire values.
    watch_weight : float
        Weight of a fire's value for the agent watching it (its own sensing reward; the coupling
        gives watching its main worth).
    spread_px : float
        Search assignments (all agents, all slots) at most one among the blocks within this
        distance of any candidate block (150 px: no two on neighbouring 100-px blocks); 0: only
        each block at most once.
    support_weight : float
        Bonus (times the fire's value) for a dump on a *fresh* fire whose connected fire is also
        watched in the same or an earlier slot (the watcher senses the cells that appeared since,
        so the dump can prune them). 0 turns it off (then fresh fires get no ``z``).
    fire_candidates, search_candidates : int
        Fire tasks / search blocks kept per agent (best slot-0 discounted value).
    watch_altitude, search_altitude : float
        Altitudes (m, clipped to each agent's bounds) of agents whose route starts with a fire
        task / a search block.
    """

    slots: int = 2
    fresh_s: float = 10.0
    tau_s: float = 1.0
    slot_delay_s: float = 3.0
    search_weight: float = 0.3
    watch_weight: float = 0.2
    fire_candidates: int = 6
    search_candidates: int = 16
    spread_px: float = 150.0
    support_weight: float = 3.0
    watch_altitude: float = 35.0
    search_altitude: float = 70.0

    def __post_init__(self) -> None:
        if self.slots < 1:
            raise ValueError(f"slots must be >= 1, got {self.slots}")
        if not self.tau_s > 0:
            raise ValueError(f"tau_s must be > 0, got {self.tau_s}")
        if self.fire_candidates < 0 or self.search_candidates < 0:
            raise ValueError("candidate counts must be >= 0")


@dataclass(frozen=True, eq=False)
class MilpModel:
    """``max c @ x  s.t.  A_ub @ x <= b_ub,  x in {0, 1}^n`` plus what each variable means.

    Attributes
    ----------
    c : ndarray, (n,) float64
        Objective coefficients (maximised).
    A_ub : scipy.sparse.csr_array, (m, n) float64
        Constraint matrix; every entry is integral.
    b_ub : ndarray, (m,) float64
        Right-hand sides (integral).
    integrality : ndarray, (n,) int8
        1 for integer variables (all of them: every variable is binary, bounds ``[0, 1]``).
    var_agent, var_task, var_slot : ndarray, (n,) int64
        Agent row, task row and slot of each variable (``var_agent = -1`` for ``AUX``).
    var_kind : ndarray, (n,) int8
        ``DUMP``, ``WATCH``, ``SEARCH`` or ``AUX``.
    row_kind : tuple of str
        Constraint family of each row (``slot``, ``order``, ``once``, ``spread``, ``tank``,
        ``battery``, ``couple_dump``, ``couple_watch``).
    agent_ids, task_ids : tuple of str
        Of the graph the model was built for.
    params : MilpParams
    size : dict
        Sizes for :class:`fcplan.scheduling.SolveStats` (variables, constraints, nonzeros, ...).
    """

    c: np.ndarray
    A_ub: sp.csr_array
    b_ub: np.ndarray
    integrality: np.ndarray
    var_agent: np.ndarray
    var_task: np.ndarray
    var_slot: np.ndarray
    var_kind: np.ndarray
    row_kind: tuple[str, ...]
    agent_ids: tuple[str, ...]
    task_ids: tuple[str, ...]
    params: MilpParams
    size: dict[str, Any] = field(default_factory=dict)

    @property
    def n_vars(self) -> int:
        """Number of variables ``n``."""
        return int(self.c.size)

    @property
    def n_rows(self) -> int:
        """Number of constraints ``m``."""
        return int(self.b_ub.size)

    @property
    def lb(self) -> np.ndarray:
        """(n,) lower bounds (0)."""
        return np.zeros(self.n_vars)

    @property
    def ub(self) -> np.ndarray:
        """(n,) upper bounds (1)."""
        return np.ones(self.n_vars)

    def objective(self, x: np.ndarray) -> float:
        """``c @ x``."""
        return float(self.c @ np.asarray(x, dtype=np.float64))

    def is_feasible(self, x: np.ndarray, tol: float = 1e-6) -> bool:
        """``x`` is 0/1 (within ``tol``) and satisfies every row."""
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self.n_vars,):
            return False
        if np.any(np.abs(x - np.round(x)) > tol) or np.any(x < -tol) or np.any(x > 1 + tol):
            return False
        return bool(np.all(self.A_ub @ np.round(x) <= self.b_ub + tol))
