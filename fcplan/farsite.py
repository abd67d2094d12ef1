"""FARSITE spread rate and the two wind models of the fire (one fire step of one front).

A fire step moves a front by ``C (sin Theta, cos Theta)`` px (FIRECOMMANDER.md 1.4), with::

    C = R * (C/R)(U),   R = fuel * terrain[round(x), round(y)]
    LB = 0.936 exp(0.2566 U) + 0.461 exp(-0.1548 U) - 0.397
    HB = (LB + sqrt|LB^2 - 1|) / (LB - sqrt|LB^2 - 1|)
    (C/R)(U) = 0.5 (1 - 1 / HB)

:func:`spread_rate_ratio` is ``C/R``; the fire reads it from a table (:func:`ratio_tabulated`).
The wind speed ``U`` (scenario units) and direction ``Theta`` (rad; 0 is +y, pi/2 is +x) of every
front and every step come from one of two models (``Scenario.wind_model``):

``"fresh"`` (:func:`wind_draws`)
    ``U ~ N(U_avg, 2)`` and ``Theta ~ N(theta_avg, 2 rad)``, drawn anew for every front every
    step: every episode has exactly the region's mean wind.
``"tables"`` (:func:`wind_tables`, :func:`wind_from_tables`)
    The original's model: at the start of an episode each region draws a table of ``L`` wind
    speeds ``~ N(U_avg, 2)`` and one of ``L`` directions ``~ N(theta_avg, 2 rad)`` (``L`` = the
    map side in px, 1,200 on the shipped maps); every step each front picks one entry of each
    table, uniformly and independently. The draws have the same law on average over episodes, but
    within an episode they follow the table's empirical distribution, whose mean departs from the
    region's mean by ``O(1 / sqrt(L))``: every episode has its own wind bias, and the spread of
    the fire's drift between episodes is larger (``bench/bench_wind.py``).

Examples
--------
>>> import numpy as np
>>> round(float(spread_rate_ratio(5.0)), 3)
0.487
>>> tables = wind_tables(np.random.default_rng(0), np.array([5.0]), np.array([0.0]), 1200)
>>> tables.shape  # (regions, speed and direction, L)
(1, 2, 1200)
>>> u, s, c = wind_from_tables(np.random.default_rng(1), tables, np.zeros(4, dtype=np.int64))
>>> bool(np.isin(u, tables[0, 0]).all())
True
"""

from __future__ import annotations

import numpy as np

try:  # np.interp without its argument checks (same compiled routine, same results)
    from numpy._core.multiarray import interp as _interp
except ImportError:  # numpy < 2
    from numpy.core.multiarray import interp as _interp  # type: ignore[no-redef]

__all__ = ["spread_rate_ratio", "ratio_tabulated", "wind_draws", "wind_tables", "wind_from_tables"]
__all__ += ["WIND_SPEED_SD", "WIND_DIR_SD_RAD"]

#: Standard deviation of the wind speed draws (scenario units).
WIND_SPEED_SD = 2.0
#: Standard deviation of the wind direction draws (rad, about 115 degrees).
WIND_DIR_SD_RAD = 2.0


def _lb(u: np.ndarray | float) -> np.ndarray:
    """FARSITE length-to-breadth ratio LB(U) (reference exponents 0.2566 and 0.1548)."""
    return 0.936 * np.exp(0.2566 * u) + 0.461 * np.exp(-0.1548 * u) - 0.397


