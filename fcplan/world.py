"""The world: fire, team, sensing, pruning and facility damage, advanced one fixed tick at a time.

:class:`World` is usable on its own, without any scheduler: ``reset(scenario, seed)`` then
``step(commands)`` as often as you like. Each tick runs, in this order (the reference MARL order):

1. apply the commands (:class:`fcplan.team.Command` per agent id);
2. agents move, dock, recharge, and apply the battery and 3-second rules;
3. the fire propagates (regions activate after their delay);
4. every perception/hybrid agent senses: each burning cell inside its field of view is sensed
   independently with the agent's altitude confidence; a sensed cell stays sensed;
5. every armed action/hybrid agent dumps if a dump can do something: each *sensed* burning cell in
   its field of view is pruned with its prune confidence (the manual's rule that action needs
   perception first). With ``scenario.action_gate == "reference"`` the 2020 code's looser gate is
   used instead: every burning cell in view may be pruned, provided one of them was sensed or
   nothing is sensed anywhere;
6. facility counts and the trace row are updated.

Randomness comes from four independent streams spawned from the seed (fire, sensing, pruning, and
one for whoever controls the team, :attr:`World.controller_rng`), so the fire's evolution depends
only on the seed and on where cells were pruned.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.team import Command
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> info = world.step({"P1": Command(route=((350.0, 350.0),), altitude=60.0)})
>>> while not world.done:
...     info = world.step()
>>> world.tick == world.scenario.n_ticks
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from fcplan._fast.team import sensing_confidence_of
from fcplan._fast.world import scan_box as _scan_box
from fcplan._fast.world import step_info_builder
from fcplan.errors import SeedError
from fcplan.fire import _BURNING8, Fire, _unique
from fcplan.shared_views import KeepsViews
from fcplan.team import Command, Team, per_tick_probability
from fcplan.trace import TRACE_FIELDS, Trace

if TYPE_CHECKING:
    from fcplan.scenario import Scenario

#: What seeds an episode: an int, a SeedSequence, a Generator, or None (fresh OS entropy).
Seed = int | np.integer | np.random.SeedSequence | np.random.Generator | None

__all__ = ["World", "StepInfo"]

_EMPTY = np.zeros(0, dtype=np.int64)
_EMPTY16 = np.zeros(0, dtype=np.int16)
_ZERO16 = np.int16(0)
_NO_OFFSETS = np.zeros((0, 0), dtype=np.int64)


@dataclass(frozen=True, slots=True, eq=False)
class StepInfo:
    """What happened during one tick (flat cell indices are ``x * W + y``)."""

    tick: int
    time_s: float
    ignited: np.ndarray  # (k,) int64 cells that started burning
    sensed: np.ndarray  # (k,) int64 cells sensed this tick (unique)
    newly_sensed: np.ndarray  # (k,) int64 cells sensed for the first time
    pruned: np.ndarray  # (k,) int64 cells put out this tick
    fov_rects: list  # (N,) lists [x0, x1, y0, y1] of floats: every agent's field of view
    dumped: tuple[int, ...]  # rows of agents that dumped
    arrived: tuple[int, ...]  # rows of agents that reached a route goal

    @property
    def fov(self) -> np.ndarray:
        """(N, 4) float64 ``[x0, x1, y0, y1]`` inclusive field of view of every agent after
        moving (built from :attr:`fov_rects` on each access)."""
        return np.array(self.fov_rects, dtype=np.float64).reshape(-1, 4)


_step_info = step_info_builder(StepInfo)  # StepInfo(...), cheaper


class World(KeepsViews):
    """Fire, team and scoring state of one episode.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario, optional
        If given, the world is reset at once with ``seed``.
    seed : int, numpy.random.SeedSequence or numpy.random.Generator, optional

    Attributes
    ----------
    scenario : Scenario
    fire : fcplan.fire.Fire
    team : fcplan.team.Team
    sensed : ndarray, (W, W) bool
        Cells sensed at least once.
    facility_burning, facility_pruned : ndarray, (F,) int64
        Per scored facility (houses, hospitals, power stations, depot last): burning cells inside
        its footprint, and cumulative pruned cells inside it. Read only: the world changes them
        (the trace copies them lazily, from the last change on).
    """

    scenario: Scenario  # set by the first reset()

    def __init__(self, scenario: Scenario | None = None, seed: Seed = None) -> None:
        # (a flag, not a look into __dict__: reading an instance's __dict__ makes Python 3.11+
        # materialise it, and every attribute access of the per-tick path gets slower)
        self._started = False
        if scenario is not None:
            self.reset(scenario, seed)

    # ------------------------------------------------------------------ setup
    def reset(self, scenario: Scenario | None = None, seed: Seed = None) -> World:
        """Start a new episode (same scenario if none is given); return ``self``."""
        if scenario is None:
            if not self._started:
                raise ValueError("World.reset needs a scenario the first time")
            scenario = self.scenario
        self.scenario = scenario
        self.seed = seed
        streams = _spawn(seed, 4)
        rng_fire, self.rng_sense, self.rng_prune, self.controller_rng = streams
        w = scenario.world_size
        self.world_size = w
        self.fire = Fire(
            scenario.regions, w, scenario.ticks_per_second, rng_fire, wind_model=scenario.wind_model
        )
        self.team = Team(scenario)
        self._tps = scenario.ticks_per_second
        self._sensing_rows = np.flatnonzero(self.team.can_sense).tolist()
        self._can_act = self.team.can_act.tolist()
        self.sensed = np.zeros((w, w), dtype=bool)
        self._sensed_flat = self.sensed.reshape(-1)
        self._box_offsets = _NO_OFFSETS  # (see _cells)
        facilities = scenario.scored_facilities
        self.facility_labels = np.full((w, w), -1, dtype=np.int16)
        for f, fac in enumerate(facilities):
            x0, x1, y0, y1 = fac.footprint  # open bounds: x0 < x < x1
            xs, xe = max(math.floor(x0) + 1, 0), min(math.ceil(x1) - 1, w - 1)
            ys, ye = max(math.floor(y0) + 1, 0), min(math.ceil(y1) - 1, w - 1)
            if xe >= xs and ye >= ys:
                self.facility_labels[xs : xe + 1, ys : ye + 1] = f
        self._labels_flat = self.facility_labels.reshape(-1)
        self.n_facilities = len(facilities)
        self.facility_penalties = np.array([f.penalty for f in facilities], dtype=np.float64)
        self.facility_burning = np.zeros(self.n_facilities, dtype=np.int64)
        self.facility_pruned = np.zeros(self.n_facilities, dtype=np.int64)
        self.n_sensed_active = 0
        self.n_sensed_ever = 0
        self.tick = 0
        self._alloc_trace(scenario.n_ticks)
        self._started = True
        return self

    def _alloc_trace(self, rows: int) -> None:
        """Allocate ``rows`` trace rows of every :data:`fcplan.trace.TRACE_FIELDS` array, by the
        field's row name (agent fields without their ``agent_`` prefix)."""
        dims = {"T": max(rows, 1), "N": self.team.n, "F": self.n_facilities}
        self._rows: dict[str, np.ndarray] = {f.name: f.zeros(dims) for f in TRACE_FIELDS}
        self._n_recorded = 0  # trace rows recorded (ticks stepped since the reset)
        self._fac_rows = 0  # facility trace rows written so far (see _sync_facility_rows)
        self._record_views()

    # ------------------------------------------------------------------ queries
    @property
    def time_s(self) -> float:
        """Simulated seconds elapsed."""
        return self.tick / self.scenario.ticks_per_second

    @property
    def done(self) -> bool:
        """True once the scenario's duration has been simulated."""
        return self.tick >= self.scenario.n_ticks

    def trace(self) -> Trace:
        """The per-tick record so far (copies), ready for :func:`fcplan.metrics.compute_metrics`."""
        self._sync_facility_rows()
        rows = {k: v[: self.tick].copy() for k, v in self._rows.items()}
        return Trace.from_rows(self.scenario, rows, self.team.ids)

    def trace_sum(self, name: str, start: int, stop: int) -> np.ndarray:
        """Sum over ticks ``start + 1 .. stop`` (trace rows ``start:stop``) of one trace array
        (a name of :meth:`trace`'s rows, e.g. ``"active"``, ``"facility_burning"``), read in
        place without copying the trace.

        Returns
        -------
        ndarray
            The array's row dtype and shape without the tick axis (zeros for an empty range).
        """
        self._sync_facility_rows()
        return self._rows[name][start:stop].sum(axis=0)

    def ignite(self, xy: npt.ArrayLike) -> np.ndarray:
        """Set cells burning by hand (spot fires, tests); return the flat indices that ignited.

        Parameters
        ----------
        xy : array_like, (k, 2)
            Integer cell coordinates inside the map. Pruned or burning cells are left alone.
        """
        xy = np.asarray(xy, dtype=np.int64).reshape(-1, 2)
        w = self.world_size
        if xy.size and (xy.min() < 0 or xy.max() >= w):
            raise ValueError(f"cells must lie in 0..{w - 1}")
        new = self.fire._ignite(xy[:, 0] * w + xy[:, 1])
        if new.size:
            self._count_facilities(new, +1)
        return new

    # ------------------------------------------------------------------ dynamics
    def step(self, commands: Mapping[str | int, Command] | None = None) -> StepInfo:
        """Advance one tick with optional per-agent commands; return what happened."""
        if not self._started:
            raise ValueError("World.step before World.reset")
        team, fire = self.team, self.fire
        if commands:  # (Team.apply does nothing without commands: the call is saved)
            team.apply(commands)
        arrived = team.move()
        self.tick = tick = self.tick + 1
        ignited = fire.step()
        if ignited.size:
            self._count_facilities(ignited, +1)
        rects = team.fov_rects_list()
        sensed, newly = self._sense(rects)
        if True in team.armed.tolist():  # (else _prune finds no dump: the call is saved)
            pruned, dumped_rows = self._prune(rects)
            dumped: tuple[int, ...] = tuple(dumped_rows)
        else:
            pruned, dumped = _EMPTY, ()
        self._record(tick - 1)
        return _step_info(  # StepInfo(...), cheaper
            tick,
            tick / self._tps,  # time_s
            ignited,
            sensed,
            newly,  # newly_sensed
            pruned,
            rects,  # fov_rects
            dumped,
            tuple(arrived.tolist()) if arrived.size else (),  # arrived
        )

    def _count_facilities(self, flat: np.ndarray, sign: int) -> np.ndarray:
        lab = self._labels_flat[flat]
        if lab.size <= 32 and max(lab.tolist(), default=-1) < 0:  # (usual: no facility there)
            return _EMPTY16
        inside = lab >= _ZERO16
        if not np.count_nonzero(inside):  # (the usual case: no facility there)
            return _EMPTY16
        lab = lab[inside]
        counts = np.bincount(lab, minlength=self.n_facilities)
        self._sync_facility_rows()  # (the rows so far hold the counts before this change)
        self.facility_burning += sign * counts
        return counts

    def _sense(self, rects: list) -> tuple[np.ndarray, np.ndarray]:
        fire = self.fire
        if fire.n_burning == 0:  # nothing to sense (and no random draws, as in the loop below)
            return _EMPTY, _EMPTY
        team, w = self.team, self.world_size
        state, blocks = fire.state, fire.block_burning
        bx0, bx1, by0, by1 = fire.burn_box
        parts = []
        for i in self._sensing_rows:
            r = rects[i]
            # no burning cell in view (every cell of the range is outside the fire's box): the
            # scan below would find none and draw nothing
            if r[1] < bx0 or r[0] > bx1 or r[3] < by0 or r[2] > by1:
                continue
            box = _scan_box(r, blocks, w)
            if box is None:
                continue
            x0, x1, y0, y1 = box
            flat = self._cells(state[x0:x1, y0:y1] == _BURNING8, x0, y0)
            if flat.size == 0:
                continue
            p = per_tick_probability(sensing_confidence_of(team, i), self._tps)
            keep = self.rng_sense.random(flat.size) < p
            if np.count_nonzero(keep):
                parts.append(flat[keep])
        if not parts:
            return _EMPTY, _EMPTY
        sensed = parts[0] if len(parts) == 1 else _unique(np.concatenate(parts))
        seen = self._sensed_flat[sensed]
        if np.count_nonzero(seen) == seen.size:  # (usual: every cell sensed before)
            return sensed, _EMPTY
        newly = sensed[~seen]
        self._sensed_flat[newly] = True
        self.n_sensed_active += int(newly.size)
        self.n_sensed_ever += int(newly.size)
        return sensed, newly

    def _cells(self, mask: np.ndarray, x0: int, y0: int) -> np.ndarray:
        """(k,) int64 flat indices ``(x0 + i) W + y0 + j`` of the true cells ``(i, j)`` of a 2-D
        bool ``mask`` over the cell box starting at ``(x0, y0)``, row-major (the order of
        ``mask.nonzero()``).

        One boolean selection from a cached grid of in-box offsets ``i W + j`` (grown on demand
        to the largest box seen), then one add: far cheaper than the 2-D ``nonzero`` and the
        arithmetic on its two index arrays.
        """
        h, bw = mask.shape
        off = self._box_offsets
        if h > off.shape[0] or bw > off.shape[1]:
            h_max, bw_max = max(h, off.shape[0]), max(bw, off.shape[1])
            off = np.arange(h_max, dtype=np.int64)[:, None] * self.world_size
            off = off + np.arange(bw_max, dtype=np.int64)
            off.flags.writeable = False
            self._box_offsets = off
        flat = off[:h, :bw][mask]
        flat += x0 * self.world_size + y0
        return flat

    def _prune(self, rects: list) -> tuple[np.ndarray, list[int]]:
        team, w = self.team, self.world_size
        armed = team.armed.tolist()
        if True not in armed:
            return _EMPTY, []
        fire = self.fire
        if fire.n_burning == 0:  # no dump can find a burning cell
            return _EMPTY, []
        bx0, bx1, by0, by1 = fire.burn_box
        # armed, able to act, tank not empty, and a burning cell may be in view (outside the
        # fire's box the scan below finds nothing: no draw, no dump)
        rows = [
            i
            for i, (a, act, t, r) in enumerate(
                zip(armed, self._can_act, team.tank.tolist(), rects, strict=True)
            )
            if a and act and t > 0 and not (r[1] < bx0 or r[0] > bx1 or r[3] < by0 or r[2] > by1)
        ]
        if not rows:
            return _EMPTY, []
        reference_gate = self.scenario.action_gate == "reference"
        state, sensed, blocks = fire.state, self.sensed, fire.block_burning
        parts, dumped = [], []
        for i in rows:
            box = _scan_box(rects[i], blocks, w)
            if box is None:
                continue
            x0, x1, y0, y1 = box
            burning = state[x0:x1, y0:y1] == _BURNING8
            seen = burning & sensed[x0:x1, y0:y1]
            # (np.count_nonzero: the cheapest "any" on these small masks)
            if reference_gate:
                some_seen = self.n_sensed_active == 0 or np.count_nonzero(seen)
                if not some_seen or not np.count_nonzero(burning):
                    continue
                cand = burning
            else:
                if not np.count_nonzero(seen):
                    continue
                cand = seen
            flat = self._cells(cand, x0, y0)
            keep = self.rng_prune.random(flat.size) < team.prune_confidence[i]
            flat = flat[keep]
            hit = self.fire.prune(flat)
            if hit.size:
                counts = self._count_facilities(hit, -1)  # (syncs the facility rows first)
                if counts.size:
                    self.facility_pruned += counts
                self.n_sensed_active -= int(np.count_nonzero(self._sensed_flat[hit]))
                parts.append(hit)
            team.record_dump(i)
            dumped.append(i)
        if not parts:
            return _EMPTY, dumped
        return (parts[0] if len(parts) == 1 else np.concatenate(parts)), dumped

    def _record_views(self) -> None:
        """Cache the trace arrays :meth:`_record` writes every tick (the xy and z parts of ``xyz``
        apart; not the facility rows, see :meth:`_sync_facility_rows`)."""
        r = self._rows
        self._row_views: tuple[Any, ...] = (
            len(r["active"]),
            r["active"],
            r["pruned"],
            r["sensed_active"],
            r["sensed_ever"],
            r["xyz"][:, :, :2],
            r["xyz"][:, :, 2],
            r["battery"],
            r["tank"],
            r["mode"],
            r["dumps"],
        )

    def _sync_facility_rows(self) -> None:
        """Write the facility trace rows left unwritten by :meth:`_record`.

        The facility counts change rarely (fire inside a footprint), so :meth:`_record` does not
        copy them every tick: the recorded rows from ``_fac_rows`` on all hold the current
        ``facility_burning`` and ``facility_pruned``. This fills them, and must run before those
        arrays change (:meth:`_count_facilities`, which every change goes through first) and
        before the trace rows are read (:meth:`trace`, :meth:`trace_sum`).
        """
        k0, k1 = self._fac_rows, self._n_recorded
        if k1 > k0:
            rows = self._rows
            rows["facility_burning"][k0:k1] = self.facility_burning
            rows["facility_pruned"][k0:k1] = self.facility_pruned
            self._fac_rows = k1

    def _record(self, k: int) -> None:
        """Write trace row ``k`` (tick ``k + 1``), growing the trace if needed (the facility
        rows are written later, by :meth:`_sync_facility_rows`)."""
        if k >= self._row_views[0]:
            rows = self._rows
            for name, arr in rows.items():
                rows[name] = np.concatenate([arr, np.zeros_like(arr)])
            self._record_views()
        _, active, pruned, s_active, s_ever, xy, z, bat, tank, mode, dumps = self._row_views
        team, fire = self.team, self.fire
        active[k] = fire.n_burning
        pruned[k] = fire.n_pruned
        s_active[k] = self.n_sensed_active
        s_ever[k] = self.n_sensed_ever
        xy[k] = team.pos
        z[k] = team.z
        bat[k] = team.battery
        tank[k] = team.tank
        mode[k] = team.mode
        dumps[k] = team.dumps
        self._n_recorded = k + 1


