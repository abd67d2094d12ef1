"""Batched simulator: ``B`` worlds of one scenario stepped in one call (issue 14).

See :mod:`fcplan.batch.world` for the tick and the episode rules, :mod:`fcplan.batch.cells`,
:mod:`fcplan.batch.fire`, :mod:`fcplan.batch.team` and :mod:`fcplan.batch.streams` for the data
layout and how each world stays bit-identical to a single :class:`fcplan.World` of the same seed.
"""

from __future__ import annotations

from fcplan.batch.world import BatchStepInfo, BatchWorld

__all__ = ["BatchWorld", "BatchStepInfo"]
