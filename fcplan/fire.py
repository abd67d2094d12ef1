"""FARSITE wildfire: propagating fronts over a 1-px cell grid, vectorised over all fronts.

Each fire region starts with ``fronts`` ignition points drawn uniformly (integer pixels) in its
ignition box. Every **fire step** every live front moves once (FIRECOMMANDER.md 1.4;
:mod:`fcplan.farsite` has the formulas)::

    R = fuel * terrain[round(x), round(y)]                    (terrain ~ U(0, 1), fixed per episode)
    C = R * (C/R)(U)                                          (FARSITE spread rate, U: wind speed)
    x += C sin(Theta),   y += C cos(Theta)                    (Theta: wind direction)

This is the manual's FARSITE model, ``dq/dt = C(R, U) D(Theta)``, with the reference code's
exponents. Units: px (1 px = 1 m), angles in radians (theta = 0 is +y, screen down; 90 degrees is
+x). A front moves about ``0.24 * fuel`` px on its first step at wind 5.

**The fire's clock.** A fire step is 0.1 simulated second (the original's per-frame step at
fcplan's reference 10 frames per second), whatever ``ticks_per_second`` ``r``: tick ``t`` runs
steps ``floor(10 (t - 1) / r) + 1 .. floor(10 t / r)``, two per tick at 5 Hz, one at 10 Hz, one
every 2nd (4th) tick at 20 (40) Hz. The wind is drawn per step, so without pruning the fire at
any rate is, bit for bit, the 10 Hz fire seen at the ticks' times. Per simulated second, a front
on fuel ``R`` has (wind 5: ``E[C/R] = 0.475``, ``E[(C/R)^2] = 0.227``; ``E[sin Theta] = e^-2 sin
theta_avg``):

* a mean drift velocity of ``10 * 0.475 e^-2 R = 0.643 R`` px/s along the wind azimuth;
* a diffusion: the position's variance grows by ``10 * 0.227 R^2 / 2 = 1.14 R^2`` px^2 per second
  per axis, linearly in time (the steps are independent given the terrain);
* lingering: ``R`` is read at the front's cell, so on low fuel a front takes small steps and needs
  about ``1 / (1.14 R^2)`` s to wander 1 px; this makes the mean step over a run 4-5 times smaller
  than the first step (FIRECOMMANDER.md 1.4).

Why the step is fixed rather than scaled to the tick: the terrain is independent from one 1-px cell
to the next and a front reads it once per step, so the front's path has no continuous-time limit
that keeps these statistics. Scaling each step by ``dt = 10 / r`` (fcplan before this rule) shrank
the random walk's variance per second by ``dt``; scaling the random part by ``sqrt(dt)`` keeps the
variance on constant fuel but not the drift, as fronts linger longer in low-fuel cells when steps
shrink (drift after 180 s at 5/10/20/40 Hz: 252/172/103/67 px, against 173 px at every rate with
the fixed step); and cells burn where fronts land, so the burnt area depends on how finely the
path is sampled (``bench/bench_tick_rate.py --alternatives``).

**Wind.** ``Scenario.wind_model`` (``[fire] wind_model``) picks how ``U`` and ``Theta`` are drawn
(:mod:`fcplan.farsite`): ``"fresh"`` draws ``U ~ N(U_avg, 2)`` and ``Theta ~ N(theta_avg, 2 rad)``
for every front every step; ``"tables"`` is the original's model: each region draws a table of
``W`` speeds and one of ``W`` directions (``W``: the map side) once per episode, and every step
each front picks an entry of each. Both have the same mean drift, but the tables give each episode
its own wind bias: after 1,800 steps the spread between episodes of the fronts' drift along the
wind is 1.51 times the fresh model's for scenario #1's region (1,000 seeds; 1.3 with 5 fronts, 2.1
with 30: the bias does not average out over fronts; ``bench/bench_wind.py``).

What fcplan keeps and fixes (ARCHITECTURE.md "Fire"):

* There is no branching: each front is one point; the fire grows as the trail of cells the fronts
  visit. Every cell a front lands in burns; the ignition cells burn as soon as their region
  activates (the first step at or after its delay; the tick that runs it), which the 2020 code
  forgot.
* A front standing in a pruned cell is frozen forever; pruned cells never re-ignite.
* A front leaving the map dies (the 2020 code kept a phantom front at (0, 0)). fcplan moves every
  live front and kills those that land outside ``[0, W)``; the original tests ``0 < x <= W - 1``
  (and the same for y) *before* stepping and skips a front that fails, so its fronts die one
  step later, a front landing at exactly ``x = 0`` or ``y = 0`` dies there, and the strip
  ``W - 1 < x < W`` (1 px) is outside its map but inside fcplan's.
* One terrain field is shared by all regions (it is the map's fuel pattern); each region scales it
  by its fuel coefficient.
* The wind of *every* front is drawn every step, live or not, so the fire's random stream never
  depends on what the agents do (common random numbers across schedulers); :class:`Fire` draws
  it for blocks of steps at once (:mod:`fcplan._fast.fire`), bit for bit as step by step.
* ``C/R`` is tabulated (:func:`~fcplan.farsite.ratio_tabulated`) in the fresh model, exact per
  table entry in the tables model.
* Intensity is not used by any rule. It is kept as a grid of front visits (``visits``); the
  Gaussian heat field of the manual is computed on demand by :meth:`Fire.intensity`.

Cells are indexed ``[x, y]``; a flat cell index is ``x * W + y``.

Examples
--------
>>> import numpy as np
>>> from fcplan.fire import Fire
>>> from fcplan.scenario import FireRegion
>>> region = FireRegion(center=(350, 350), fronts=10, delay_s=0, fuel=10, wind_speed=5,
...                     wind_dir_deg=45)
>>> fire = Fire([region], world_size=1200, ticks_per_second=10, rng=np.random.default_rng(0))
>>> for _ in range(50):
...     _ = fire.step()
>>> int(fire.n_burning) > 10, fire.n_steps
(True, 50)
>>> slow = Fire([region], 1200, ticks_per_second=5, rng=np.random.default_rng(0),
...             wind_model="tables")
>>> for _ in range(25):
...     _ = slow.step()
>>> slow.n_steps, slow.wind_tables.shape
(50, (1, 2, 1200))
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from fcplan._fast.fire import advance_whole, draw_ahead, draw_ahead_tables, ignite_cells
from fcplan._fast.fire import unique as _unique
from fcplan.farsite import (
    INTERP_MAX,
    WIND_DIR_SD_RAD,
    WIND_SPEED_SD,
    interp_ratio,
    ratio_tabulated,
    spread_rate_ratio,
    wind_draws,
    wind_tables,
)
from fcplan.scenario.parts import DEFAULT_WIND_MODEL, WIND_MODELS
from fcplan.shared_views import KeepsViews

__all__ = ["Fire", "spread_rate_ratio", "wind_draws", "INTENSITY_COEFF", "STEPS_PER_SECOND"]
__all__ += ["UNBURNT", "BURNING", "PRUNED", "WIND_SPEED_SD", "WIND_DIR_SD_RAD"]

#: ``259.833 (h / cos(alpha))^2.174 / 1000`` with h = 3 m, alpha = pi/3 (manual Eq. intensity).
INTENSITY_COEFF = 259.833 * (3.0 / math.cos(math.pi / 3)) ** 2.174 / 1000.0
#: Fire steps per simulated second, at every tick rate (see "The fire's clock").
STEPS_PER_SECOND = 10
#: Cell states in :attr:`Fire.state`.
UNBURNT, BURNING, PRUNED = 0, 1, 2
#: Side (px) of the blocks in :attr:`Fire.block_burning`.
BLOCK = 16


class Fire(KeepsViews):
    """All fire regions of one episode.

    Parameters
    ----------
    regions : sequence of fcplan.scenario.FireRegion
        Any objects with ``center``, ``fronts``, ``delay_s``, ``fuel``, ``wind_speed``,
        ``wind_dir_deg`` and ``half_width``.
    world_size : int
        Map side ``W`` in px (cells).
    ticks_per_second : int
        Simulation rate; the fire takes :data:`STEPS_PER_SECOND` steps per simulated second at
        any rate (module docstring, "The fire's clock").
    rng : numpy.random.Generator
        The fire's own random stream.
    wind_model : {"fresh", "tables"}
        How the wind is drawn (module docstring, "Wind").

    Attributes
    ----------
    x, y : ndarray, (n,) float64
        Front positions.
    region : ndarray, (n,) int16
        Region index of each front.
    alive : ndarray, (n,) bool
        False once the front left the map.
    state : ndarray, (W, W) uint8
        ``UNBURNT`` (0), ``BURNING`` (1) or ``PRUNED`` (2) per cell. Pruned cells never burn
        again and freeze fronts standing in them.
    visits : ndarray, (W, W) uint32
        Front-steps spent in each cell (the accumulation behind :meth:`intensity`).
    tick, n_steps : int
        Ticks and fire steps taken.
    start_step : ndarray, (R,) int64
        Per region, ``ceil(10 delay_s)``: it activates on fire step ``max(1, start_step)``.
    wind_tables : ndarray, (R, 2, W) float64 or None
        Per region, the wind speeds (``[:, 0]``) and directions (``[:, 1]``, rad) of the tables
        model; None in the fresh model.
    """

    _block = BLOCK  # (read by the kernels of fcplan._fast.fire, which cannot import this module)

    def __init__(
        self,
        regions: Sequence[Any],
        world_size: int,
        ticks_per_second: int,
        rng: np.random.Generator,
        *,
        wind_model: str = DEFAULT_WIND_MODEL,
    ) -> None:
        if wind_model not in WIND_MODELS:
            raise ValueError(f"wind_model must be one of {WIND_MODELS} (got {wind_model!r})")
        self.wind_model = wind_model
        w = int(world_size)
        self.world_size = w
        self._w_float = np.float64(w)
        self._w_bits = self._w_float.view(np.uint64)
        self._stride = np.array([w, 1], dtype=np.int64)  # (x, y) -> flat x w + y
        self.ticks_per_second = int(ticks_per_second)
        self.rng = rng
        self.tick = 0
        self.n_steps = 0
        n_per = np.array([int(r.fronts) for r in regions], dtype=np.int64)
        self.region = np.repeat(np.arange(len(regions), dtype=np.int16), n_per)
        n = int(n_per.sum())
        self.n_fronts = n
        # Ignition points: integers in [c - hw, c + hw - 1] per axis, as the reference draws them.
        lo = np.array([[r.center[0] - r.half_width, r.center[1] - r.half_width] for r in regions])
        hi = np.array([[r.center[0] + r.half_width, r.center[1] + r.half_width] for r in regions])
        lo_f, hi_f = np.repeat(lo, n_per, axis=0), np.repeat(hi, n_per, axis=0)
        pts = rng.integers(lo_f.astype(np.int64), hi_f.astype(np.int64), size=(n, 2))
        # positions as one (2, n) array: one numpy call moves both coordinates
        self._xy = np.ascontiguousarray(pts.T, dtype=np.float64)
        self.alive = (self.x >= 0) & (self.x < w) & (self.y >= 0) & (self.y < w)
        per = np.array(
            [[r.fuel, r.wind_speed, math.radians(r.wind_dir_deg)] for r in regions], np.float64
        )
        self._fuel = per[self.region, 0]
        self._wind = per[self.region, 1]
        self._theta = per[self.region, 2]
        self.start_step = np.array(
            [math.ceil(r.delay_s * STEPS_PER_SECOND - 1e-9) for r in regions], np.int64
        )
        self.region_active = np.zeros(len(regions), dtype=bool)
        self._set_next_wake()
        # One terrain field for the map, padded by one cell so rounded positions never overflow.
        self.terrain = rng.random((w + 1, w + 1), dtype=np.float32)
        self._terrain_flat = self.terrain.reshape(-1)
        self._t_stride = np.array([w + 1, 1], dtype=np.int64)  # rounded (x, y) -> terrain index
        # A front moves less than C = fuel R/2 px per axis in a step (terrain < 1, C/R < 1/2).
        # Fronts stand in burning cells, inside ``burn_box``, so while the box keeps this far
        # from the edges no front can leave the map.
        self._edge_margin = 0.5 * float(per[:, 0].max(initial=0.0)) + 1.0
        #: (W, W) uint8 cell state: UNBURNT, BURNING or PRUNED.
        self.state = np.zeros((w, w), dtype=np.uint8)
        self._visits = np.zeros((w, w), dtype=np.uint32)
        self._state_flat = self.state.reshape(-1)
        self._visits_flat = self._visits.reshape(-1)
        # the cells of the moving fronts are queued here step after step (one copy per step) and
        # added to the grid in one np.add.at when full or when someone reads ``visits``
        self._visit_queue = np.zeros(_VISIT_ROWS * max(n, 1), dtype=np.int64)
        self._n_visits = 0
        self._move = np.empty((2, n))  # per-step buffer: the moves of all fronts
        self._init_wind(per)
        #: (n,) int64 flat index of each front's current cell (valid while alive).
        self.cell = np.where(
            self.alive,
            np.clip(self.x, 0, w - 1).astype(np.int64) * w
            + np.clip(self.y, 0, w - 1).astype(np.int64),
            0,
        )
        #: (B, B) int32 burning cells per ``BLOCK`` x ``BLOCK`` block: lets callers skip empty
        #: areas without scanning cells.
        nblk = -(-w // BLOCK)
        self.block_burning = np.zeros((nblk, nblk), dtype=np.int32)
        self._block_flat = self.block_burning.reshape(-1)
        self._nblk = nblk
        #: (n,) bool: the front stands in a pruned cell and never moves again.
        self.frozen = np.zeros(n, dtype=bool)
        self._moving: np.ndarray | None = None  # cached rows of moving fronts
        self.n_burning = 0
        self.n_pruned = 0
        self.n_ignited = 0
        #: ``[x0, x1, y0, y1]`` (inclusive, Python ints) box around every cell that burns: a
        #: superset of the burning cells (cells pruned since may still lie inside), empty
        #: (``x0 > x1``) when nothing burns. Lets callers skip areas without a numpy call.
        self.burn_box = [w, -1, w, -1]

    def _init_wind(self, per: np.ndarray) -> None:
        """The wind tables (tables model) and the buffers of the wind drawn ahead: the
        position-free part of the FARSITE step (draws, U, C/R, sin and cos of Theta) for the next
        ``_pre_len`` steps of every front, filled in one go by :meth:`_refill` (row t: step t of
        the block, the result of :func:`~fcplan.farsite.wind_draws` or
        :func:`~fcplan.farsite.wind_from_tables`)."""
        n, w = self.n_fronts, self.world_size
        self.wind_tables = None
        tables = self.wind_model == "tables"
        if tables:  # entries as flat arrays, with C/R, sin and cos per entry
            self.wind_tables = wind_tables(self.rng, per[:, 1], per[:, 2], w)
            u = np.ascontiguousarray(self.wind_tables[:, 0]).reshape(-1)
            theta = np.ascontiguousarray(self.wind_tables[:, 1]).reshape(-1)
            self._tab = (u, np.sin(theta), np.cos(theta), spread_rate_ratio(u))
            self._tab_base = self.region.astype(np.int64) * w  # row of each front's tables
        self._pre_len = max(1, min(_PRE_TICKS, _PRE_VALUES // max(n, 1)))
        self._pre_t = self._pre_len  # next row to use (all used: refill first)
        self._pre_z = np.empty((self._pre_len, 2, n))
        self._pre_sc = np.empty((self._pre_len, 2, n))
        self._pre_u = self._pre_z[:, 0]  # (wind speeds overwrite the draws: a view)
        with_ratio = n <= INTERP_MAX or tables
        self._pre_ratio = np.empty((self._pre_len, n)) if with_ratio else None

    # ------------------------------------------------------------------ queries
    @property
    def x(self) -> np.ndarray:
        """(n,) float64 front x positions (a view: writing into it moves the fronts)."""
        return self._xy[0]

    @x.setter
    def x(self, value: Any) -> None:
        self._xy[0] = value

    @property
    def y(self) -> np.ndarray:
        """(n,) float64 front y positions (a view: writing into it moves the fronts)."""
        return self._xy[1]

    @y.setter
    def y(self, value: Any) -> None:
        self._xy[1] = value

    @property
    def visits(self) -> np.ndarray:
        """(W, W) uint32 front-steps spent in each cell (up to date; writable)."""
        if self._n_visits:
            self._flush_visits()
        return self._visits

    def _flush_visits(self) -> None:
        np.add.at(self._visits_flat, self._visit_queue[: self._n_visits], _ONE)
        self._n_visits = 0

    @property
    def live(self) -> np.ndarray:
        """(n,) bool: fronts that move on the next step (alive and their region active)."""
        return self.alive & self.region_active[self.region]

    @property
    def burning(self) -> np.ndarray:
        """(W, W) bool: burning cells (a fresh array; scans the grid, not for the hot path)."""
        return self.state == BURNING

    @property
    def pruned(self) -> np.ndarray:
        """(W, W) bool: pruned cells (a fresh array; scans the grid, not for the hot path)."""
        return self.state == PRUNED

    def burning_cells(self) -> np.ndarray:
        """(k, 2) int64 ``[x, y]`` of every burning cell (scans the grid: not for the hot path)."""
        return np.argwhere(self.state == BURNING)

    def intensity(self, sigma: float = 9.5, radius: float = 10.0) -> np.ndarray:
        """(W, W) heat field in kW/m: Gaussian radiation of every front visit, linearly summed.

        This is the manual's "Gaussian heat radiation with linear summation" evaluated on the
        grid (``sigma`` about the reference's ``randint(9, 11) + N(0, 1)``, truncated at
        ``radius`` px). No rule reads it; it is for display and analysis.
        """
        from scipy.signal import fftconvolve

        r = int(math.floor(radius))
        off = np.arange(-r, r + 1, dtype=np.float64)
        d2 = off[:, None] ** 2 + off[None, :] ** 2
        kernel = np.where(d2 <= radius**2, np.exp(-0.5 * d2 / sigma**2), 0.0)
        kernel /= 2.0 * math.pi * sigma**2
        field = fftconvolve(self.visits.astype(np.float64), kernel, mode="same")
        return 1000.0 * INTENSITY_COEFF * field

    def _block_of(self, flat: np.ndarray) -> np.ndarray:
        w = self.world_size
        return (flat // w // BLOCK) * self._nblk + (flat % w) // BLOCK

    def any_burning_in(self, x0: int, x1: int, y0: int, y1: int) -> bool:
        """True if a cell in ``[x0, x1) x [y0, y1)`` may burn (exact for block-aligned ranges;
        otherwise a cheap necessary condition)."""
        b = self.block_burning[
            x0 // BLOCK : (x1 - 1) // BLOCK + 1, y0 // BLOCK : (y1 - 1) // BLOCK + 1
        ]
        return bool(np.count_nonzero(b))

    # ------------------------------------------------------------------ dynamics
    def _ignite(self, flat: np.ndarray, state: np.ndarray | None = None) -> np.ndarray:
        """Set unburnt cells burning; return the newly burning ones (unique). ``state``: the
        current states of ``flat``, if the caller has them."""
        if state is None:
            state = self._state_flat[flat]
        fresh = flat[state == _UNBURNT8]
        n = fresh.size
        if n == 0:
            return fresh
        if n <= _SMALL:  # a few cells (every tick of a normal fire): Python ints are cheaper
            return ignite_cells(self, fresh.tolist())
        fresh = _unique(fresh)
        np.add.at(self._block_flat, self._block_of(fresh), _ONE32)
        w = self.world_size
        ys = fresh % w
        return self._burn(
            fresh, int(fresh[0]) // w, int(fresh[-1]) // w, int(ys.min()), int(ys.max())
        )

    def _burn(self, fresh: np.ndarray, x0: int, x1: int, y0: int, y1: int) -> np.ndarray:
        """Set the (unique, unburnt) cells ``fresh`` burning, spanning ``[x0, x1] x [y0, y1]``
        (blocks already counted); return ``fresh``."""
        box = self.burn_box
        if x0 < box[0]:
            box[0] = x0
        if x1 > box[1]:
            box[1] = x1
        if y0 < box[2]:
            box[2] = y0
        if y1 > box[3]:
            box[3] = y1
        self._state_flat[fresh] = BURNING
        self.n_burning += int(fresh.size)
        self.n_ignited += int(fresh.size)
        return fresh

    def step(self) -> np.ndarray:
        """Advance one tick: take the fire steps due by its end (:meth:`_fire_step`); return the
        flat indices of the cells that started burning."""
        self.tick += 1
        stop = self.tick * STEPS_PER_SECOND // self.ticks_per_second
        k = self.n_steps
        if stop == k + 1:  # (one step per tick: 10 ticks per second)
            return self._fire_step()
        if stop == k:  # (no fire step in this tick: above 10 ticks per second)
            return _EMPTY
        parts = [p for p in (self._fire_step() for _ in range(stop - k)) if p.size]
        return np.concatenate(parts) if len(parts) > 1 else (parts[0] if parts else _EMPTY)

    def _fire_step(self) -> np.ndarray:
        """Take one fire step (0.1 simulated second); return the flat indices of the cells that
        started burning.

        1. Regions whose delay has passed (``start_step <= n_steps``) activate: their ignition
           cells burn (:meth:`_wake_regions`).
        2. Every live, unfrozen front takes one FARSITE step with this step's wind
           (:meth:`_advance_moving`).
        3. Fronts that left the map die.
        4. Every other moved front lands in a cell: a pruned cell freezes it for good, an
           unburnt cell starts burning.
        """
        self.n_steps += 1
        new = self._wake_regions() if self.n_steps >= self._next_wake else _EMPTY
        t = self._pre_t  # this step's row of the wind drawn ahead
        if t == self._pre_len:
            self._refill()
            t = 0
        self._pre_t = t + 1
        idx = self._moving
        if idx is None:
            idx = self._refresh_moving()
        if idx.size == 0:
            return new
        all_moving = self._all_moving
        ratio = self._pre_ratio
        # the visits of this step: the cells the moving fronts stand in
        k = self._n_visits
        if k + self.n_fronts > self._visit_queue.size:
            self._flush_visits()
            k = 0
        if all_moving:
            self._visit_queue[k : k + self.n_fronts] = self.cell
            self._n_visits = k + self.n_fronts
        else:
            self._visit_queue[k : k + idx.size] = self.cell[idx]
            self._n_visits = k + idx.size
        # 2. The rule moves the moving fronts only. The whole-array kernel is bit-identical and
        # cheaper when every front moves, or when C/R of every front was drawn ahead (fires up to
        # INTERP_MAX fronts: C/R's method depends on how many fronts move).
        masked = not all_moving and ratio is not None
        if all_moving or masked:
            ratio_t = ratio_tabulated(self._pre_u[t]) if ratio is None else ratio[t]
            xy = advance_whole(self, t, ratio_t, all_moving)
        else:
            xy = self._advance_moving(idx, t)
        # 3. No front can leave the map this step while the burn box keeps _edge_margin from the
        # edges (moving fronts stand in burning cells); the box does not change until step 4.
        (x0, x1, y0, y1), m, w = self.burn_box, self._edge_margin, self.world_size
        inside = None
        if not (m <= x0 <= x1 and x1 + m < w and m <= y0 and y1 + m < w):
            # As unsigned integers the bits of non-negative doubles keep their order and every
            # negative double (and NaN) is larger: all below W's bits means all in [+0, W). In
            # the whole-array step the idle fronts add the same count as when they stopped.
            n_in = np.count_nonzero(xy.view(np.uint64) < self._w_bits)
            if n_in != (self._idle_inside + 2 * idx.size if masked else xy.size):
                on_map: np.ndarray = (xy >= _ZERO) & (xy < self._w_float)
                inside = on_map[0] & on_map[1]
                if masked:
                    inside = inside[idx]
                if np.count_nonzero(inside) == inside.size:
                    inside = None
        rows: np.ndarray | slice
        if inside is None:
            rows = slice(None) if all_moving else idx
        else:
            self.alive[idx[~inside]] = False
            self._moving = None
            rows = idx[inside]
            if not masked:
                xy = xy[:, inside]
        # 4. land: x w + y, exact on int64 (one call)
        flat = self._stride @ xy.astype(np.int64)
        if masked:
            flat = flat[rows]
        self.cell[rows] = flat
        st = self._state_flat[flat]
        if flat.size <= _SMALL:  # a few fronts: the checks below on Python ints
            st_list = st.tolist()
            if PRUNED in st_list:
                self._freeze(st, idx if isinstance(rows, slice) else rows)
            fresh = ignite_cells(
                self, [c for c, v in zip(flat.tolist(), st_list, strict=True) if v == UNBURNT]
            )
        else:
            if np.count_nonzero(st == _PRUNED8):
                self._freeze(st, idx if isinstance(rows, slice) else rows)
            fresh = self._ignite(flat, st)
        return fresh if new.size == 0 else np.concatenate([new, fresh])

    def _wake_regions(self) -> np.ndarray:
        """Activate the regions whose delay has passed; return their ignition cells that started
        burning."""
        new = _EMPTY
        waking = (~self.region_active) & (self.start_step <= self.n_steps)
        if waking.any():
            self.region_active |= waking
            self._moving = None
            new = self._ignite(self.cell[self.alive & waking[self.region]])
        self._set_next_wake()
        return new

    def _advance_moving(self, idx: np.ndarray, t: int) -> np.ndarray:
        """One FARSITE step of the moving fronts ``idx`` with row ``t`` of the wind drawn ahead;
        return their new positions, ``(2, k)``, also written back into the fronts.

        ``R = fuel terrain[round(x), round(y)]``, ``C = R (C/R)(U)``, then
        ``x += C sin(Theta)`` and ``y += C cos(Theta)``.
        """
        idx2 = self._m_idx2  # idx in the flat (2 n) positions: 1-D takes, not 2-D fancy indexing
        xy = self._xy.reshape(-1)[idx2].reshape(2, -1)
        sin_cos = self._pre_sc[t].reshape(-1)[idx2].reshape(2, -1)
        pre_ratio = self._pre_ratio
        ratio = ratio_tabulated(self._pre_u[t][idx]) if pre_ratio is None else pre_ratio[t][idx]
        terrain = self._terrain_flat[self._t_stride @ np.rint(xy).astype(np.int64)]
        c = terrain * self._m_fuel * ratio
        xy += np.multiply(sin_cos, c)
        self._xy.reshape(-1)[idx2] = xy.reshape(-1)
        return xy

    def _freeze(self, st: np.ndarray, idx: np.ndarray) -> None:
        """Freeze the moved fronts ``idx`` whose new cell, of state ``st``, is pruned."""
        self.frozen[idx[st == _PRUNED8]] = True
        self._moving = None

    def _refill(self) -> None:
        """Compute the wind of the next ``_pre_len`` steps of every front at once: row ``t`` is
        what :func:`wind_draws` (or :func:`~fcplan.farsite.wind_from_tables`, with the exact C/R
        of each table entry) would give on step ``t`` of the block, bit for bit."""
        z, sc, ratio, rng = self._pre_z, self._pre_sc, self._pre_ratio, self.rng
        if self.wind_tables is not None and ratio is not None:  # (always drawn ahead)
            draw_ahead_tables(rng, z, sc, ratio, self._tab_base, self.world_size, *self._tab)
            return
        sd = (WIND_SPEED_SD, WIND_DIR_SD_RAD)
        draw_ahead(rng, z, sc, ratio, self._wind, self._theta, *sd, interp_ratio)

    def _set_next_wake(self) -> None:
        """Step at which the next inactive region activates (never: a huge number)."""
        waiting = self.start_step[~self.region_active]
        self._next_wake = int(waiting.min()) if waiting.size else _NEVER

    def _refresh_moving(self) -> np.ndarray:
        """Cache the fronts that move (alive, region active, not frozen) and their parameters;
        return their rows."""
        idx = np.flatnonzero(self.alive & self.region_active[self.region] & ~self.frozen)
        self._moving = idx
        self._all_moving = idx.size == self.n_fronts
        self._m_idx2 = np.concatenate([idx, idx + self.n_fronts])  # rows 0 and 1 of (2, n)
        self._m_fuel = self._fuel[idx]
        fuel = self._fuel.copy()
        idle = self.frozen | ~self.alive | ~self.region_active[self.region]
        fuel[idle] = 0.0
        self._fuel_masked = fuel  # (n,): 0 for the fronts that do not move
        # coordinates of the idle fronts inside the map, as the step's check counts them
        self._idle_inside = int(np.count_nonzero(self._xy[:, idle].view(np.uint64) < self._w_bits))
        return idx

    def prune(self, flat: np.ndarray) -> np.ndarray:
        """Put out burning cells; return the flat indices actually pruned (they were burning).

        Fronts standing in a pruned cell freeze for good.
        """
        flat = np.asarray(flat, dtype=np.int64)
        hit = flat[self._state_flat[flat] == BURNING]
        if hit.size > 1:
            hit = np.unique(hit)
        if hit.size == 0:
            return hit
        self._state_flat[hit] = PRUNED
        np.subtract.at(self._block_flat, self._block_of(hit), _ONE32)
        self.n_burning -= int(hit.size)
        self.n_pruned += int(hit.size)
        if self.n_burning == 0:
            self.burn_box = [self.world_size, -1, self.world_size, -1]
        self.frozen |= self.alive & (self._state_flat[self.cell] == PRUNED)
        self._moving = None
        return hit


_EMPTY = np.zeros(0, dtype=np.int64)
_ONE = np.uint32(1)
_ONE32 = np.int32(1)
_NEVER = 2**62
_ZERO = np.float64(0.0)  # numpy scalars compare faster than Python numbers
_UNBURNT8, _BURNING8, _PRUNED8 = np.uint8(UNBURNT), np.uint8(BURNING), np.uint8(PRUNED)
_SMALL = 32  # up to this many fresh cells, _ignite works on Python ints
_PRE_TICKS = 64  # steps of draws and position-free terms computed ahead in one go ...
_PRE_VALUES = 4096  # ... fewer for large fires: at most about this many fronts x steps
_VISIT_ROWS = 256  # steps of front visits queued before they are added to the grid
