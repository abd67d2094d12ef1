"""Kernels of :class:`fcplan.fire.Fire`'s step.

* :func:`draw_ahead` computes the position-free part of the FARSITE step (the two normal draws of
  every front, the wind speed ``U``, ``C/R`` of ``U``, ``sin`` and ``cos`` of ``Theta``) for a
  block of steps in a few numpy calls. The normals are drawn as one ``(T, 2, n)`` array, which
  takes them from the generator in the order ``T`` per-step draws of shape ``(2, n)`` would, and
  element by element the arithmetic is the per-step one (:func:`fcplan.farsite.wind_draws`), so
  the fronts move exactly as if everything were computed step by step. :func:`draw_ahead_tables`
  is the same for the tables wind model (:func:`fcplan.farsite.wind_from_tables`).
* :func:`advance_whole` is the FARSITE step over the whole ``(2, n)`` position array in place,
  without gathering the moving fronts: the fronts that do not move get a zero spread
  (``x + (+-0.0) == x``; positions are never ``-0.0``).
* :func:`ignite_cells` is ``Fire._ignite`` of a few cells on Python ints.
* :func:`unique` is ``np.unique`` of a 1-D array with less call overhead.

``tests/_fast/test_fast_fire.py`` checks each against the readable rule, bit for bit. The kernels
read the fire's arrays and take the rule's constants as arguments or from the fire: this module
cannot import :mod:`fcplan.fire`, which imports it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["draw_ahead", "draw_ahead_tables", "advance_whole", "ignite_cells", "unique"]

_EMPTY = np.zeros(0, dtype=np.int64)


def draw_ahead(
    rng: np.random.Generator,
    z: np.ndarray,
    sin_cos: np.ndarray,
    ratio: np.ndarray | None,
    wind_avg: np.ndarray,
    theta_avg: np.ndarray,
    speed_sd: float,
    dir_sd: float,
    ratio_of: Callable[[np.ndarray], np.ndarray],
) -> None:
    """Fill the wind of the next ``T`` steps of ``n`` fronts in place (fresh wind model).

    Parameters
    ----------
    rng : numpy.random.Generator
        The fire's stream.
    z : ndarray, (T, 2, n) float64
        Receives the normals; afterwards ``z[:, 0]`` holds the wind speeds ``U`` (``z[:, 1]``
        is scratch).
    sin_cos : ndarray, (T, 2, n) float64
        Receives ``sin(Theta)`` (``[:, 0]``) and ``cos(Theta)`` (``[:, 1]``).
    ratio : ndarray, (T, n) float64 or None
        Receives ``C/R`` of ``U`` (skipped when None).
    wind_avg, theta_avg : ndarray, (n,) float64
        Mean wind speed and direction (rad) of each front.
    speed_sd, dir_sd : float
        Standard deviations of the wind speed and direction.
    ratio_of : callable
        ``C/R`` of a 1-D array of wind speeds.
    """
    rng.standard_normal(out=z)
    theta = z[:, 1]
    theta *= dir_sd
    theta += theta_avg
    np.sin(theta, out=sin_cos[:, 0])
    np.cos(theta, out=sin_cos[:, 1])
    u = z[:, 0]  # the speed draws, overwritten
    u *= speed_sd
    u += wind_avg
    if ratio is not None:
        ratio[:] = ratio_of(u.reshape(-1)).reshape(u.shape)


def draw_ahead_tables(
    rng: np.random.Generator,
    z: np.ndarray,
    sin_cos: np.ndarray,
    ratio: np.ndarray,
    base: np.ndarray,
    length: int,
    tab_u: np.ndarray,
    tab_sin: np.ndarray,
    tab_cos: np.ndarray,
    tab_ratio: np.ndarray,
) -> None:
    """:func:`draw_ahead` for the tables model: the wind of the next ``T`` steps of ``n`` fronts,
    picked from their regions' tables, in place.

    The table indices are drawn as one ``(T, 2, n)`` integer array, which takes them from the
    generator in the order ``T`` per-step draws of shape ``(2, n)`` would
    (:func:`fcplan.farsite.wind_from_tables`); the values are gathered from per-entry arrays.

    Parameters
    ----------
    rng : numpy.random.Generator
    z : ndarray, (T, 2, n) float64
        ``z[:, 0]`` receives the wind speeds ``U`` (``z[:, 1]`` is left alone).
    sin_cos : ndarray, (T, 2, n) float64
        Receives ``sin(Theta)`` (``[:, 0]``) and ``cos(Theta)`` (``[:, 1]``).
    ratio : ndarray, (T, n) float64
        Receives ``C/R`` of ``U``.
    base : ndarray, (n,) int64
        Offset of each front's region in the flat tables (``region * length``).
    length : int
        Entries per table.
    tab_u, tab_sin, tab_cos, tab_ratio : ndarray, (R * length,) float64
        Per table entry: the speed, ``sin`` and ``cos`` of the direction, and ``C/R`` of the speed.
    """
    idx = rng.integers(0, length, size=z.shape)
    idx += base
    i_u, i_dir = idx[:, 0], idx[:, 1]
    z[:, 0] = tab_u[i_u]
    ratio[:] = tab_ratio[i_u]
    sin_cos[:, 0] = tab_sin[i_dir]
    sin_cos[:, 1] = tab_cos[i_dir]


def advance_whole(fire: Any, t: int, ratio: np.ndarray, all_moving: bool) -> np.ndarray:
    """``Fire._advance_moving`` over every front, in place; return the ``(2, n)`` positions.

    Parameters
    ----------
    fire : fcplan.fire.Fire
    t : int
        Row of the drawn-ahead wind to use.
    ratio : ndarray, (n,) float64
        ``C/R`` of every front this step.
    all_moving : bool
        Every front moves; otherwise the fronts that do not move (dead, frozen, region inactive)
        get a zero spread and dead ones, just off the map, read a clipped terrain cell.
    """
    xy, sc = fire._xy, fire._pre_sc[t]
    cells = fire._t_stride @ np.rint(xy).astype(np.int64)
    if all_moving:
        terrain, fuel = fire._terrain_flat[cells], fire._m_fuel
    else:
        terrain, fuel = fire._terrain_flat.take(cells, mode="clip"), fire._fuel_masked
    c = terrain * fuel * ratio
    # x += C sin(Theta), y += C cos(Theta)
    xy += np.multiply(sc, c, out=fire._move)
    return xy


def ignite_cells(fire: Any, cells: list[int]) -> np.ndarray:
    """``Fire._ignite`` of a short list of unburnt flat cells (Python ints, repeats allowed).

    Parameters
    ----------
    fire : fcplan.fire.Fire
    cells : list of int
        Flat indices ``x W + y`` of unburnt cells.

    Returns
    -------
    ndarray, (k,) int64
        The distinct cells, sorted, now burning.
    """
    if not cells:
        return _EMPTY
    w, nblk, blocks, side = fire.world_size, fire._nblk, fire._block_flat, fire._block
    if len(cells) > 1:
        cells = sorted(set(cells))
    y0, y1 = w, -1
    for c in cells:
        cx, cy = divmod(c, w)
        blocks[(cx // side) * nblk + cy // side] += 1
        if cy < y0:
            y0 = cy
        if cy > y1:
            y1 = cy
    # (cells are sorted: x grows along the list)
    return fire._burn(np.array(cells, dtype=np.int64), cells[0] // w, cells[-1] // w, y0, y1)


def unique(a: np.ndarray) -> np.ndarray:
    """``np.unique`` of a 1-D array (sorted distinct values), with less call overhead.

    Examples
    --------
    >>> import numpy as np
    >>> unique(np.array([3, 1, 3, 2])).tolist()
    [1, 2, 3]
    """
    s = np.sort(a)
    keep = np.empty(s.size, dtype=bool)
    keep[:1] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]
