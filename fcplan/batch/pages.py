"""Arrays of zeros that take memory only where they are written.

A batch holds per-world maps of the whole world (the fire's cell grid, the team's belief) of
which an episode writes a small part: the cells near the fire. ``numpy.zeros`` already gets
its memory lazily, zeroed by the operating system at the first write to each page, but numpy
advises the kernel to back large arrays by 2 MB huge pages (with transparent huge pages on
``madvise``, Linux's usual setting), so a single write makes 2 MB resident and a batch of such
maps, written at scattered cells, becomes resident nearly whole. :func:`paged_zeros` gives the
same zeros in an anonymous memory map of its own, advised against huge pages where the platform
allows it (``mmap.MADV_NOHUGEPAGE``), so that memory is taken one small page (4 KB on Linux) at
a time. :class:`fcplan.belief_batch.BatchBelief` keeps its maps in them. ``bench/README.md``
("The batched belief is paged in only where written", and the section after it) measures what
this saves and what the page faults cost, and why the fire's cell grid
(:class:`fcplan.batch.cells.CellGrid`) stays written whole when it is made.

Copies. ``pickle`` and ``copy.deepcopy`` would copy such an array whole, into ordinary memory,
every page of it made resident. :class:`PagedRows` stands for one in a copied state and keeps
only the rows its owner says were written: the copy is a :func:`paged_zeros` array again, with
those rows filled.
"""

from __future__ import annotations

import mmap
from typing import Any

import numpy as np

from fcplan.shared_views import CopyRecord

__all__ = ["PagedRows", "paged_zeros"]


def paged_zeros(shape: tuple[int, ...], dtype: Any) -> np.ndarray:
    """A C-contiguous array of zeros whose memory the operating system maps at the first write
    to each small page (module docstring). The map lives as long as the array.

    Examples
    --------
    >>> a = paged_zeros((2, 3), np.int32)
    >>> a[1, 2] = 7
    >>> a.tolist(), a.dtype.name, a.flags.c_contiguous
    ([[0, 0, 0], [0, 0, 7]], 'int32', True)
    """
    dt = np.dtype(dtype)
    count = int(np.prod(shape, dtype=np.int64))
    buf = mmap.mmap(-1, max(count * dt.itemsize, 1))
    if hasattr(mmap, "MADV_NOHUGEPAGE"):
        buf.madvise(mmap.MADV_NOHUGEPAGE)
    return np.frombuffer(buf, dtype=dt, count=count).reshape(shape)


def _paged_rows(
    shape: tuple[int, ...], dtype: str, index: tuple[np.ndarray, ...], rows: np.ndarray
) -> np.ndarray:
    """A :func:`paged_zeros` array of ``shape`` with ``rows`` written at ``index``."""
    out = paged_zeros(shape, np.dtype(dtype))
    out[index] = rows
    return out


class PagedRows(CopyRecord):
    """A :func:`paged_zeros` array ``a`` of shape ``(B, W, ...)`` in a copied state, with only
    the rows ``written`` ((B, W) bool; every other row must be all zeros) kept: it pickles and
    deep-copies as those rows, and comes back as a paged array (module docstring).

    Examples
    --------
    >>> import pickle
    >>> a = paged_zeros((2, 3, 4), np.int32)
    >>> a[1, 2, 3] = 5
    >>> written = np.zeros((2, 3), dtype=bool)
    >>> written[1, 2] = True
    >>> b = pickle.loads(pickle.dumps(PagedRows(a, written)))
    >>> bool((b == a).all()), int(b[1, 2, 3])
    (True, 5)
    """

    __slots__ = ()
    _make = staticmethod(_paged_rows)

    def __init__(self, a: np.ndarray, written: np.ndarray) -> None:
        index = np.nonzero(written)
        self._args = (a.shape, a.dtype.str, index, a[index])