def check_seed(seed: Any, *, generator: bool = True) -> Seed:
    """``seed`` if it is a seed the world takes: an integer >= 0 (not a bool), a
    ``SeedSequence``, a ``Generator`` (when ``generator``) or None; else a one-line
    :class:`~fcplan.errors.SeedError` (numpy's own errors name neither the argument nor the
    allowed values, and it takes ``True`` as 1).

    Examples
    --------
    >>> check_seed(3), check_seed(None)
    (3, None)
    >>> check_seed(-1)
    Traceback (most recent call last):
    ...
    fcplan.errors.SeedError: seed: must be an integer >= 0, a SeedSequence, a Generator or None (got -1)
    """
    if seed is None or isinstance(seed, np.random.SeedSequence):
        return seed
    if generator and isinstance(seed, np.random.Generator):
        return seed
    if _is_int_seed(seed):
        return seed
    allowed = "an integer >= 0, a SeedSequence, a Generator or None"
    if not generator:
        allowed = "an integer >= 0, a SeedSequence or None"
    raise SeedError(f"seed: must be {allowed} (got {seed!r:.40})")


def seed_list(seeds: Any, name: str = "seeds") -> list[int]:
    """``seeds`` as a list of distinct integers >= 0 in the order given, a lone integer as a
    list of one: the one rule of every function that plays a list of seeds
    (:func:`fcplan.compare`, :func:`fcplan.env.demonstrations`, a sweep's ``seeds``). An
    empty list is returned as it is (the caller says whether it may be empty); anything else
    (a bool, a float, a negative number, a string, a non-iterable) is a one-line
    :class:`~fcplan.errors.SeedError` naming ``name``.

    Examples
    --------
    >>> seed_list([3, 1, 3]), seed_list(2), seed_list(range(2))
    ([3, 1], [2], [0, 1])
    >>> seed_list([0, -1])
    Traceback (most recent call last):
    ...
    fcplan.errors.SeedError: seeds: must be integers >= 0 (got -1)
    """
    if _is_int_seed(seeds):
        return [int(seeds)]
    if isinstance(seeds, (str, bytes, dict)) or not hasattr(seeds, "__iter__"):
        raise SeedError(f"{name}: must be a list of integers >= 0 (got {seeds!r:.40})")
    out = []
    for s in seeds:
        if not _is_int_seed(s):
            raise SeedError(f"{name}: must be integers >= 0 (got {s!r:.40})")
        out.append(int(s))
    return list(dict.fromkeys(out))


def _is_int_seed(s: Any) -> bool:
    return isinstance(s, (int, np.integer)) and not isinstance(s, (bool, np.bool_)) and bool(s >= 0)


def _spawn(seed: Seed, n: int) -> list[np.random.Generator]:
    """``n`` independent generators from an int, SeedSequence, Generator or None."""
    seed = check_seed(seed)
    if isinstance(seed, np.random.Generator):
        return list(seed.spawn(n))
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return [np.random.default_rng(s) for s in ss.spawn(n)]