def spread_rate_ratio(wind_speed: np.ndarray | float) -> np.ndarray:
    """FARSITE ``C / R`` as a function of wind speed ``U`` (0 at U = 0, about 0.487 at U = 5).

    Below 1/2 for every ``U`` (``LB(U) >= 0.77`` keeps ``HB > 1``).

    Examples
    --------
    >>> round(float(spread_rate_ratio(5.0)), 3)
    0.487
    """
    lb = _lb(np.asarray(wind_speed, dtype=np.float64))
    s = np.sqrt(np.abs(lb * lb - 1.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_hb = np.where(lb - s != 0.0, (lb - s) / (lb + s), 1.0)
    return 0.5 * (1.0 - inv_hb)


def wind_draws(
    rng: np.random.Generator, wind_avg: np.ndarray, theta_avg: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One step's wind for every front, ``"fresh"`` model: ``U ~ N(U_avg, 2)``,
    ``Theta ~ N(theta_avg, 2 rad)``.

    The two normals of every front are drawn as one ``(2, n)`` array (speeds, then directions).
    :class:`fcplan.fire.Fire` computes this for blocks of steps ahead, bit for bit as successive
    calls.

    Parameters
    ----------
    rng : numpy.random.Generator
    wind_avg, theta_avg : ndarray, (n,) float64
        Mean wind speed and direction (rad) of each front.

    Returns
    -------
    u, sin_theta, cos_theta : ndarray, (n,) float64

    Examples
    --------
    >>> import numpy as np
    >>> u, s, c = wind_draws(np.random.default_rng(0), np.full(3, 5.0), np.zeros(3))
    >>> u.shape, bool(np.allclose(s**2 + c**2, 1.0))
    ((3,), True)
    """
    z = rng.standard_normal((2, wind_avg.size))
    u = z[0] * WIND_SPEED_SD + wind_avg
    theta = z[1] * WIND_DIR_SD_RAD + theta_avg
    return u, np.sin(theta), np.cos(theta)


def wind_tables(
    rng: np.random.Generator, wind_avg: np.ndarray, theta_avg: np.ndarray, length: int
) -> np.ndarray:
    """The ``"tables"`` model's per-episode tables: ``length`` speeds and ``length`` directions
    per region.

    Parameters
    ----------
    rng : numpy.random.Generator
    wind_avg, theta_avg : ndarray, (R,) float64
        Mean wind speed and direction (rad) of each region.
    length : int
        Entries per table (the original uses the map side in px).

    Returns
    -------
    ndarray, (R, 2, length) float64
        ``[r, 0]`` the speeds ``~ N(U_avg, 2)``, ``[r, 1]`` the directions ``~ N(theta_avg, 2)``
        of region ``r``.
    """
    z = rng.standard_normal((len(wind_avg), 2, int(length)))
    z[:, 0] *= WIND_SPEED_SD
    z[:, 0] += np.asarray(wind_avg, dtype=np.float64)[:, None]
    z[:, 1] *= WIND_DIR_SD_RAD
    z[:, 1] += np.asarray(theta_avg, dtype=np.float64)[:, None]
    return z


def wind_from_tables(
    rng: np.random.Generator, tables: np.ndarray, region: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One step's wind for every front, ``"tables"`` model: entry ``i`` of its region's speed
    table and entry ``j`` of its direction table, ``i`` and ``j`` uniform on ``0 .. L - 1``.

    The two indices of every front are drawn as one ``(2, n)`` integer array (speeds, then
    directions). :class:`fcplan.fire.Fire` computes this for blocks of steps ahead, bit for bit
    as successive calls.

    Parameters
    ----------
    rng : numpy.random.Generator
    tables : ndarray, (R, 2, L) float64
        From :func:`wind_tables`.
    region : ndarray, (n,) int
        Region of each front.

    Returns
    -------
    u, sin_theta, cos_theta : ndarray, (n,) float64
    """
    i = rng.integers(0, tables.shape[2], size=(2, region.size))
    u = tables[region, 0, i[0]]
    theta = tables[region, 1, i[1]]
    return u, np.sin(theta), np.cos(theta)


def _ratio_grid() -> np.ndarray:
    """Wind speeds at which C/R is tabulated: uniform, plus log-spaced points around the kinks
    where LB(U) = 1 (there sqrt|LB^2 - 1| has an infinite slope)."""
    from scipy.optimize import brentq

    base = np.linspace(-40.0, 60.0, 20001)
    gb = _lb(base) ** 2 - 1.0
    pieces = [base]
    for k in np.flatnonzero(np.sign(gb[:-1]) != np.sign(gb[1:])):
        root = brentq(lambda u: _lb(u) ** 2 - 1.0, base[k], base[k + 1], xtol=1e-14)
        off = np.logspace(-12, 0, 1500)
        pieces += [root - off, root + off, np.array([root])]
    return np.unique(np.concatenate(pieces))


# C/R tabulated once (accuracy: ratio_tabulated): np.interp on a grid refined around the kinks,
# and a uniform 0.001 grid indexed directly for large batches (np.interp's search is slow there).
_U_GRID = _ratio_grid()
_RATIO_TABLE = spread_rate_ratio(_U_GRID)
_U_LO, _U_STEP, _U_N = -40.0, 1e-3, 100_001
_UNI_TABLE = spread_rate_ratio(_U_LO + _U_STEP * np.arange(_U_N))
_UNI_SLOPE = np.diff(_UNI_TABLE, append=_UNI_TABLE[-1])
#: Up to this many wind speeds, :func:`ratio_tabulated` interpolates on the refined grid.
INTERP_MAX = 256


def interp_ratio(u: np.ndarray) -> np.ndarray:
    """:func:`spread_rate_ratio` of a 1-D array by linear interpolation on the refined grid."""
    return _interp(u, _U_GRID, _RATIO_TABLE, None, None)


def ratio_tabulated(u: np.ndarray) -> np.ndarray:
    """:func:`spread_rate_ratio` of a 1-D array, read from a table (the fire's hot path).

    Up to :data:`INTERP_MAX` values: linear interpolation on a grid refined around the two kinks
    of ``sqrt|LB^2 - 1|`` (``U = 0`` and ``U = -6.219``), error below 1e-5. More values: a uniform
    0.001 grid, error below 1.5e-4 except within 0.002 of the kinks, where it stays below 0.0065
    (a wind draw lands there with probability about 1e-5).
    """
    if u.size <= INTERP_MAX:
        return _interp(u, _U_GRID, _RATIO_TABLE, None, None)
    pos = (u - _U_LO) * (1.0 / _U_STEP)
    np.clip(pos, 0.0, _U_N - 1.0, out=pos)
    i = pos.astype(np.int64)
    return _UNI_TABLE[i] + (pos - i) * _UNI_SLOPE[i]
