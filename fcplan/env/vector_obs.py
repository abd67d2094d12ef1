"""Observations of the batched motion level: :mod:`fcplan.env.motion_obs` with a batch axis.

:class:`BatchMotionObs` builds, for all ``B`` worlds of a :class:`fcplan.batch.BatchWorld` at
once, exactly what :class:`fcplan.env.motion_obs.MotionObs` builds for one world: agent vectors
``(B, N, 15)``, action masks ``(B, N, n_max)`` (padded with 0 beyond an agent's actions, as
:class:`fcplan.env.joint_gym.JointGymEnv` pads them) and field-of-view crops
``(B, N, 7, view, view)`` of the coarse maps.

Coarse maps. Every world keeps the seven observation channels of its coarse cells, padded by
``view // 2`` cells as in :class:`fcplan.env.motion_grid.CoarseMaps`, *channel last*:
:attr:`BatchMotionObs.maps` is ``(B, H, H, 7)`` float32 holding known (scaled, clipped), pruned
(scaled, clipped), ``seen`` (minus the tick each cell was last covered, times the staleness
scale; ``+inf`` never), agents (0/1), and the scenario's static outside, lake and facility
shares (the same in every world, copied once). ``counts`` ``(B, H, H, 2)`` holds the known and
pruned cell counts behind the scaled channels. All ``B N`` crops are one fancy-indexed gather of
``sliding_window_view(maps)``, which yields them directly in the ``(7, view, view)`` layout;
with the channels last, each window row is one run of ``7 view`` floats, and the gather runs
about twice as fast as from channel-first maps (``bench/README.md``). The staleness
``min(1, seen + tick scale)`` is then computed in place on the crops' ``seen`` slot, as the same
float32 operations as the single map's (``seen`` once lived in an array of its own and was
gathered a second time; ``bench/README.md`` has the two timings). The
true burning layer behind :meth:`BatchMotionObs.state` is brought up to date only when read (the
fire's changes are queued per tick, as the single map queues them).

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> from fcplan.batch import BatchWorld
>>> sc = load_scenario("practice")
>>> batch = BatchWorld(sc, 2)
>>> batch.reset(seeds=[0, 1])
>>> obs = BatchMotionObs(sc, 2, cell_px=20, view=15, stale_s=30.0)
>>> obs.reset_worlds(np.arange(2))
>>> o = obs.observe(batch)
>>> o["fov"].shape, o["agent"].shape, o["action_mask"].shape
((2, 4, 7, 15, 15), (2, 4, 15), (2, 4, 7))
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from fcplan.batch import BatchStepInfo, BatchWorld
from fcplan.batch.cells import SENSED
from fcplan.env.motion import role_letters
from fcplan.env.motion_grid import FACILITY, LAKE, OUTSIDE, CoarseMaps
from fcplan.env.motion_obs import N_AGENT_FEATURES, N_FOV
from fcplan.scenario import Scenario
from fcplan.shared_views import KeepsViews
from fcplan.team import DRAIN_PER_PX

__all__ = ["BatchMotionObs"]

#: the channels of :attr:`BatchMotionObs.maps` that differ between worlds
D_KNOWN, D_PRUNED, D_SEEN, D_AGENTS = range(4)
_ONE32 = np.float32(1.0)
_PENDING_MAX = 1 << 16  # (queued fire cells of the burning layer before it is updated)
_ACTIVE = 1


class BatchMotionObs(KeepsViews):
    """The observation side of a batched motion env (module docstring).

    Parameters
    ----------
    scenario : Scenario
    num : int
        Worlds ``B``.
    cell_px, view : int
        Coarse cell side (px) and crop side (cells, odd).
    stale_s : float
        Seconds for a cell to become fully stale.
    """

    def __init__(
        self, scenario: Scenario, num: int, *, cell_px: int, view: int, stale_s: float
    ) -> None:
        sc = scenario
        self.scenario, self.num = sc, int(num)
        self.cell_px, self.view = int(cell_px), int(view)
        self.seen_scale = 1.0 / (float(stale_s) * sc.ticks_per_second)
        one = CoarseMaps(sc, self.cell_px, self.view, seen_scale=self.seen_scale)
        self.radius, self.nc, self.world_size = one.radius, one.nc, sc.world_size
        h = one.grid.shape[1]
        self.h = h
        self.static = np.ascontiguousarray(one.grid[[OUTSIDE, LAKE, FACILITY]])
        #: (B, H, H, 7) float32: the observation's channels, last (module docstring)
        self.maps = np.zeros((self.num, h, h, N_FOV), dtype=np.float32)
        self.maps[..., 4:] = np.moveaxis(self.static, 0, 2)
        self.counts = np.zeros((self.num, h, h, 2), dtype=np.float32)
        self.burning = np.zeros((self.num, h, h), dtype=np.float32)  # (state(): true fire)
        self._pending: list[tuple[np.ndarray, np.ndarray, float]] = []  # (see _flush)
        self._n_pending = 0
        v = self.view
        #: (B, H - v + 1, H - v + 1, 7, v, v) windows: a crop is ``windows[b, cx, cy]``
        self.windows = sliding_window_view(self.maps, (v, v), axis=(1, 2))
        #: (B, H, H) float32 view of the ``seen`` channel of :attr:`maps` (module docstring)
        self.seen = self.maps[..., D_SEEN]
        self.seen[:] = np.inf
        self._inv_c = 1.0 / self.cell_px
        letters = role_letters(sc)
        self.letters = letters
        self.n = n = len(letters)
        self.n_actions = np.array([{"P": 7, "A": 6, "H": 8}[r] for r in letters], dtype=np.int64)
        self.n_max = int(self.n_actions.max(initial=1))
        self._sensing = np.flatnonzero([r != "A" for r in letters])
        self._prev_cells = np.zeros((self.num, n), dtype=np.int64)
        self._ever = np.zeros(self.num, dtype=bool)  # agents placed since the reset
        self.free = np.zeros((self.num, n), dtype=bool)
        self.masks = np.zeros((self.num, n, self.n_max), dtype=bool)
        self._mask_cols = self._mask_columns(letters)
        self._agent_col = np.arange(n)[:, None]
        self._world_of = np.repeat(np.arange(self.num), n)  # (B N,) world of each agent

    @staticmethod
    def _mask_columns(letters: list[str]) -> np.ndarray:
        """(N, n_max) column of the condition table (stay, west, east, north, south, climb,
        descend, dump, never) behind each agent's action."""
        order = {"P": (0, 1, 2, 3, 4, 5, 6), "A": (0, 1, 2, 3, 4, 7), "H": tuple(range(8))}
        n_max = max((len(order[r]) for r in letters), default=1)
        cols = np.full((len(letters), n_max), 8, dtype=np.int64)
        for i, r in enumerate(letters):
            cols[i, : len(order[r])] = order[r]
        return cols

    def reset_worlds(self, rows: np.ndarray) -> None:
        """Fresh maps for the worlds ``rows``: no fire known, nothing seen, no agent placed."""
        self.maps[rows, :, :, :4] = 0.0
        self.maps[rows, :, :, D_SEEN] = np.inf
        self.counts[rows] = 0.0
        self._flush()
        self.burning[rows] = 0.0
        self._ever[rows] = False

    # ------------------------------------------------------------------ updates
    def _plane(self, flat: np.ndarray) -> np.ndarray:
        """Flat px cells ``x W + y`` -> their coarse cell's index in one padded (H, H) layer."""
        x, y = np.divmod(flat, self.world_size)
        c, r = self.cell_px, self.radius
        return (x // c + r) * self.h + y // c + r

    def _add(self, layer: int, wb: np.ndarray, flat: np.ndarray, sign: float) -> None:
        """Add ``sign`` per cell to count layer ``layer`` (known or pruned) of worlds ``wb`` and
        rescale the cells touched (``CoarseMaps._add``)."""
        if wb.size == 0:
            return
        cell = wb * (self.h * self.h) + self._plane(flat)
        ic = cell * 2 + layer
        counts = self.counts.reshape(-1)
        np.add.at(counts, ic, np.float32(sign))  # (a float32 scalar: ufunc.at's fast path)
        self.maps.reshape(-1)[cell * N_FOV + layer] = np.minimum(counts[ic] * self._inv_c, 1.0)

    def update(self, info: BatchStepInfo, batch: BatchWorld) -> None:
        """Fold one batch tick into the maps (:meth:`fcplan.env.motion_grid.CoarseMaps.update`)."""
        self._add(D_KNOWN, *info.newly_sensed, 1.0)
        wb, flat = info.ignited
        if wb.size:
            self._pending.append((wb, flat, 1.0))
            self._n_pending += wb.size
        wb, flat = info.pruned
        if wb.size:
            self._pending.append((wb, flat, -1.0))
            self._n_pending += wb.size
            self._add(D_PRUNED, wb, flat, 1.0)
            x, y = np.divmod(flat, self.world_size)
            sensed = (batch.grid.flat_state[batch.grid.index(wb, x, y)] & SENSED) > 0
            self._add(D_KNOWN, wb[sensed], flat[sensed], -1.0)
        if self._n_pending > _PENDING_MAX:
            self._flush()
        ran = info.ran
        if np.count_nonzero(ran):
            stamp = (batch.tick * self.seen_scale).astype(np.float32)
            self._cover(info.fov[:, self._sensing], -stamp, ran)

    def _flush(self) -> None:
        """Bring :attr:`burning` up to date: the ignited and pruned cells of the ticks since the
        last call, queued by :meth:`update` (only :meth:`state` reads the layer), go in with one
        ``np.add.at`` (exact: the counts are whole numbers)."""
        if not self._pending:
            return
        wb, flat, sign = zip(*self._pending, strict=True)
        self._pending.clear()
        self._n_pending = 0
        cell = np.concatenate(wb) * (self.h * self.h) + self._plane(np.concatenate(flat))
        one = np.concatenate(
            [np.full(a.size, g, np.float32) for a, g in zip(wb, sign, strict=True)]
        )
        np.add.at(self.burning.reshape(-1), cell, one)

    def _cover(self, rects: np.ndarray, value: np.ndarray, ran: np.ndarray) -> None:
        """Mark the coarse cells overlapping each rectangle ``rects[b, j]`` of the worlds ``ran``
        as seen with ``value[b]`` (``CoarseMaps._cover`` for every world and sensing agent)."""
        c, nc, r, h = self.cell_px, self.nc, self.radius, self.h
        x0, x1, y0, y1 = (rects[..., k] for k in range(4))
        ok = ran[:, None] & (x1 >= 0) & (y1 >= 0)
        i0 = np.maximum((x0 // c).astype(np.int64), 0)
        i1 = np.minimum((x1 // c).astype(np.int64) + 1, nc)
        j0 = np.maximum((y0 // c).astype(np.int64), 0)
        j1 = np.minimum((y1 // c).astype(np.int64) + 1, nc)
        ok &= (i1 > i0) & (j1 > j0)
        wb, _ = np.nonzero(ok)
        i0, j0 = i0[ok], j0[ok]
        ni, nj = i1[ok] - i0, j1[ok] - j0
        # each rectangle: ni rows of nj cells; a row is a run of flat indices N_FOV apart, the
        # rows of a rectangle h N_FOV apart (no division: runs of aranges shifted per row)
        hs = h * N_FOV
        base = ((wb * h + i0 + r) * h + j0 + r) * N_FOV + D_SEEN
        start = np.repeat(base - hs * (np.cumsum(ni) - ni), ni)
        start += hs * np.arange(start.size)
        run = np.repeat(nj, ni)
        flat = np.repeat(start - N_FOV * (np.cumsum(run) - run), run)
        flat += N_FOV * np.arange(flat.size)
        self.maps.reshape(-1)[flat] = np.repeat(np.repeat(value[wb], ni), run)

    # ------------------------------------------------------------------ observations
    def agent_arrays(self, batch: BatchWorld) -> tuple[np.ndarray, np.ndarray]:
        """(B, N, 15) float32 agent vectors and (B, N, n_max) int8 action masks
        (``MotionObs.agent_arrays`` for every world); keeps the masks and who takes orders."""
        team = batch.team
        w = float(self.world_size)
        inv_w = 1.0 / w
        pos, z, mode = team.pos, team.z, team.mode
        v = np.zeros((self.num, self.n, N_AGENT_FEATURES))
        v[..., 0:2] = pos * inv_w
        zn = (z - team.alt_lo) * team.inv_span
        v[..., 2] = zn
        v[..., 3] = team.battery * (1.0 / team.battery_capacity)
        v[..., 4] = team.tank * (1.0 / np.maximum(team.tank_capacity, 1))
        d = team.home - pos
        d *= d
        home = np.sqrt(d[..., 0] + d[..., 1]) * (DRAIN_PER_PX / team.battery_capacity)
        v[..., 5] = np.minimum(home, 1.0)
        v[..., 6:10] = mode[..., None] == np.arange(4)
        v[..., 10] = team.can_sense
        v[..., 11] = team.can_act
        v[..., 12] = (batch.tick / batch.n_ticks)[:, None]
        conf = 1.0 - 0.6 * zn
        v[..., 13] = np.maximum(conf, 0.4) * team.can_sense
        v[..., 14] = team.speed / w
        free = mode <= _ACTIVE
        sp, hi_lim = team.speed, (w - 1.0) - team.speed
        zt = team.z_target
        cond = np.zeros((self.num, self.n, 9), dtype=bool)
        cond[..., 0] = True
        cond[..., 1] = free & (pos[..., 0] >= sp)
        cond[..., 2] = free & (pos[..., 0] <= hi_lim)
        cond[..., 3] = free & (pos[..., 1] >= sp)
        cond[..., 4] = free & (pos[..., 1] <= hi_lim)
        cond[..., 5] = zt < team.alt_hi - 1e-9
        cond[..., 6] = zt > team.alt_lo + 1e-9
        cond[..., 7] = free & (team.tank > 0)
        masks = cond[:, self._agent_col, self._mask_cols]
        self.free, self.masks = free, masks
        return v.astype(np.float32), masks.view(np.int8)

    def _place_agents(self, cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
        """Mark each world's agents on the agents layer (replacing the last placement); return
        (B, N) float32: 1 where another agent of the world shares the agent's cell."""
        h, r = self.h, self.radius
        cells = (np.arange(self.num)[:, None] * h + cx + r) * h + (cy + r)
        old = np.where(self._ever[:, None], self._prev_cells, cells)
        flat = self.maps.reshape(-1)
        flat[old * N_FOV + D_AGENTS] = 0.0
        flat[cells * N_FOV + D_AGENTS] = 1.0
        self._prev_cells, self._ever[:] = cells, True
        same = cells[:, :, None] == cells[:, None, :]
        return (same.sum(axis=2) > 1).astype(np.float32)

    def observe(self, batch: BatchWorld) -> dict[str, np.ndarray]:
        """The observations of every world: ``{"fov", "agent", "action_mask"}`` arrays with
        batch and agent axes."""
        vec, masks = self.agent_arrays(batch)
        pos = batch.team.pos
        cx = (pos[..., 0] // self.cell_px).astype(np.int64)
        cy = (pos[..., 1] // self.cell_px).astype(np.int64)
        shared = self._place_agents(cx, cy)
        v = self.view
        fov = self.windows[self._world_of, cx.reshape(-1), cy.reshape(-1)]  # (one gather)
        stamp = (batch.tick * self.seen_scale).astype(np.float32)
        stale = fov.reshape(self.num, self.n, N_FOV, v * v)[:, :, D_SEEN]
        stale += stamp[:, None, None]
        np.minimum(stale, _ONE32, out=stale)
        fov[:, D_AGENTS, self.radius, self.radius] = shared.reshape(-1)
        fov = fov.reshape(self.num, self.n, N_FOV, v, v)
        return {"fov": fov, "agent": vec, "action_mask": masks}

    def state(self, batch: BatchWorld) -> np.ndarray:
        """(B, 8, nc, nc) float32 global state of every world (``MotionObs.state``)."""
        r, nc, inv_c = self.radius, self.nc, 1.0 / self.cell_px
        self._flush()
        inner = slice(r, r + nc)
        s = np.zeros((self.num, 8, nc, nc), dtype=np.float32)
        np.minimum(self.burning[:, inner, inner] * inv_c, 1.0, out=s[:, 0])
        np.minimum(self.counts[:, inner, inner, 0] * inv_c, 1.0, out=s[:, 1])
        np.minimum(self.counts[:, inner, inner, 1] * inv_c, 1.0, out=s[:, 2])
        stamp = (batch.tick * self.seen_scale).astype(np.float32)
        np.minimum(self.seen[:, inner, inner] + stamp[:, None, None], _ONE32, out=s[:, 3])
        team = batch.team
        cell = np.clip((team.pos // self.cell_px).astype(np.int64), 0, nc - 1)
        rows = np.broadcast_to(np.arange(self.num)[:, None], cell.shape[:2])
        for k, can in ((4, team.can_sense), (5, team.can_act)):
            np.add.at(s[:, k], (rows[:, can], cell[:, can, 0], cell[:, can, 1]), _ONE32)
        s[:, 6] = self.static[1, inner, inner]
        s[:, 7] = self.static[2, inner, inner]
        return s
