"""FARSITE fronts of ``B`` worlds stepped together: :mod:`fcplan.fire`'s rule with a batch axis.

Every world has the scenario's ``n`` fronts (one scenario per batch, so fronts are not ragged):
positions ``x, y`` are ``(B, n)`` float64, ``alive``/``frozen`` ``(B, n)`` bool, ``cell`` the
flat ``x W + y`` of each front's cell, ``region_active`` ``(B, R)``, ``n_steps`` ``(B,)``. A fire
step gathers the moving fronts of every world into one flat array (index ``b n + f``), moves them
with the world's wind row of the step, kills the ones that leave the map, freezes those landing on
pruned cells and ignites the unburnt cells they land on; everything is one numpy call over all
worlds' fronts.

Bit-identity with :class:`fcplan.fire.Fire` of the same seed:

* the ignition points and (in the tables model) the wind tables are drawn at a world's reset by
  the same calls on the world's own fire generator; the terrain is skipped and read on demand
  (:class:`fcplan.batch.streams.TerrainJump`), each front keeping the value of its last terrain
  cell, since it stays in the same rounded cell on about three steps in four;
* the wind of the next ``L`` steps is drawn ahead per world by the single fire's own kernels
  (:func:`fcplan._fast.fire.draw_ahead`, ``draw_ahead_tables``) on buffers of the same shape,
  block by block at the steps where the single fire refills (step ``1 + k L``): the sines,
  cosines and ``C/R`` come from the same calls on the same arrays; in the tables model the
  worlds refilling at one step draw their table indices with the same call each, and the
  lookups are one gather for all of them (tested bit-equal to the kernel);
* the per-step arithmetic is the rule's, ``C = terrain * fuel * (C/R)``, ``x += C sin``,
  ``y += C cos``, element by element (correctly rounded operations only); ``C/R`` of the fresh
  model with more than :data:`fcplan.farsite.INTERP_MAX` fronts is computed the way the single
  fire picks for that world (interpolation when at most ``INTERP_MAX`` of them move);
* the front visits behind :meth:`fcplan.fire.Fire.intensity` are not kept (no rule reads them).

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> from fcplan.batch.cells import CellGrid
>>> sc = load_scenario("practice")
>>> fire = BatchFire(sc, 3, CellGrid(3, sc.world_size))
>>> for b, s in enumerate([5, 6, 7]):
...     fire.reset_world(b, np.random.default_rng(s))
>>> for _ in range(20):
...     new = fire.step(np.ones(3, dtype=bool))
>>> fire.n_steps.tolist(), bool((fire.n_burning > 0).all())
([20, 20, 20], True)
"""

from __future__ import annotations

import math

import numpy as np

from fcplan._fast.fire import draw_ahead, draw_ahead_tables, unique
from fcplan.batch.cells import SENSED, STATE_BITS, CellGrid, runs
from fcplan.batch.streams import TerrainJump
from fcplan.farsite import (
    INTERP_MAX,
    WIND_DIR_SD_RAD,
    WIND_SPEED_SD,
    interp_ratio,
    ratio_tabulated,
    spread_rate_ratio,
    wind_tables,
)
from fcplan.fire import _PRE_TICKS, _PRE_VALUES, BURNING, PRUNED, STEPS_PER_SECOND, UNBURNT
from fcplan.scenario import Scenario

__all__ = ["BatchFire"]

_NEVER = 2**62
_EMPTY = np.zeros(0, dtype=np.int64)
#: cells as ``(world, x, y)`` int64 arrays
Cells = tuple[np.ndarray, np.ndarray, np.ndarray]


