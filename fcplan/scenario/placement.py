"""Random placement of map objects on the 100-px grid, under the open-world GUI's rules.

A :class:`GridLayout` is a map being filled in, one kind of object after another. The scenario
generator (:mod:`fcplan.scenario.generate`) uses it. The rules are those of the manual's open-world
pages, as :func:`fcplan.scenario.validate.manual_limit_violations` checks them:

* every object sits on the grid. Its centre is the centre of the block it reserves
  (:data:`~fcplan.scenario.grid.GRID_BLOCKS`: region 1 x 1, facility 2 x 2, vertical depot 2 x 4,
  horizontal depot 4 x 2, lake 3 x 4), and the block lies inside the map;
* the depot (:func:`draw_depot`) lies on an edge: a vertical one in column A or the second-to-last
  column, a horizontal one in row 1 or the second-to-last row;
* no two objects share a grid cell, except fire regions with each other. Fire regions are placed
  first, so facilities and lakes avoid their cells;
* no two facility or depot footprints overlap. A power station's 220-px footprint overhangs its
  200-px block, so this is checked on the footprints themselves.

Each ``place_*`` method draws uniformly among the blocks that satisfy its rule. When none is left,
it raises :class:`PlacementError` naming the setting to relax, and the caller can draw the layout
again. Indices are (column, row - 1), 0-based, as in ``occupied[column, row - 1]``.

Examples
--------
>>> import numpy as np
>>> from fcplan.scenario.placement import GridLayout, draw_depot
>>> rng = np.random.default_rng(0)
>>> lay = GridLayout(800, draw_depot(rng, 800, "vertical"))
>>> lay.place_regions(rng, 2, min_depot_distance=300)
>>> lay.place_facilities(rng, {"house": 2}, distance=(150, 400))
>>> len(lay.region_cells), [f.kind for f in lay.facilities], int(lay.occupied.sum())
(2, ['house', 'house'], 18)
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from fcplan.scenario.grid import CELL_PX, GRID_BLOCKS, cell_center, format_cell, parse_cell
from fcplan.scenario.model import DEFAULT_PENALTIES, FACILITY_KINDS, Depot, Facility, Lake

__all__ = ["GridLayout", "PlacementError", "draw_depot"]


class PlacementError(Exception):
    """No block is left that satisfies a placement rule.

    Attributes
    ----------
    knob : str
        The generator setting that would have to change (e.g. ``"n_houses"``).
    what : str
        What could not be placed, and why.
    hint : str
        What to change.
    """

    def __init__(self, knob: str, what: str, hint: str):
        super().__init__(f"{knob}: {what}; {hint}")
        self.knob, self.what, self.hint = knob, what, hint


def pick(rng: np.random.Generator, mask: np.ndarray) -> tuple[int, int]:
    """A uniformly drawn index ``(column, row - 1)`` among the ``True`` entries of a 2-d mask."""
    flat = np.flatnonzero(mask)
    column, row = divmod(int(flat[int(rng.integers(flat.size))]), mask.shape[1])
    return column, row


def draw_depot(
    rng: np.random.Generator, world: int, orientation: str = "any", penalty: float = 5.0
) -> Depot:
    """A depot at a uniformly drawn position on an edge of a ``world`` px map.

    ``orientation`` is ``"vertical"``, ``"horizontal"`` or ``"any"`` (drawn first, evenly).

    Examples
    --------
    >>> d = draw_depot(np.random.default_rng(1), 1000, "horizontal")
    >>> d.orientation, d.cell[-2:] in ("01", "09")
    ('horizontal', True)
    """
    n = world // CELL_PX
    if orientation == "any":
        orientation = ("vertical", "horizontal")[int(rng.integers(2))]
    if orientation == "vertical":  # column A or the second-to-last, top-left rows 1..n-3
        spots = [(c, r) for c in (0, n - 2) for r in range(n - 3)]
    else:  # row 1 or the second-to-last, top-left columns A..n-4
        spots = [(c, r) for r in (0, n - 2) for c in range(n - 3)]
    c, r = spots[int(rng.integers(len(spots)))]
    cell = format_cell(c, r + 1)
    return Depot(cell_center(cell, f"depot_{orientation}", world), orientation, penalty, cell)


class GridLayout:
    """A map being filled in: occupied grid cells, scored footprints and the objects placed.

    Parameters
    ----------
    world : int
        Map side in px (a multiple of 100).
    depot : Depot
        Placed on the grid; its block is reserved at once.

    Attributes
    ----------
    occupied : ndarray, (n, n) bool
        Reserved cells, indexed ``[column, row - 1]``.
    region_cells : list of str
        Cells of the fire regions, in placement order.
    far_px : float
        The distance from the depot centre beyond which a cell counts as far (set by
        :meth:`place_regions`).
    facilities : list of Facility
    lakes : list of Lake
    """

    def __init__(self, world: int, depot: Depot):
        self.world, self.n = world, world // CELL_PX
        self.depot = depot
        self.occupied = np.zeros((self.n, self.n), dtype=bool)
        self.boxes = [depot.footprint]
        self.region_cells: list[str] = []
        self.far_px = 0.0
        self.facilities: list[Facility] = []
        self.lakes: list[Lake] = []
        column, row = parse_cell(depot.cell or format_cell(0, 1))
        self._reserve(f"depot_{depot.orientation}", column, row - 1)

    def _blocks(self, kind: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Free-block mask and block centres (x, y), one per possible top-left cell of ``kind``."""
        cols, rows = GRID_BLOCKS[kind]
        free = np.asarray(~sliding_window_view(self.occupied, (cols, rows)).any(axis=(2, 3)))
        c, r = np.indices(free.shape, dtype=float)
        return free, np.asarray(CELL_PX * (c + cols / 2)), np.asarray(CELL_PX * (r + rows / 2))

    def _reserve(self, kind: str, c: int, r: int) -> str:
        cols, rows = GRID_BLOCKS[kind]
        self.occupied[c : c + cols, r : r + rows] = True
        return format_cell(c, r + 1)

    def place_regions(
        self,
        rng: np.random.Generator,
        n: int,
        n_late: int = 0,
        *,
        placement: str = "uniform",
        min_depot_distance: float = 0.0,
        far_fraction: float = 0.5,
        n_clusters: int = 1,
        cluster_radius: float = 300.0,
    ) -> None:
        """Place ``n`` fire regions on free cells at least ``min_depot_distance`` px from the
        depot centre, on distinct cells while free ones remain.

        A cell is *far* when its centre lies at least ``far_fraction`` times the largest
        depot-to-cell distance from the depot centre. ``placement`` is ``"uniform"`` (any allowed
        cell), ``"far"`` (far cells only) or ``"clustered"``: ``n_clusters`` cluster cells are
        drawn among the allowed ones, and each region picks a cluster and then a cell within
        ``cluster_radius`` of it. The last ``n_late`` regions always lie on far cells, inside
        their cluster when it reaches that far.
        """
        free, x, y = self._blocks("region")
        dx, dy = self.depot.center
        dist = np.hypot(x - dx, y - dy)
        ok = free & (dist >= min_depot_distance)
        if not ok.any():
            what, hint = "leaves no grid cell for a fire region", "lower it or use a bigger map"
            raise PlacementError("min_depot_distance_px", what, hint)
        self.far_px = far_fraction * float(dist.max())
        far = ok & (dist >= self.far_px)
        if (n_late or placement == "far") and not far.any():
            what = "leaves no far grid cell for a fire region"
            raise PlacementError("far_fraction", what, "lower it or min_depot_distance_px")
        base = far if placement == "far" else ok
        clusters = []
        if placement == "clustered":
            for _ in range(n_clusters):
                c, r = pick(rng, base)
                clusters.append(np.hypot(x - x[c, r], y - y[c, r]) <= cluster_radius)
        used = np.zeros_like(ok)
        for i in range(n):
            allowed = far if i >= n - n_late else base
            if clusters:
                near = allowed & clusters[int(rng.integers(len(clusters)))]
                allowed = near if near.any() else allowed
            fresh = allowed & ~used
            c, r = pick(rng, fresh if fresh.any() else allowed)
            used[c, r] = True
            self.region_cells.append(format_cell(c, r + 1))
        for column, row in zip(*np.nonzero(used), strict=True):
            self._reserve("region", int(column), int(row))

    def place_facilities(
        self,
        rng: np.random.Generator,
        counts: Mapping[str, int],
        *,
        distance: tuple[float, float] = (0.0, float("inf")),
        penalties: Mapping[str, float] | None = None,
    ) -> None:
        """Place ``counts[kind]`` facilities of each kind (houses, hospitals, power stations, in
        that order) on free 2 x 2 blocks whose centre is ``distance = (lo, hi)`` px from the
        nearest fire region centre (``lo <= d <= hi``), with footprints overlapping nothing."""
        lo, hi = distance
        penalties = penalties or DEFAULT_PENALTIES
        nearest = None
        for kind in FACILITY_KINDS:
            x0, x1, y0, y1 = Facility.standard(kind, (0.0, 0.0)).footprint
            for k in range(counts.get(kind, 0)):
                free, x, y = self._blocks(kind)
                if nearest is None:
                    nearest = np.full(free.shape, np.inf)
                    for cell in self.region_cells:
                        rx, ry = cell_center(cell, "region", self.world)
                        nearest = np.minimum(nearest, np.hypot(x - rx, y - ry))
                ok = free & (nearest >= lo) & (nearest <= hi)
                for bx0, bx1, by0, by1 in self.boxes:
                    ok &= ~((x + x0 < bx1) & (bx0 < x + x1) & (y + y0 < by1) & (by0 < y + y1))
                if not ok.any():
                    what = f"no free block {lo:g}..{hi:g} px from a fire region for {kind} {k + 1}"
                    hint = "ask for fewer, a bigger map or a wider facility_fire_distance_px"
                    raise PlacementError(f"n_{kind}s", what, hint)
                cell = self._reserve(kind, *pick(rng, ok))
                center = cell_center(cell, kind, self.world)
                f = Facility.standard(kind, center, cell=cell, penalty=penalties[kind])
                self.facilities.append(f)
                self.boxes.append(f.footprint)

    def place_lakes(self, rng: np.random.Generator, n: int) -> None:
        """Place ``n`` lakes on free 3 x 4 blocks."""
        for k in range(n):
            free, _, _ = self._blocks("lake")
            if not free.any():
                what, hint = (
                    f"no free 3 x 4 block for lake {k + 1}",
                    "ask for fewer or a bigger map",
                )
                raise PlacementError("n_lakes", what, hint)
            cell = self._reserve("lake", *pick(rng, free))
            self.lakes.append(Lake(cell_center(cell, "lake", self.world), cell))
