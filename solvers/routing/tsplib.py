"""TSPLIB instances for checking routing solvers against known optima.

TSPLIB (Reinelt 1991) is the classic library of travelling-salesman benchmarks. This module reads
symmetric instances given by ``NODE_COORD_SECTION`` coordinates and ``TOUR_SECTION`` tours, with
TSPLIB's integer distances (the published optima are computed with them):

=========  ===============================================================================
type       ``d(i, j)``
=========  ===============================================================================
EUC_2D     ``nint(r)``, ``r = sqrt(dx^2 + dy^2)``
ATT        ``t = nint(r')``, ``r' = sqrt((dx^2 + dy^2) / 10)``; ``t + 1`` if ``t < r'`` else ``t``
GEO        ``int(6378.388 * acos(((1 + q1) q2 - (1 - q1) q3) / 2) + 1)`` on latitudes and
           longitudes read as ``DDD.MM`` (degrees, minutes; TSPLIB's pi = 3.141592),
           ``q1 = cos(lon_i - lon_j)``, ``q2 = cos(lat_i - lat_j)``, ``q3 = cos(lat_i + lat_j)``
=========  ===============================================================================

:data:`OPTIMA` holds the published optimal tour lengths of the instances the test suite ships
(``tests/solvers/data/tsplib/``, with their optimal tours).

Posed as :func:`solvers.routing.solve_routes`: one vehicle starting and ending at city 1, every
other city a required task, the closing leg charged (``charge_return=True``).

Examples
--------
>>> import io
>>> text = '''NAME : square
... TYPE : TSP
... DIMENSION : 4
... EDGE_WEIGHT_TYPE : EUC_2D
... NODE_COORD_SECTION
... 1 0 0
... 2 0 3
... 3 4 3
... 4 4 0
... EOF
... '''
>>> dist = read_tsplib(io.StringIO(text))
>>> float(dist[0, 2]), tour_length(dist, [0, 1, 2, 3])
(5.0, 14.0)
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import IO

import numpy as np

__all__ = ["OPTIMA", "read_coords", "read_tour", "read_tsplib", "tour_length", "tsplib_distances"]

#: Published optimal tour lengths (TSPLIB's ``STSP.html`` table).
OPTIMA = {
    "ulysses22": 7013,
    "att48": 10628,
    "eil51": 426,
    "berlin52": 7542,
    "st70": 675,
    "eil76": 538,
    "kroA100": 21282,
    "rd100": 7910,
    "ch130": 6110,
    # a validation set, outside bench_tsplib.py's target table: settings are chosen on these
    "pr76": 108159,
    "kroC100": 20749,
    "kroD100": 21294,
    "eil101": 629,
    "lin105": 14379,
}


def _lines(src: str | Path | IO[str]) -> list[str]:
    if isinstance(src, (str, Path)):
        return Path(src).read_text().splitlines()
    return src.read().splitlines()


def _section(lines: list[str], name: str) -> list[list[str]]:
    """The whitespace-split rows after the line starting with ``name``, up to ``EOF`` or -1."""
    start = next(i for i, ln in enumerate(lines) if ln.strip().startswith(name))
    rows = []
    for ln in lines[start + 1 :]:
        parts = ln.split()
        if not parts or parts[0] in ("EOF", "-1") or not parts[0].lstrip("-").isdigit():
            break
        rows.append(parts)
    return rows


def read_coords(src: str | Path | IO[str]) -> tuple[np.ndarray, str]:
    """``(coords (n, 2), edge weight type)`` of a TSPLIB file (a path or a text stream)."""
    lines = _lines(src)
    header = {k.strip(): v.strip() for k, _, v in (ln.partition(":") for ln in lines) if _ and v}
    kind = header.get("EDGE_WEIGHT_TYPE", "")
    if kind not in ("EUC_2D", "ATT", "GEO"):
        raise ValueError(f"only EUC_2D, ATT and GEO instances, got {kind!r}")
    rows = _section(lines, "NODE_COORD_SECTION")
    return np.array([[float(r[1]), float(r[2])] for r in rows]), kind


def read_tsplib(src: str | Path | IO[str]) -> np.ndarray:
    """``(n, n)`` TSPLIB distances of a TSPLIB file (see the module docstring)."""
    xy, kind = read_coords(src)
    return tsplib_distances(xy, kind)


def tsplib_distances(xy: np.ndarray, kind: str = "EUC_2D") -> np.ndarray:
    """``(n, n)`` TSPLIB distances of coordinates ``xy`` (see the module docstring)."""
    if kind == "GEO":
        deg = np.trunc(xy)
        rad = 3.141592 * (deg + 5.0 * (xy - deg) / 3.0) / 180.0
        lat, lon = rad[:, 0], rad[:, 1]
        q1 = np.cos(lon[:, None] - lon[None, :])
        q2 = np.cos(lat[:, None] - lat[None, :])
        q3 = np.cos(lat[:, None] + lat[None, :])
        arg = np.clip(0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3), -1.0, 1.0)
        geo: np.ndarray = np.trunc(6378.388 * np.arccos(arg) + 1.0)
        np.fill_diagonal(geo, 0.0)
        return geo
    diff = xy[:, None, :] - xy[None, :, :]
    sq = (diff**2).sum(axis=2)
    if kind == "ATT":
        r = np.sqrt(sq / 10.0)
        t = np.floor(r + 0.5)
        att: np.ndarray = np.where(t < r, t + 1.0, t)
        return att
    out: np.ndarray = np.floor(np.sqrt(sq) + 0.5)
    return out


def read_tour(src: str | Path | IO[str]) -> list[int]:
    """The 0-based city order of a TSPLIB ``.tour`` file (any number of cities per line)."""
    rows = _section(_lines(src), "TOUR_SECTION")
    return [int(c) - 1 for r in rows for c in r if int(c) > 0]


def tour_length(dist: np.ndarray, tour: Sequence[int]) -> float:
    """Length of the closed tour visiting ``tour`` in order and returning to its first city."""
    t = np.asarray(tour, dtype=np.int64)
    return float(dist[t, np.roll(t, -1)].sum())