class BatchFire:
    """The fires of ``num`` worlds of ``scenario`` (module docstring).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    num : int
        Worlds ``B``.
    grid : fcplan.batch.cells.CellGrid
        The cells the fronts burn (shared with the world, which marks sensing there).
    """

    def __init__(self, scenario: Scenario, num: int, grid: CellGrid) -> None:
        regions = scenario.regions
        self.num, self.grid = int(num), grid
        self.world_size = w = scenario.world_size
        self._shift = int(w - 1).bit_length()
        self._mask = (1 << self._shift) - 1
        self.ticks_per_second = scenario.ticks_per_second
        n_per = np.array([int(r.fronts) for r in regions], dtype=np.int64)
        self.region = np.repeat(np.arange(len(regions), dtype=np.int64), n_per)
        self.n = n = int(n_per.sum())
        lo = np.array([[r.center[0] - r.half_width, r.center[1] - r.half_width] for r in regions])
        hi = np.array([[r.center[0] + r.half_width, r.center[1] + r.half_width] for r in regions])
        self._lo = np.repeat(lo, n_per, axis=0).astype(np.int64).reshape(n, 2)
        self._hi = np.repeat(hi, n_per, axis=0).astype(np.int64).reshape(n, 2)
        per = np.array(
            [[r.fuel, r.wind_speed, math.radians(r.wind_dir_deg)] for r in regions], np.float64
        ).reshape(-1, 3)
        self._per = per
        self.fuel = per[self.region, 0]
        self._wind, self._theta = per[self.region, 1], per[self.region, 2]
        self.start_step = np.array(
            [math.ceil(r.delay_s * STEPS_PER_SECOND - 1e-9) for r in regions], np.int64
        )
        self.tables = scenario.wind_model == "tables"
        self.jump = TerrainJump(w + 1)
        self.pre_len = length = max(1, min(_PRE_TICKS, _PRE_VALUES // max(n, 1)))
        self.with_ratio = n <= INTERP_MAX or self.tables
        b = self.num
        self.pre_z = np.zeros((b, length, 2, n))
        self.pre_sc = np.zeros((b, length, 2, n))
        self.pre_ratio = np.zeros((b, length, n)) if self.with_ratio else None
        n_tab = len(regions) * w if self.tables else 0
        self._tab = np.zeros((b, 4, n_tab))
        self._tab_base = self.region * w
        self.rngs: list[np.random.Generator | None] = [None] * b
        self.x, self.y = np.zeros((b, n)), np.zeros((b, n))
        self.alive = np.zeros((b, n), dtype=bool)
        self.frozen = np.zeros((b, n), dtype=bool)
        self.cell = np.zeros((b, n), dtype=np.int64)
        self.region_active = np.zeros((b, len(regions)), dtype=bool)
        self.n_steps = np.zeros(b, dtype=np.int64)
        self.next_wake = np.full(b, _NEVER, dtype=np.int64)
        self.terrain_base = np.zeros((b, 6), dtype=np.uint64)
        self._t_cell = np.full((b, n), -1, dtype=np.int64)
        self._t_val = np.zeros((b, n))
        self.n_burning = np.zeros(b, dtype=np.int64)
        self.n_pruned = np.zeros(b, dtype=np.int64)
        self.n_ignited = np.zeros(b, dtype=np.int64)
        #: (B, 4) ``[x0, x1, y0, y1]`` inclusive box around every burning cell (empty: x0 > x1)
        self.burn_box = np.tile(np.array([w, -1, w, -1], dtype=np.int64), (b, 1))

    # ------------------------------------------------------------------ reset
    def reset_world(self, b: int, rng: np.random.Generator) -> None:
        """Start world ``b``'s fire on the fire stream ``rng``, drawing what
        :class:`fcplan.fire.Fire` draws at construction, in its order."""
        w, n = self.world_size, self.n
        pts = rng.integers(self._lo, self._hi, size=(n, 2))
        x, y = pts[:, 0].astype(np.float64), pts[:, 1].astype(np.float64)
        self.x[b], self.y[b] = x, y
        self.alive[b] = (x >= 0) & (x < w) & (y >= 0) & (y < w)
        self.terrain_base[b] = self.jump.skip(rng)
        if self.tables:
            tab = wind_tables(rng, self._per[:, 1], self._per[:, 2], w)
            u = np.ascontiguousarray(tab[:, 0]).reshape(-1)
            theta = np.ascontiguousarray(tab[:, 1]).reshape(-1)
            self._tab[b] = (u, np.sin(theta), np.cos(theta), spread_rate_ratio(u))
        self.rngs[b] = rng
        cx = np.clip(x, 0, w - 1).astype(np.int64)
        cy = np.clip(y, 0, w - 1).astype(np.int64)
        self.cell[b] = np.where(self.alive[b], cx * w + cy, 0)
        self.frozen[b] = False
        self.region_active[b] = False
        self.n_steps[b] = 0
        self.next_wake[b] = int(self.start_step.min()) if self.start_step.size else _NEVER
        self._t_cell[b] = -1
        self.n_burning[b] = self.n_pruned[b] = self.n_ignited[b] = 0
        self.burn_box[b] = (w, -1, w, -1)

    # ------------------------------------------------------------------ step
    def steps_due(self, tick: np.ndarray) -> np.ndarray:
        """(B,) fire steps each world takes in the tick that ends at ``tick`` (the fire's clock,
        :mod:`fcplan.fire`)."""
        return tick * STEPS_PER_SECOND // self.ticks_per_second - self.n_steps

    def step(self, take: np.ndarray) -> Cells:
        """One fire step of the worlds ``take`` ((B,) bool); return the cells that started
        burning as ``(world, x, y)`` (sorted by world, unique)."""
        self.n_steps += take
        parts = []
        waking = take & (self.n_steps >= self.next_wake)
        if np.count_nonzero(waking):
            parts.append(self._wake(waking))
        row = (self.n_steps - 1) % self.pre_len
        due = np.flatnonzero(take & (row == 0))
        if due.size:
            self._refill_worlds(due)
        moving = self.alive & ~self.frozen
        moving &= self.region_active[:, self.region]
        moving &= take[:, None]
        mi = np.flatnonzero(moving)
        if mi.size:
            parts.append(self._advance(mi, row))
        if not parts:
            return _EMPTY, _EMPTY, _EMPTY
        if len(parts) == 1:
            return parts[0]
        wb, x, y = (np.concatenate(p) for p in zip(*parts, strict=True))
        order = np.argsort(wb, kind="stable")  # (per world: the woken regions' cells first)
        return wb[order], x[order], y[order]

    def _wake(self, waking: np.ndarray) -> Cells:
        """Activate the regions of worlds ``waking`` whose delay has passed and ignite the
        cells of their live fronts."""
        new = ~self.region_active & (self.start_step <= self.n_steps[:, None]) & waking[:, None]
        self.region_active |= new
        wb = np.flatnonzero(waking)
        later = np.where(self.region_active[wb], _NEVER, self.start_step)
        self.next_wake[wb] = later.min(axis=1, initial=_NEVER)
        fronts = self.alive & new[:, self.region]
        b, f = np.nonzero(fronts)
        if b.size == 0:
            return _EMPTY, _EMPTY, _EMPTY
        x, y = np.divmod(self.cell[b, f], self.world_size)
        return self.ignite(b, x, y)

    def _refill(self, b: int) -> None:
        """Draw world ``b``'s wind of its next ``L`` steps (the single fire's ``_refill``)."""
        rng = self.rngs[b]
        assert rng is not None
        ratio = None if self.pre_ratio is None else self.pre_ratio[b]
        if self.tables:
            assert ratio is not None
            tab = self._tab[b]
            draw_ahead_tables(
                rng, self.pre_z[b], self.pre_sc[b], ratio, self._tab_base, self.world_size, *tab
            )
            return
        sd = (WIND_SPEED_SD, WIND_DIR_SD_RAD)
        draw_ahead(
            rng, self.pre_z[b], self.pre_sc[b], ratio, self._wind, self._theta, *sd, interp_ratio
        )

    def _refill_worlds(self, worlds: np.ndarray) -> None:
        """:meth:`_refill` of each world of ``worlds`` (distinct): in the tables model the draws
        are one generator call per world and the table lookups one gather for all of them (the
        same values :func:`~fcplan._fast.fire.draw_ahead_tables` picks), else world by world."""
        if not self.tables or worlds.size == 1:
            for b in worlds.tolist():
                self._refill(b)
            return
        shape = self.pre_z.shape[1:]
        w = self.world_size
        rngs = [self.rngs[b] for b in worlds.tolist()]
        idx = np.stack([g.integers(0, w, size=shape) for g in rngs if g is not None])
        idx += self._tab_base
        n_tab = self._tab.shape[2]
        at = (worlds * (4 * n_tab))[:, None, None]
        i_u, i_dir = idx[:, :, 0] + at, idx[:, :, 1] + at
        tab = self._tab.reshape(-1)
        assert self.pre_ratio is not None
        self.pre_z[worlds, :, 0] = tab[i_u]
        self.pre_ratio[worlds] = tab[i_u + 3 * n_tab]
        self.pre_sc[worlds, :, 0] = tab[i_dir + n_tab]
        self.pre_sc[worlds, :, 1] = tab[i_dir + 2 * n_tab]

    def _ratio(self, wb: np.ndarray, f: np.ndarray, r: np.ndarray) -> np.ndarray:
        """C/R of moving fronts ``(wb, f)`` on their rows ``r`` of the wind drawn ahead."""
        n = self.n
        if self.pre_ratio is not None:
            return self.pre_ratio.reshape(-1)[(wb * self.pre_len + r) * n + f]
        u = self.pre_z.reshape(-1)[((wb * self.pre_len + r) * 2) * n + f]
        counts = np.bincount(wb, minlength=self.num)
        small = (counts <= INTERP_MAX)[wb]  # the single fire interpolates for few movers
        out = np.empty(u.size)
        if np.count_nonzero(small):
            out[small] = interp_ratio(u[small])
        if not small.all():
            out[~small] = ratio_tabulated(u[~small])  # (more than INTERP_MAX values)
        return out

    def _terrain(self, mi: np.ndarray, wb: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Terrain at the rounded positions of moving fronts ``mi`` (flat ``b n + f``)."""
        tk = np.rint(x).astype(np.int64) * (self.world_size + 1) + np.rint(y).astype(np.int64)
        t_cell, t_val = self._t_cell.reshape(-1), self._t_val.reshape(-1)
        val = t_val[mi]
        new = np.flatnonzero(t_cell[mi] != tk)
        if new.size:
            v = self.jump.values(self.terrain_base[wb[new]], tk[new])
            val[new] = v
            t_cell[mi[new]] = tk[new]
            t_val[mi[new]] = v
        return val

    def _advance(self, mi: np.ndarray, row: np.ndarray) -> Cells:
        """Move the fronts ``mi`` (flat ``b n + f``) one FARSITE step; kill, freeze and ignite
        as the rule does; return the ignited cells."""
        n, w = self.n, self.world_size
        wb, f = np.divmod(mi, n)
        r = row[wb]
        xf, yf = self.x.reshape(-1), self.y.reshape(-1)
        x, y = xf[mi], yf[mi]
        c = self._terrain(mi, wb, x, y) * self.fuel[f] * self._ratio(wb, f, r)
        sc = self.pre_sc.reshape(-1)
        at = (wb * self.pre_len + r) * (2 * n) + f
        x += sc[at] * c
        y += sc[at + n] * c
        xf[mi], yf[mi] = x, y
        inside = (x >= 0.0) & (x < w) & (y >= 0.0) & (y < w)
        if not inside.all():
            self.alive.reshape(-1)[mi[~inside]] = False
            mi, wb, x, y = mi[inside], wb[inside], x[inside], y[inside]
        xi, yi = x.astype(np.int64), y.astype(np.int64)
        self.cell.reshape(-1)[mi] = xi * w + yi
        st = self.grid.flat_state[self.grid.index(wb, xi, yi)] & STATE_BITS
        pruned = st == PRUNED
        if np.count_nonzero(pruned):
            self.frozen.reshape(-1)[mi[pruned]] = True
        fresh = st == UNBURNT
        return self.ignite(wb[fresh], xi[fresh], yi[fresh])

    # ------------------------------------------------------------------ cells
    def ignite(self, wb: np.ndarray, x: np.ndarray, y: np.ndarray) -> Cells:
        """Set the unburnt cells among ``(wb, x, y)`` burning; return them (unique, sorted by
        world then flat index)."""
        grid = self.grid
        if wb.size == 0:
            return _EMPTY, _EMPTY, _EMPTY
        sh = self._shift  # (a sortable key per cell: world, x, y in bit fields)
        key = unique((wb << (2 * sh)) | (x << sh) | y)
        wb, x, y = key >> (2 * sh), (key >> sh) & self._mask, key & self._mask
        g = grid.index(wb, x, y)
        fresh = grid.flat_state[g] & STATE_BITS == UNBURNT
        if not fresh.all():
            wb, x, y, g = wb[fresh], x[fresh], y[fresh], g[fresh]
            if wb.size == 0:
                return _EMPTY, _EMPTY, _EMPTY
        grid.flat_state[g] = BURNING
        grid.count(wb, x, y, +1)
        # per world (the cells are sorted by world, then x): counts and the box of the new cells
        start, counts = runs(wb)
        worlds = wb[start]
        self.n_burning[worlds] += counts
        self.n_ignited[worlds] += counts
        lo = (x[start], np.minimum.reduceat(y, start))
        hi = (x[np.append(start[1:], wb.size) - 1], np.maximum.reduceat(y, start))
        box = self.burn_box
        box[worlds, 0] = np.minimum(box[worlds, 0], lo[0])
        box[worlds, 1] = np.maximum(box[worlds, 1], hi[0])
        box[worlds, 2] = np.minimum(box[worlds, 2], lo[1])
        box[worlds, 3] = np.maximum(box[worlds, 3], hi[1])
        grid.touch(worlds, lo, hi)
        return wb, x, y

    def prune(self, wb: np.ndarray, x: np.ndarray, y: np.ndarray) -> None:
        """Put out the burning cells ``(wb, x, y)`` (distinct); fronts standing in them freeze."""
        grid, w = self.grid, self.world_size
        g = grid.index(wb, x, y)
        grid.flat_state[g] = (grid.flat_state[g] & SENSED) | PRUNED
        grid.count(wb, x, y, -1)
        counts = np.bincount(wb, minlength=self.num)
        self.n_burning -= counts
        self.n_pruned += counts
        out = (self.n_burning == 0) & (counts > 0)
        if np.count_nonzero(out):
            self.burn_box[out] = (w, -1, w, -1)
        hit = np.flatnonzero(counts)
        cx, cy = np.divmod(self.cell[hit], w)
        st = grid.flat_state[grid.index(hit[:, None], cx, cy)] & STATE_BITS
        self.frozen[hit] |= self.alive[hit] & (st == PRUNED)

    def world_state(self, b: int) -> np.ndarray:
        """(W, W) uint8 fire state of world ``b`` (as :attr:`fcplan.fire.Fire.state`)."""
        return self.grid.world_array(b) & STATE_BITS


assert BURNING == 1 and PRUNED == 2 and UNBURNT == 0  # (the byte layout of fcplan.batch.cells)
