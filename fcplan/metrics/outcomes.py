"""Outcome metrics that separate schedulers where the manual's scores saturate.

On the manual's scenarios most competent schedulers reach OFS, PS, AS and FPS of 100 %, and the
manual's final score is in effect ``300 - 3 NRR``. These outcomes, computed from the same trace,
measure what a fire fighter would report; they complement the manual's metrics (which stay the
default and unchanged):

==========================  ===============================================================
outcome                     definition (``T`` ticks, ``tps`` ticks per second)
==========================  ===============================================================
time to containment (s)     ``(t* + 1) / tps`` for the first tick ``t*`` from which no cell
                            is active (burning, unpruned) until the episode ends, counted
                            once some cell has burned; the episode's duration when fire is
                            still active at its end (censored: see ``contained``)
contained                   1 when the fire was contained before the end, else 0
burned area (cells)         cells that ever burned: active plus pruned at the last tick
                            (pruned cells never re-ignite; nothing else stops a burning cell)
facility damage (cell s)    ``sum_t sum_f n_f(t) / tps``: active cells inside facility
                            footprints integrated over simulated seconds
==========================  ===============================================================

The manual's negative reward ratio (NRR, ``metrics.negative_reward_ratio``) is the fourth
discriminating number; it is already among the manual's metrics.

Examples
--------
>>> from fcplan.trace import Trace
>>> tr = Trace.from_counts(ticks_per_second=10, active=[0, 3, 2, 0, 0], pruned=[0, 0, 1, 3, 3],
...                        sensed_active=[0] * 5, sensed_ever=[0] * 5,
...                        facility_burning=[[0], [1], [1], [0], [0]], facility_penalties=[2.0])
>>> compute_outcomes(tr)
Outcomes(time_to_containment_s=0.4, contained=1, burned_area_cells=3, facility_damage_cell_s=0.2)
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from fcplan.trace import Trace

__all__ = ["Outcomes", "compute_outcomes"]


@dataclass(frozen=True)
class Outcomes:
    """The outcome metrics of one episode (module docstring)."""

    time_to_containment_s: float
    contained: int
    burned_area_cells: int
    facility_damage_cell_s: float

    def as_dict(self) -> dict[str, float | int]:
        """Plain dict (for tables)."""
        return asdict(self)


def compute_outcomes(trace: Trace) -> Outcomes:
    """The :class:`Outcomes` of an episode's trace."""
    active = np.asarray(trace.active)
    pruned = np.asarray(trace.pruned)
    tps = float(trace.ticks_per_second)
    n = active.size
    burned = int(active[-1] + pruned[-1]) if n else 0
    burning = np.flatnonzero(active > 0)
    last = int(burning[-1]) if burning.size else -1  # the last row with an active cell
    if burned == 0:  # nothing ever burned
        contained, ttc = 1, 0.0
    elif last == n - 1:  # still burning at the end: censored at the duration
        contained, ttc = 0, n / tps
    else:  # row t is the state after t + 1 ticks; the fire is out from row last + 1 on
        contained, ttc = 1, (last + 2) / tps
    damage = float(np.asarray(trace.facility_burning).sum()) / tps
    return Outcomes(
        time_to_containment_s=float(ttc),
        contained=contained,
        burned_area_cells=burned,
        facility_damage_cell_s=damage,
    )
