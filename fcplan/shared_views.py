"""Copies and pickles that keep an object's numpy views views of the same memory.

Many of fcplan's stateful objects keep several numpy arrays on one block of memory: a map and
its flat view (``World.sensed`` and the flat view the sensing writes through), a padded grid and
the inner window the rules write, the sliding windows the crops are gathered from, one buffer
of observations and the per-agent dicts that hand out its rows. ``copy.deepcopy`` and
``pickle`` copy every array on its own (numpy's ``__deepcopy__`` and ``__reduce__`` copy an
array's data, not its relation to a base), so a copied environment used to write through one
copy and read another: it ran on silently, and its steps differed from the original's from the
first tick on (measured on both levels, single and batched, before this module).

:class:`KeepsViews` is the mixin that keeps those relations. Its ``__getstate__`` replaces every
array of the object's state (in attributes, and in the lists, tuples and dicts they hold) that
is a view of a larger array by a small record, :class:`_View`: the array that owns the memory,
and the view's byte offset, shape, strides and write flag. Pickle and ``copy.deepcopy`` copy
each owner once (both keep a memo by object) and rebuild the views on the copy, so views of one
owner held by different objects of one copied tree stay on one block of memory too. A shallow
``copy.copy`` gets views of the same owners, as a shallow copy should.

The mixin is for objects with state, whose views are written. Values handed out (task graphs,
candidate tables) stay plain: their arrays are rows of a batch's arrays, and a view record would
carry the whole batch's owner into the pickle of one graph (64 worlds of #1: 98 kB for one task
graph instead of 23 kB, 720 kB for one candidate table instead of 12 kB).

An owner that a :class:`KeepsViews` class wants copied otherwise (the batched belief's maps,
which are paged in only where written, :mod:`fcplan.batch.pages`) is replaced in the class's
own ``__getstate__`` by another :class:`CopyRecord` (``fcplan.batch.pages.PagedRows``).

Examples
--------
>>> import copy
>>> class Maps(KeepsViews):
...     def __init__(self):
...         self.grid = np.zeros((3, 3))
...         self.flat = self.grid.reshape(-1)
>>> m = copy.deepcopy(Maps())
>>> m.flat[4] = 1.0
>>> m.grid[1, 1]
np.float64(1.0)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.lib.stride_tricks import as_strided

__all__ = ["CopyRecord", "KeepsViews", "memory_owner"]


def memory_owner(a: np.ndarray) -> np.ndarray:
    """The outermost numpy array whose memory ``a`` views (``a`` itself if it owns its data or
    views a non-numpy buffer), following the bases of strided views (``as_strided``,
    ``sliding_window_view``) through their buffer objects.

    Examples
    --------
    >>> g = np.zeros((4, 4))
    >>> memory_owner(g[1:, ::2]) is g, memory_owner(g) is g
    (True, True)
    """
    while True:
        base: Any = a.base
        inner = getattr(base, "base", None)  # (as_strided's buffer object keeps its array)
        if isinstance(base, np.ndarray):
            a = base
        elif isinstance(inner, np.ndarray):
            a = inner
        else:
            return a


class CopyRecord:
    """What stands for an array in a copied state: it pickles and deep-copies as its
    ``__reduce__`` says, and :meth:`array` gives the array again where a shallow copy left the
    record itself (:meth:`KeepsViews.__setstate__`). ``_args`` are the arguments of ``_make``."""

    __slots__ = ("_args",)
    _args: tuple[Any, ...]
    _make: Any  # (a staticmethod of the subclass)

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        return type(self)._make, self._args

    def array(self) -> np.ndarray:
        """The array this record stands for."""
        return type(self)._make(*self._args)


def _rebuild(
    owner: np.ndarray,
    offset: int,
    shape: tuple[int, ...],
    strides: tuple[int, ...],
    dtype: np.dtype,
    writeable: bool,
) -> np.ndarray:
    """The view of ``owner`` at ``offset`` bytes with ``shape`` and ``strides``."""
    start = owner.reshape(-1).view(np.uint8)[offset : offset + dtype.itemsize].view(dtype)
    return as_strided(
        start, shape=shape, strides=strides, writeable=writeable and owner.flags.writeable
    )


class _View(CopyRecord):
    """A view of ``owner`` in a copied state: rebuilt by :func:`_rebuild` on the copy."""

    __slots__ = ()
    _make = staticmethod(_rebuild)

    def __init__(self, a: np.ndarray, owner: np.ndarray) -> None:
        offset = a.__array_interface__["data"][0] - owner.__array_interface__["data"][0]
        self._args = (owner, int(offset), a.shape, a.strides, a.dtype, bool(a.flags.writeable))


def _each(value: Any, leaf: Any) -> Any:
    """``value`` with ``leaf`` applied to everything but lists, tuples and dicts, through them."""
    if type(value) is list:
        return [_each(v, leaf) for v in value]
    if type(value) is tuple:
        return tuple(_each(v, leaf) for v in value)
    if type(value) is dict:
        return {k: _each(v, leaf) for k, v in value.items()}
    return leaf(value)


def _encode(value: Any) -> Any:
    """A :class:`_View` for an array that views a larger array's memory, else ``value``."""
    if not isinstance(value, np.ndarray) or value.size == 0 or value.dtype.hasobject:
        return value
    owner = memory_owner(value)
    if owner is value or not owner.flags.c_contiguous:
        return value
    return _View(value, owner)


def _decode(value: Any) -> Any:
    """The array of a :class:`CopyRecord` left in a state (a shallow copy), else ``value``."""
    return value.array() if isinstance(value, CopyRecord) else value


class KeepsViews:
    """Mixin: ``copy.deepcopy``, ``copy.copy`` and ``pickle`` keep the object's views of shared
    memory views of the copied memory (module docstring)."""

    def __getstate__(self) -> dict[str, Any]:
        """The instance's attributes with the views of shared memory as records."""
        return {k: _each(v, _encode) for k, v in self.__dict__.items()}

    def __setstate__(self, state: dict[str, Any]) -> None:
        """Restore the attributes (views a deep copy or pickle left as records, rebuilt)."""
        self.__dict__.update({k: _each(v, _decode) for k, v in state.items()})
