"""What both MILP schedulers share: settings, model building, solving and plan decoding."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats
from fcplan.taskgraph import TaskGraph
from solvers.milp_model.build import build_milp_model
from solvers.milp_model.decode import decode_plan
from solvers.milp_model.types import MilpModel, MilpParams

__all__ = ["MilpSchedulerBase"]


class MilpSchedulerBase:
    """What both MILP schedulers share: settings, model building and plan decoding.

    Subclasses set ``name`` and ``default_time_limit`` and implement :meth:`_solve` (one backend).

    Parameters
    ----------
    time_limit : float, optional
        Seconds per replan when the caller gives no limit (a given ``time_limit`` overrides it);
        ``default_time_limit`` if omitted.
    seed : int
        The backend's random seed (single worker / thread, so results are deterministic).
    **model_settings
        Fields of :class:`MilpParams` (``slots``, ``fresh_s``, ``tau_s``, ``slot_delay_s``,
        ``search_weight``, ``watch_weight``, ``fire_candidates``, ``search_candidates``,
        ``watch_altitude``, ``search_altitude`` ...).
    """

    name = "milp-base"
    default_time_limit = 0.2

    def __init__(
        self, time_limit: float | None = None, seed: int = 0, **model_settings: Any
    ) -> None:
        self.time_limit = float(self.default_time_limit if time_limit is None else time_limit)
        self.seed = int(seed)
        self.params = MilpParams(**model_settings)

    def plan(self, graph: TaskGraph, *, time_limit: float | None = None, rng: Any = None) -> Plan:
        """Build the model of ``graph``, solve it with the backend and decode the plan.

        Raises
        ------
        RuntimeError
            If the backend returns no solution within the limit.
        """
        t0 = time.perf_counter()
        limit = self.time_limit if time_limit is None else float(time_limit)
        model = build_milp_model(graph, self.params)
        remaining = max(limit - (time.perf_counter() - t0), 1e-4)
        x, stats = self._solve(model, time_limit=remaining, seed=self.seed)
        return decode_plan(model, x, graph, stats)

    def _solve(
        self, model: MilpModel, *, time_limit: float, seed: int
    ) -> tuple[np.ndarray, SolveStats]:  # pragma: no cover
        raise NotImplementedError
