"""``B`` worlds of one scenario advanced one tick per call: :class:`fcplan.World` with a batch axis.

A tick of :class:`BatchWorld` is :meth:`fcplan.World.step` for every running world at once, in the
same order: team motion (:class:`fcplan.batch.team.BatchTeam`), fire steps
(:class:`fcplan.batch.fire.BatchFire`), sensing, pruning (dumps), facility counts and the trace
row. Sensing and dumps find the burning cells of each field of view with
:func:`fcplan.batch.cells.scan_boxes` over all (world, agent) pairs at once and read each world's
sensing and pruning stream through :class:`fcplan.batch.streams.UniformBlocks`, in the single
world's order (agents in row order, cells in ``[x, y]`` row-major order). Dumps of one tick are
taken in rounds, round ``r`` the ``r``-th dumping agent of every world, because a dump changes what
the next agent of the same world finds; the rounds are bounded by the team size, not by ``B``.

Episodes. :meth:`BatchWorld.reset` starts worlds from seeds; without a seed a world takes the next
seed of its own reseed generator (``default_rng(last seed).integers(2**63)``, what
:meth:`fcplan.env.motion.MotionEnv.reset` does without a seed), so world ``i`` of a batch follows
the episodes of a single environment reset with its seed, whatever ``B`` and whatever the other
worlds do. A world whose episode is over (:attr:`BatchWorld.done`) is *held*: :meth:`step` leaves
it untouched until it is reset; ``step(autoreset=True)`` resets the held worlds instead of stepping
them (Gymnasium's next-step autoreset).

What each world keeps per tick is its trace of counts (``active``, ``pruned``, ``sensed_active``,
``sensed_ever``, facility rows; ``(B, T)`` int32, int64 when read) and, with
``record_agents=True``, the agents' rows: :meth:`trace` and :meth:`metrics` give world ``b``'s
:class:`fcplan.trace.Trace` and manual metrics, bit for bit those of the single world.

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> batch = BatchWorld(load_scenario("practice").replace(duration_s=2), 4)
>>> batch.reset(seeds=[0, 1, 2, 3])
>>> while not batch.done.all():
...     info = batch.step()
>>> batch.tick.tolist(), sorted(batch.metrics(2)), bool(batch.step().ran.any())  # all held
([20, 20, 20, 20], ['manual', 'reference2020'], False)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from fcplan._fast.fire import unique
from fcplan.batch.cells import SENSED, STATE_BITS, CellGrid, runs, scan_boxes
from fcplan.batch.fire import BatchFire
from fcplan.batch.streams import UniformBlocks, spawn_streams, world_seeds
from fcplan.batch.team import BatchTeam
from fcplan.fire import BURNING
from fcplan.scenario import Scenario
from fcplan.team import per_tick_probability
from fcplan.trace import TRACE_FIELDS, Trace
from fcplan.world import World

__all__ = ["BatchWorld", "BatchStepInfo"]

_EMPTY = np.zeros(0, dtype=np.int64)
_BURNING_SENSED = BURNING | SENSED


@dataclass(frozen=True, slots=True, eq=False)
class BatchStepInfo:
    """What happened in one :meth:`BatchWorld.step` (cells as world index and flat ``x W + y``,
    sorted by world; within a world ``ignited`` keeps the single world's order, the others are
    sorted by cell).

    Attributes
    ----------
    ran, reset : ndarray, (B,) bool
        Worlds that took a tick; worlds reset instead (``autoreset``).
    ignited, sensed, newly_sensed, pruned : tuple of two ndarray, (k,) int64
        ``(world, flat)`` of the cells that started burning, were sensed this tick, were sensed
        for the first time, were put out.
    fov : ndarray, (B, N, 4) float64
        Every agent's field of view after moving.
    dumped, arrived : ndarray, (B, N) bool
        Agents that dumped; agents that reached a route goal.
    """

    ran: np.ndarray
    reset: np.ndarray
    ignited: tuple[np.ndarray, np.ndarray]
    sensed: tuple[np.ndarray, np.ndarray]
    newly_sensed: tuple[np.ndarray, np.ndarray]
    pruned: tuple[np.ndarray, np.ndarray]
    fov: np.ndarray
    dumped: np.ndarray
    arrived: np.ndarray


class BatchWorld:
    """``num`` worlds of ``scenario`` stepped together (module docstring).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    num : int
        Worlds ``B``.
    record_agents : bool
        Keep the agents' trace rows too (:meth:`trace` needs them; metrics do not).

    Attributes
    ----------
    tick : ndarray, (B,) int64
    fire : BatchFire
    team : BatchTeam
    grid : CellGrid
    facility_burning, facility_pruned : ndarray, (B, F) int64
    n_sensed_active, n_sensed_ever : ndarray, (B,) int64
    controller_rngs : list of numpy.random.Generator
        Each world's controller stream (:attr:`fcplan.World.controller_rng`).
    seeds : list
        The seed of each world's current episode.
    """

    def __init__(self, scenario: Scenario, num: int, *, record_agents: bool = False) -> None:
        if int(num) < 1:
            raise ValueError(f"num: must be >= 1 (got {num})")
        self.scenario = scenario
        self.num = b = int(num)
        self.world_size = w = scenario.world_size
        self.n_ticks = scenario.n_ticks
        self.tps = scenario.ticks_per_second
        one = World(scenario, seed=0)  # the facility footprints, computed by the world's code
        self.facility_labels = one.facility_labels.reshape(-1)
        self.facility_penalties = one.facility_penalties
        self.n_facilities = f = one.n_facilities
        self.grid = CellGrid(b, w)
        self.fire = BatchFire(scenario, b, self.grid)
        self.team = BatchTeam(scenario, b)
        self._sensing = np.flatnonzero(self.team.can_sense)
        self._shift = int(w - 1).bit_length()  # (bit fields of sortable (world, x, y) keys)
        self._mask = (1 << self._shift) - 1
        self._sense_streams = UniformBlocks(b)
        self._prune_streams = UniformBlocks(b)
        self.controller_rngs: list[np.random.Generator | None] = [None] * b
        self._reseed: list[np.random.Generator | None] = [None] * b
        self.seeds: list[Any] = [None] * b
        self.tick = np.zeros(b, dtype=np.int64)
        self.facility_burning = np.zeros((b, f), dtype=np.int64)
        self.facility_pruned = np.zeros((b, f), dtype=np.int64)
        self.n_sensed_active = np.zeros(b, dtype=np.int64)
        self.n_sensed_ever = np.zeros(b, dtype=np.int64)
        self.record_agents = bool(record_agents)
        t = max(self.n_ticks, 1)
        self._counts = np.zeros((4, b, t), dtype=np.int32)  # active, pruned, s_active, s_ever
        self._fac = np.zeros((2, b, t, f), dtype=np.int32)  # burning, pruned
        self._agents: dict[str, np.ndarray] = {}
        if self.record_agents:
            dims = {"T": t, "N": self.team.n, "F": f}
            for fld in TRACE_FIELDS:
                if fld.agent:
                    z = fld.zeros(dims)
                    self._agents[fld.name] = np.zeros((b, *z.shape), dtype=z.dtype)
        self._started = np.zeros(b, dtype=bool)

    # ------------------------------------------------------------------ episodes
    @property
    def done(self) -> np.ndarray:
        """(B,) bool: the world's episode is over (held until reset)."""
        return self.tick >= self.n_ticks

    def reset(self, seeds: Sequence[Any] | int | None = None, mask: Any = None) -> None:
        """Start new episodes in every world, or in the worlds of ``mask`` ((B,) bool).

        Parameters
        ----------
        seeds : sequence, int or None
            Seeds by :func:`fcplan.batch.streams.world_seeds` (Gymnasium's rule): one per world,
            or with ``mask`` one per masked world; an int ``s`` gives world ``b`` the seed
            ``s + b``, whichever worlds are reset. A None seed takes the world's next seed from
            its reseed generator (module docstring), or fresh entropy before its first seeded
            episode.
        """
        rows = np.arange(self.num) if mask is None else np.flatnonzero(mask)
        for b, seed in zip(rows.tolist(), world_seeds(self.num, rows, seeds), strict=True):
            self._reset_world(b, seed)
        self.team.reset_worlds(rows)

    def _reset_world(self, b: int, seed: Any) -> None:
        if seed is not None:
            self._reseed[b] = np.random.default_rng(seed)
        elif self._reseed[b] is not None:
            seed = int(self._reseed[b].integers(2**63))  # type: ignore[union-attr]
        self.seeds[b] = seed
        rng_fire, rng_sense, rng_prune, self.controller_rngs[b] = spawn_streams(seed)
        self.grid.clear(b)
        self.fire.reset_world(b, rng_fire)
        self._sense_streams.reset(b, rng_sense)
        self._prune_streams.reset(b, rng_prune)
        self.tick[b] = 0
        self.facility_burning[b] = self.facility_pruned[b] = 0
        self.n_sensed_active[b] = self.n_sensed_ever[b] = 0
        self._started[b] = True

    # ------------------------------------------------------------------ step
    def step(self, *, autoreset: bool = False, mask: np.ndarray | None = None) -> BatchStepInfo:
        """Advance every running world one tick (held worlds stay; with ``autoreset`` they are
        reset instead and not stepped; ``mask``, (B,) bool, holds the others too); return what
        happened."""
        if not self._started.all():
            raise ValueError("BatchWorld.step before reset() of every world")
        done = self.done
        reset = done if autoreset else np.zeros(self.num, dtype=bool)
        if autoreset and np.count_nonzero(done):
            self.reset(mask=done)
        run = ~done if mask is None else ~done & mask
        team = self.team
        arrived = team.move(run)
        self.tick += run
        ignited = self._fire_steps(run)
        rects = team.fov_rects()
        sensed, newly = self._sense(rects, run)
        dumped = np.zeros((self.num, team.n), dtype=bool)
        pruned: tuple[np.ndarray, np.ndarray] = (_EMPTY, _EMPTY)
        if np.count_nonzero(team.armed):
            pruned = self._prune(rects, run, dumped)
        self._record(run)
        return BatchStepInfo(run, reset, ignited, sensed, newly, pruned, rects, dumped, arrived)

    def _fire_steps(self, run: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fire steps due in this tick (one per tick at 10 ticks per second); the cells that
        started burning, counted in the facilities."""
        fire, w = self.fire, self.world_size
        due = np.where(run, fire.steps_due(self.tick), 0)
        parts = [fire.step(due > s) for s in range(int(due.max(initial=0)))]
        parts = [p for p in parts if p[0].size]
        if not parts:
            return _EMPTY, _EMPTY
        wb, x, y = (np.concatenate(a) for a in zip(*parts, strict=True))
        if len(parts) > 1:  # (sorted by world, as one step's)
            order = np.argsort(wb, kind="stable")
            wb, x, y = wb[order], x[order], y[order]
        flat = x * w + y
        self._count_facilities(wb, flat, self.facility_burning, +1)
        return wb, flat

    def _count_facilities(
        self, wb: np.ndarray, flat: np.ndarray, into: np.ndarray, sign: int
    ) -> None:
        lab = self.facility_labels[flat]
        inside = lab >= 0
        if np.count_nonzero(inside):
            np.add.at(
                into.reshape(-1), wb[inside] * self.n_facilities + lab[inside], np.int64(sign)
            )

    # ------------------------------------------------------------------ sensing and dumps
    def _boxes(self, rects: np.ndarray, box: np.ndarray) -> tuple[np.ndarray, ...]:
        """Inclusive cell ranges of ``rects`` ((P, K, 4)) inside the map and the fire's boxes
        ``box`` ((P, 4), one per row of ``rects``)."""
        w = self.world_size
        x0 = np.maximum(np.maximum(np.ceil(rects[..., 0]), 0), box[:, 0:1]).astype(np.int64)
        x1 = np.minimum(np.minimum(np.floor(rects[..., 1]), w - 1), box[:, 1:2]).astype(np.int64)
        y0 = np.maximum(np.maximum(np.ceil(rects[..., 2]), 0), box[:, 2:3]).astype(np.int64)
        y1 = np.minimum(np.minimum(np.floor(rects[..., 3]), w - 1), box[:, 3:4]).astype(np.int64)
        return x0, x1, y0, y1

    def _sense(self, rects: np.ndarray, run: np.ndarray) -> tuple[tuple, tuple]:
        """Every sensing agent observes the burning cells in view (``World._sense``)."""
        fire, s = self.fire, self._sensing
        live = run & (fire.n_burning > 0)
        if not np.count_nonzero(live) or s.size == 0:
            return (_EMPTY, _EMPTY), (_EMPTY, _EMPTY)
        x0, x1, y0, y1 = self._boxes(rects[:, s], fire.burn_box)
        ok = live[:, None] & (x0 <= x1) & (y0 <= y1)
        pw, pa = np.nonzero(ok)
        if pw.size == 0:
            return (_EMPTY, _EMPTY), (_EMPTY, _EMPTY)
        pair, x, y = scan_boxes(self.grid, pw, x0[ok], x1[ok], y0[ok], y1[ok], _burning)
        if pair.size == 0:
            return (_EMPTY, _EMPTY), (_EMPTY, _EMPTY)
        wb = pw[pair]
        start, per_world = runs(wb)
        u = self._sense_streams.take(wb[start], per_world)
        conf = self.team.sensing_confidence()[pw, s[pa]]
        if self.tps != 10:  # (Python floats: the single world's own power function)
            conf = np.array([per_tick_probability(float(c), self.tps) for c in conf.tolist()])
        keep = u < conf[pair]
        wb, x, y = wb[keep], x[keep], y[keep]
        if np.count_nonzero(pw[1:] == pw[:-1]):  # two agents of a world may see the same cell
            sh = self._shift
            key = unique((wb << (2 * sh)) | (x << sh) | y)
            wb, x, y = key >> (2 * sh), (key >> sh) & self._mask, key & self._mask
        flat = x * self.world_size + y
        g = self.grid.index(wb, x, y)
        new = (self.grid.flat_state[g] & SENSED) == 0
        if np.count_nonzero(new):
            self.grid.flat_state[g[new]] |= SENSED
            counts = np.bincount(wb[new], minlength=self.num)
            self.n_sensed_active += counts
            self.n_sensed_ever += counts
        return (wb, flat), (wb[new], flat[new])

    def _prune(self, rects: np.ndarray, run: np.ndarray, dumped: np.ndarray) -> tuple:
        """Armed agents dump (``World._prune``), in rounds of one agent per world."""
        team, fire = self.team, self.fire
        cand = team.armed & team.can_act & (team.tank > 0)
        cand &= (run & (fire.n_burning > 0))[:, None]
        if not np.count_nonzero(cand):
            return _EMPTY, _EMPTY
        rank = np.cumsum(cand, axis=1) - 1
        parts = []
        for r in range(int(rank[cand].max()) + 1):
            pw, pa = np.nonzero(cand & (rank == r))
            hit = self._dump_round(rects, pw, pa, dumped)
            if hit[0].size:
                parts.append(hit)
        if not parts:
            return _EMPTY, _EMPTY
        wb, flat = (np.concatenate(a) for a in zip(*parts, strict=True))
        order = np.lexsort((flat, wb))
        return wb[order], flat[order]

    def _dump_round(
        self, rects: np.ndarray, pw: np.ndarray, pa: np.ndarray, dumped: np.ndarray
    ) -> tuple:
        """One dumping agent ``pa[j]`` in each world ``pw[j]``: the (world, flat) cells put out."""
        x0, x1, y0, y1 = self._boxes(rects[pw, pa][:, None], self.fire.burn_box[pw])
        x0, x1, y0, y1 = x0[:, 0], x1[:, 0], y0[:, 0], y1[:, 0]
        ok = (x0 <= x1) & (y0 <= y1) & (self.fire.n_burning[pw] > 0)
        pw, pa, x0, x1, y0, y1 = pw[ok], pa[ok], x0[ok], x1[ok], y0[ok], y1[ok]
        reference = self.scenario.action_gate == "reference"
        test = _burning if reference else _burning_sensed
        pair, x, y = scan_boxes(self.grid, pw, x0, x1, y0, y1, test)
        if pair.size == 0:
            return _EMPTY, _EMPTY
        g = self.grid.index(pw[pair], x, y)
        if reference:  # dump if one of them was sensed, or nothing is sensed anywhere
            seen = np.bincount(pair, self.grid.flat_state[g] == _BURNING_SENSED, minlength=pw.size)
            go = (seen > 0) | (self.n_sensed_active[pw] == 0)
            sel = go[pair]
            pair, x, y, g = pair[sel], x[sel], y[sel], g[sel]
            if pair.size == 0:
                return _EMPTY, _EMPTY
        ones, per_pair = runs(pair)
        ones = pair[ones]
        u = self._prune_streams.take(pw[ones], per_pair)
        keep = u < self.team.prune_confidence[pa[pair]]
        hit_w, hx, hy, hg = pw[pair][keep], x[keep], y[keep], g[keep]
        if hit_w.size:
            was_sensed = (self.grid.flat_state[hg] & SENSED) > 0
            self.fire.prune(hit_w, hx, hy)
            flat = hx * self.world_size + hy
            self._count_facilities(hit_w, flat, self.facility_burning, -1)
            self._count_facilities(hit_w, flat, self.facility_pruned, +1)
            self.n_sensed_active -= np.bincount(hit_w[was_sensed], minlength=self.num)
        m = np.zeros_like(dumped)
        m[pw[ones], pa[ones]] = True
        dumped |= m
        self.team.record_dumps(m)
        return hit_w, hx * self.world_size + hy

    # ------------------------------------------------------------------ trace
    def _record(self, run: np.ndarray) -> None:
        """Write each running world's trace row of the tick just taken."""
        rows = np.flatnonzero(run)
        if rows.size == 0:
            return
        k = self.tick[rows] - 1
        if rows.size == self.num and k[0] == k[-1] and (k == k[0]).all():
            k, rows = int(k[0]), slice(None)  # type: ignore[assignment]  # (all at one tick)
        c = self._counts
        c[0, rows, k] = self.fire.n_burning[rows]
        c[1, rows, k] = self.fire.n_pruned[rows]
        c[2, rows, k] = self.n_sensed_active[rows]
        c[3, rows, k] = self.n_sensed_ever[rows]
        self._fac[0, rows, k] = self.facility_burning[rows]
        self._fac[1, rows, k] = self.facility_pruned[rows]
        if self.record_agents:
            team, a = self.team, self._agents
            a["xyz"][rows, k, :, :2] = team.pos[rows]
            a["xyz"][rows, k, :, 2] = team.z[rows]
            a["battery"][rows, k] = team.battery[rows]
            a["tank"][rows, k] = team.tank[rows]
            a["mode"][rows, k] = team.mode[rows]
            a["dumps"][rows, k] = team.dumps[rows]

    def trace_rows(self, b: int) -> dict[str, np.ndarray]:
        """World ``b``'s trace rows so far (copies, the trace's dtypes; agent rows only with
        ``record_agents``)."""
        t = int(self.tick[b])
        names = ("active", "pruned", "sensed_active", "sensed_ever")
        rows = {k: self._counts[i, b, :t].astype(np.int64) for i, k in enumerate(names)}
        rows["facility_burning"] = self._fac[0, b, :t].astype(np.int64)
        rows["facility_pruned"] = self._fac[1, b, :t].astype(np.int64)
        for name, arr in self._agents.items():
            rows[name] = arr[b, :t].copy()
        return rows

    def trace_sum(self, b: int, name: str, start: int, stop: int) -> np.ndarray:
        """Sum over trace rows ``start:stop`` of world ``b``'s count array ``name`` (one of
        ``active``, ``pruned``, ``sensed_active``, ``sensed_ever``, ``facility_burning``,
        ``facility_pruned``), as int64: :meth:`fcplan.World.trace_sum`."""
        names = ("active", "pruned", "sensed_active", "sensed_ever")
        if name in names:
            rows = self._counts[names.index(name), b, start:stop]
        else:
            rows = self._fac[("facility_burning", "facility_pruned").index(name), b, start:stop]
        return rows.astype(np.int64).sum(axis=0)

    def trace(self, b: int) -> Trace:
        """World ``b``'s :class:`fcplan.trace.Trace` (needs ``record_agents=True``)."""
        if not self.record_agents:
            raise ValueError("trace: make the batch with record_agents=True (metrics() needs none)")
        return Trace.from_rows(self.scenario, self.trace_rows(b), self.team.ids)

    def metrics(self, b: int) -> dict[str, Any]:
        """World ``b``'s metrics of both definitions (:func:`fcplan.metrics.compute_all`)."""
        from fcplan.metrics import compute_all

        rows = self.trace_rows(b)
        if not self.record_agents:  # (no metric reads the agents' rows)
            t, n, f = int(self.tick[b]), self.team.n, self.n_facilities
            for fld in TRACE_FIELDS:
                if fld.agent:
                    rows[fld.name] = fld.zeros({"T": t, "N": n, "F": f})
        return compute_all(Trace.from_rows(self.scenario, rows, self.team.ids))

    def cells(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """World ``b``'s fire state ((W, W) uint8, as ``Fire.state``) and sensed cells
        ((W, W) bool, as ``World.sensed``)."""
        a = self.grid.world_array(b)
        return a & STATE_BITS, (a & SENSED) > 0


def _burning(v: np.ndarray) -> np.ndarray:
    return (v & STATE_BITS) == BURNING


def _burning_sensed(v: np.ndarray) -> np.ndarray:
    return v == _BURNING_SENSED
