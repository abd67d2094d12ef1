"""Kernels of :meth:`fcplan.world.World.step`.

* :func:`step_info_builder` makes the function that builds the tick's
  :class:`~fcplan.world.StepInfo`: the frozen dataclass's ``__init__`` goes through
  ``object.__setattr__`` once per field, the builder sets the slots through their descriptors
  (there is no ``__post_init__`` to run). The instance is the one ``StepInfo(...)`` gives.
* :func:`scan_box` is the part of a field of view worth scanning for burning cells, in a few
  integer operations on Python numbers.

``tests/_fast/test_fast_world.py`` checks both against the plain construction and computation.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from fcplan.fire import BLOCK

__all__ = ["step_info_builder", "scan_box"]

_T = TypeVar("_T")
_STEP_INFO_FIELDS = 9


def step_info_builder(cls: type[_T]) -> Callable[..., _T]:
    """A function building an instance of the frozen slots dataclass ``cls`` from its nine fields
    in order, exactly as ``cls(...)`` does.

    Parameters
    ----------
    cls : type
        :class:`fcplan.world.StepInfo` (a frozen ``slots=True`` dataclass of nine fields and no
        ``__post_init__``).

    Returns
    -------
    callable
        ``build(tick, time_s, ignited, sensed, newly, pruned, fov_rects, dumped, arrived)``.
    """
    fields = dataclasses.fields(cls)  # type: ignore[arg-type]
    if len(fields) != _STEP_INFO_FIELDS or hasattr(cls, "__post_init__"):
        raise TypeError(f"{cls.__name__} is not a StepInfo-like dataclass")
    new = object.__new__
    (s_tick, s_time, s_ign, s_sensed, s_newly, s_pruned, s_fov, s_dumped, s_arrived) = (
        getattr(cls, f.name).__set__ for f in fields
    )

    def build(
        tick: int,
        time_s: float,
        ignited: np.ndarray,
        sensed: np.ndarray,
        newly: np.ndarray,
        pruned: np.ndarray,
        fov_rects: list[list[float]],
        dumped: tuple[int, ...],
        arrived: tuple[int, ...],
    ) -> _T:
        info = new(cls)
        s_tick(info, tick)
        s_time(info, time_s)
        s_ign(info, ignited)
        s_sensed(info, sensed)
        s_newly(info, newly)
        s_pruned(info, pruned)
        s_fov(info, fov_rects)
        s_dumped(info, dumped)
        s_arrived(info, arrived)
        return info

    return build


def scan_box(rect: list[float], blocks: np.ndarray, w: int) -> tuple[int, int, int, int] | None:
    """The part of the field of view ``rect`` (inclusive ``[x0, x1, y0, y1]`` of Python floats)
    that can hold burning cells, as an end-exclusive cell range ``(x0, x1, y0, y1)``, or None.

    The range is that of the cells covered by ``rect``, clipped to the ``w x w`` map, then shrunk
    to the bounding box of its ``BLOCK``-sized blocks that hold a burning cell (``blocks``: the
    fire's per-block counts). Every burning cell of the covered range lies in the box, so scanning
    the box row-major finds the same cells in the same order as scanning the whole range. None
    when the range is empty or holds no burning block.

    Examples
    --------
    >>> import numpy as np
    >>> blocks = np.zeros((4, 4), dtype=np.int32)
    >>> blocks[1, 2] = 1  # cells x in [16, 32), y in [32, 48) hold fire
    >>> scan_box([10.0, 40.5, 20.0, 60.0], blocks, 64)
    (16, 32, 32, 48)
    """
    # (conditional expressions: cheaper than max()/min() calls on this per-tick path)
    a = math.ceil(rect[0])
    x0 = a if a > 0 else 0
    a = math.floor(rect[1])
    x1 = a if a < w - 1 else w - 1
    a = math.ceil(rect[2])
    y0 = a if a > 0 else 0
    a = math.floor(rect[3])
    y1 = a if a < w - 1 else w - 1
    if x1 < x0 or y1 < y0:
        return None
    i0, j0 = x0 // BLOCK, y0 // BLOCK
    b = blocks[i0 : x1 // BLOCK + 1, j0 : y1 // BLOCK + 1]
    if not np.count_nonzero(b):
        return None
    bi, bj_arr = b.nonzero()  # (the method: cheaper than np.nonzero's dispatch)
    bj = bj_arr.tolist()
    a = (i0 + int(bi[0])) * BLOCK
    x0 = a if a > x0 else x0
    a = (i0 + int(bi[-1]) + 1) * BLOCK
    x1 = a if a <= x1 else x1 + 1
    a = (j0 + min(bj)) * BLOCK
    y0 = a if a > y0 else y0
    a = (j0 + max(bj) + 1) * BLOCK
    y1 = a if a <= y1 else y1 + 1
    return x0, x1, y0, y1
