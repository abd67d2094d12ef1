"""Coarse maps and egocentric crops for the motion-level environment.

The motion environment observes the 1-px world through **coarse cells** of ``cell_px`` px. The
maps it crops from are kept per coarse cell and updated *incrementally* from each tick's
:class:`fcplan.world.StepInfo` (cells ignited, sensed for the first time, pruned; fields of view),
so a tick never scans the full grid. All agents' crops come from one fancy-indexed gather on a
``sliding_window_view`` of a padded stack of maps.

Layers of :attr:`CoarseMaps.grid` (``(L, H, H)`` float32, ``H = ceil(W / cell_px) + 2 r``,
``r = view // 2`` cells of padding):

===  ==============  =====================================================================
 0   ``known``       known burning px in the cell (sensed, not yet pruned) / ``cell_px``,
                     clipped to 1 (the count itself is layer 8, ``known_n``)
 1   ``pruned``      pruned px in the cell / ``cell_px``, clipped to 1 (count: layer 9)
 2   ``stale``       staleness ``min(1, seen + tick * seen_scale)`` at the tick of the last
                     :meth:`CoarseMaps.observe` in the rows its crops spanned (1 before the
                     first; 1 in the padding; :meth:`CoarseMaps.staleness` for the map), from
                     :attr:`CoarseMaps.seen`: minus the tick the cell last overlapped a sensing
                     agent's field of view, times ``seen_scale`` (``+inf``: never, and outside
                     the map)
 3   ``agents``      1 where at least one agent is (see :meth:`CoarseMaps.place_agents`)
 4   ``outside``     share of the cell outside the map (1 in the padding)
 5   ``lake``        share of the cell covered by a lake
 6   ``facility``    share of the cell inside a scored facility (incl. the depot),
                     weighted by its penalty / 5
 7   ``burning``     true burning px in the cell (global state only; read it through
                     :meth:`CoarseMaps.burning_layer`)
 8   ``known_n``     known burning px in the cell
 9   ``pruned_n``    pruned px in the cell
===  ==============  =====================================================================

Layers 0-1 are kept scaled and clipped (updated with their counts, a few cells per tick), and
layer 3 as 0/1; :meth:`CoarseMaps.observe` recomputes layer 2 over the rows the crops span
(two operations on one contiguous run, cheaper than the same on the strided crop channel), so
the crops need no arithmetic (only one write per agent: whether another agent shares its cell).

Examples
--------
>>> import numpy as np
>>> from fcplan import World, load_scenario
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> maps = CoarseMaps(world.scenario, cell_px=20, view=5)
>>> maps.grid.shape
(10, 64, 64)
>>> info = world.step()
>>> maps.update(info, world)
>>> win = maps.gather(np.array([[0.0, 0.0]]))  # (L, N, view, view) around (0, 0)
>>> win.shape, float(win[OUTSIDE, 0, 0, 0]), float(win[OUTSIDE, 0, 2, 2])
((10, 1, 5, 5), 1.0, 0.0)
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from fcplan.shared_views import KeepsViews

if TYPE_CHECKING:
    from fcplan.scenario import Scenario
    from fcplan.world import StepInfo, World

__all__ = [
    "CoarseMaps",
    "KNOWN",
    "PRUNED",
    "LAST_SEEN",
    "AGENTS",
    "OUTSIDE",
    "LAKE",
    "FACILITY",
    "BURNING",
    "KNOWN_N",
    "PRUNED_N",
]

KNOWN, PRUNED, LAST_SEEN, AGENTS, OUTSIDE, LAKE, FACILITY, BURNING, KNOWN_N, PRUNED_N = range(10)
N_LAYERS = 10
#: the count layer behind each scaled layer
_COUNT_OF = {KNOWN: KNOWN_N, PRUNED: PRUNED_N}
#: changes of up to this many cells are applied one by one (cheaper than np.add.at)
_SMALL = 16
#: maps up to this many px use a cached px -> coarse-cell lookup table (4 bytes per px)
_LUT_MAX_PX = 2048 * 2048
_ONE32 = np.float32(1.0)


@lru_cache(maxsize=4)
def _lookup(w: int, c: int, r: int, h: int) -> np.ndarray:
    """(W * W,) int32: flat px index ``x * W + y`` -> flat index of its cell in a padded layer."""
    cx = np.arange(w, dtype=np.int32) // c + r
    return ((cx[:, None] * h) + cx[None, :]).reshape(-1)


def _block_share(mask: np.ndarray, c: int, nc: int) -> np.ndarray:
    """(nc, nc) share of each ``c x c`` block of a (W, W) array that is set (cells past the
    map edge count as unset)."""
    w = mask.shape[0]
    pad = np.zeros((nc * c, nc * c), dtype=np.float64)
    pad[:w, :w] = mask
    return pad.reshape(nc, c, nc, c).sum(axis=(1, 3)) / float(c * c)


class CoarseMaps(KeepsViews):
    """Padded coarse maps of one episode, updated once per tick.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    cell_px : int
        Side of a coarse cell in px.
    view : int
        Side of the square crop in coarse cells (odd).
    seen_scale : float
        Staleness per tick (``1 / ticks to become fully stale``).
    """

    def __init__(
        self, scenario: Scenario, cell_px: int, view: int, seen_scale: float = 1.0
    ) -> None:
        w = scenario.world_size
        c = int(cell_px)
        self.world_size, self.cell_px, self.view = w, c, int(view)
        self.seen_scale = float(seen_scale)
        self._inv_c = 1.0 / c  # a Python float: the fastest scalar for numpy
        self.radius = r = self.view // 2
        self.nc = nc = -(-w // c)
        self.grid = np.zeros((N_LAYERS, nc + 2 * r, nc + 2 * r), dtype=np.float32)
        #: (L, nc, nc) view of the map part of :attr:`grid`
        self.inner = self.grid[:, r : r + nc, r : r + nc]
        #: (H, H) float32: minus the tick each cell was last seen, times ``seen_scale``
        self.seen = np.full(self.grid.shape[1:], np.inf, dtype=np.float32)
        self._seen = self.seen[r : r + nc, r : r + nc]
        self._seen_flat = self.seen.reshape(-1)
        #: the agents layer, flat, from the first map cell: cell (cx, cy) is at cx * H + cy
        self._agents_flat = self.grid[AGENTS].reshape(-1)[r * (nc + 2 * r + 1) :]
        self._stale_flat = self.grid[LAST_SEEN].reshape(-1)  # (a view: the grid is contiguous)
        self._static = self._static_layers(scenario)
        #: (L, H-view+1, H-view+1, view, view) windows; a crop is ``windows[:, cx, cy]``
        self.windows = sliding_window_view(self.grid, (self.view, self.view), axis=(1, 2))
        h = self.grid.shape[1]
        self._h = h
        #: per layer, a flat view of the padded grid
        self.flat = [self.grid[k].reshape(-1) for k in range(N_LAYERS)]
        self._lut = _lookup(w, c, r, h) if w * w <= _LUT_MAX_PX else None
        self._win_cache: dict[int, np.ndarray] = {}
        #: per agent, whether its field of view counts as camera coverage
        self._sensing = [a.role.can_sense for a in scenario.agents]
        self._sensing_rows = [j for j, f in enumerate(self._sensing) if f]
        self.reset()

    def _static_layers(self, scenario: Scenario) -> np.ndarray:
        w, c, nc = self.world_size, self.cell_px, self.nc
        static = np.zeros((3, nc, nc), dtype=np.float32)
        inside = np.ones((w, w), dtype=bool)
        static[0] = 1.0 - _block_share(inside, c, nc)
        xs = np.arange(w, dtype=np.float64)
        lake = np.zeros((w, w), dtype=bool)
        for lk in scenario.lakes:
            for cx, cy, rad in lk.circles:
                dx = (xs - cx)[:, None] ** 2
                dy = (xs - cy)[None, :] ** 2
                lake |= dx + dy <= rad * rad
        static[1] = _block_share(lake, c, nc)
        fac = np.zeros((w, w), dtype=np.float64)
        for f in scenario.scored_facilities:
            x0, x1, y0, y1 = f.footprint
            inx = (xs > x0) & (xs < x1)
            iny = (xs > y0) & (xs < y1)
            fac = np.maximum(fac, (inx[:, None] & iny[None, :]) * min(f.penalty / 5.0, 1.0))
        static[2] = _block_share(fac, c, nc)
        return static

    def reset(self) -> None:
        """Empty fire layers, never-seen cells, static layers restored."""
        g = self.grid
        g[:] = 0.0
        g[OUTSIDE] = 1.0
        g[LAST_SEEN] = 1.0
        self.seen[:] = np.inf
        self.inner[OUTSIDE : FACILITY + 1] = self._static
        self._agent_cells: list[int] = []
        #: per agent placed by :meth:`place_agents`: 1.0 if another agent shares its cell (or
        #: 0.0 alone: no agent shares one)
        self.shared: list[float] | float = 0.0
        #: cells that started burning, and cells pruned, not yet on the burning layer
        self._pending: list[np.ndarray] = []
        self._pending_out: list[np.ndarray] = []

    def padded_index(self, flat: np.ndarray) -> np.ndarray:
        """Flat px indices ``x * W + y`` -> flat indices into one padded layer of :attr:`grid`."""
        if self._lut is not None:
            return self._lut[flat]
        w, c, r = self.world_size, self.cell_px, self.radius
        return (flat // w // c + r) * self._h + (flat % w // c + r)

    def _add(self, layer: int, flat: np.ndarray, sign: float) -> None:
        """Add ``sign`` per px of ``flat`` to ``layer`` (a scaled layer: to its count, then
        rescale the cells touched)."""
        n = flat.size
        if n == 0:
            return
        idx = self.padded_index(flat)
        scaled = self.flat[layer] if layer in _COUNT_OF else None
        if scaled is not None:
            layer = _COUNT_OF[layer]
        grid = self.flat[layer]
        if n > _SMALL:
            np.add.at(grid, idx, sign)
            if scaled is not None:  # (float32 count * Python float, as a float32 array op)
                scaled[idx] = np.minimum(grid[idx] * self._inv_c, 1.0)
            return
        # a few cells: scalar updates beat np.add.at's setup
        for j in idx.tolist():
            grid[j] += sign
            if scaled is not None:
                scaled[j] = min(grid[j] * self._inv_c, 1.0)

    def update(self, info: StepInfo, world: World) -> None:
        """Fold one tick (:class:`fcplan.world.StepInfo`) of ``world`` into the maps."""
        if info.ignited.size:  # the burning layer is folded in on demand (burning_layer)
            self._pending.append(info.ignited)
        if info.newly_sensed.size:
            self._add(KNOWN, info.newly_sensed, 1.0)
        pruned = info.pruned
        if pruned.size:
            self._pending_out.append(pruned)
            self._add(PRUNED, pruned, 1.0)
            seen = pruned[world.sensed.reshape(-1)[pruned]]
            self._add(KNOWN, seen, -1.0)
        self._cover(info.fov_rects, self._sensing_rows, -float(self.stamp(info.tick)))
        if len(self._pending) + len(self._pending_out) > 512:
            self.burning_layer()

    def burning_layer(self) -> np.ndarray:
        """(nc, nc) true burning px per coarse cell (a view of :attr:`grid`, brought up to
        date first: per tick the changes are only queued, as observations do not need them;
        the queued cells go in with one ``np.add.at`` per sign, exact as the counts are whole
        numbers)."""
        for queue, sign in ((self._pending, 1.0), (self._pending_out, -1.0)):
            if queue:
                flat = queue[0] if len(queue) == 1 else np.concatenate(queue)
                self._add(BURNING, flat, sign)
                queue.clear()
        return self.inner[BURNING]

    def cover(self, rects: list, tick: int, which: list | None = None) -> None:
        """Mark the coarse cells overlapping each ``[x0, x1, y0, y1]`` rectangle as seen now
        (only the rectangles whose flag in ``which`` is true, if given)."""
        rows = range(len(rects)) if which is None else [j for j, f in enumerate(which) if f]
        self._cover(rects, rows, -float(np.float32(tick * self.seen_scale)))

    def _cover(self, rects: list[list[float]], rows: Iterable[int], value: float) -> None:
        """:meth:`cover` of the rectangles ``rects[j]`` for ``j`` in ``rows`` with ``value``."""
        c = self.cell_px
        seen = self._seen  # slicing stops at the map's far edges by itself
        for j in rows:
            x0, x1, y0, y1 = rects[j]
            if x1 < 0 or y1 < 0:
                continue
            i0, i1 = int(x0 // c), int(x1 // c) + 1
            j0, j1 = int(y0 // c), int(y1 // c) + 1
            seen[i0 if i0 > 0 else 0 : i1, j0 if j0 > 0 else 0 : j1] = value

    def stamp(self, tick: int) -> np.float32:
        """``tick * seen_scale`` as float32 (add it to :attr:`seen` to get staleness)."""
        return np.float32(tick * self.seen_scale)

    def staleness(self, tick: int) -> np.ndarray:
        """(nc, nc) float32 staleness of the map's cells at ``tick`` (a fresh array)."""
        return np.minimum(self._seen + self.stamp(tick), 1.0)

    def place_agents(self, cx: list, cy: list) -> None:
        """Mark the coarse cells ``(cx[i], cy[i])`` (lists of int inside the map) on the ``agents``
        layer (1 where at least one agent is), replacing the previous placement, and note per
        agent in :attr:`shared` whether another agent is in its cell (a loop over agents: a
        handful of scalar writes beat numpy's fancy indexing here)."""
        h = self._h
        cells = [x * h + y for x, y in zip(cx, cy, strict=True)]
        if cells == self._agent_cells:  # nobody changed cell
            return
        layer = self._agents_flat
        for c in self._agent_cells:
            layer[c] = 0.0
        for c in cells:
            layer[c] = 1.0
        if len(set(cells)) == len(cells):  # (the usual case: nobody shares a cell)
            self.shared = 0.0
        else:
            count: dict[int, int] = {}
            for c in cells:
                count[c] = count.get(c, 0) + 1
            self.shared = [1.0 if count[c] > 1 else 0.0 for c in cells]
        self._agent_cells = cells

    def cells(self, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Coarse cell (cx, cy) of each position (clipped to the map)."""
        idx = (pos // self.cell_px).astype(np.int64)
        np.clip(idx, 0, self.nc - 1, out=idx)
        return idx[:, 0], idx[:, 1]

    def crops(self, cx: list, cy: list, layers: int) -> np.ndarray:
        """(N, layers, view, view) crops of the first ``layers`` layers centred on coarse cells
        ``(cx[i], cy[i])`` (lists of int inside the map; a fresh C-contiguous array, one
        fancy-indexed gather of the windows)."""
        return self._windows(layers)[cx, cy]

    def _windows(self, layers: int) -> np.ndarray:
        """:attr:`windows` of the first ``layers`` layers with the layer axis third, ``(H-view+1,
        H-view+1, layers, view, view)`` (cached): ``_windows(k)[cx, cy]`` gathers the crops of
        cells ``(cx[i], cy[i])`` as one fresh ``(N, k, view, view)`` array."""
        win = self._win_cache.get(layers)
        if win is None:
            win = self._win_cache[layers] = np.moveaxis(self.windows[:layers], 0, 2)
        return win

    def observe(self, cx: list, cy: list, tick: int, layers: int) -> np.ndarray:
        """The agents' observation crops at ``tick``: (N, layers, view, view) float32 with
        ``layers >= 4``, a fresh C-contiguous array.

        Places the agents of coarse cells ``(cx[i], cy[i])`` (:meth:`place_agents`), brings the
        ``stale`` layer to ``tick`` (``min(1, seen + tick * seen_scale)``) in the rows the crops
        span, crops the first ``layers`` layers around each agent and sets each crop's centre
        on ``agents`` to whether *another* agent shares the cell.
        """
        self.place_agents(cx, cy)
        # the rows of the padded layers the crops span, as one contiguous run of cells
        h = self._h
        lo, hi = (min(cx) * h, (max(cx) + self.view) * h) if cx else (0, 0)
        stale = self._stale_flat[lo:hi]
        np.add(self._seen_flat[lo:hi], np.float32(tick * self.seen_scale), out=stale)
        np.minimum(stale, _ONE32, out=stale)
        out = self._windows(layers)[cx, cy]  # (one gather of all the windows)
        r = self.radius
        out[:, AGENTS, r, r] = self.shared
        return out

    def gather(self, pos: np.ndarray) -> np.ndarray:
        """(L, N, view, view) crops centred on the coarse cells of ``pos`` (a fresh array)."""
        cx, cy = self.cells(pos)
        return self.windows[:, cx, cy]
