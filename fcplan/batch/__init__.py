"""Batched simulator: ``B`` worlds of one scenario stepped in one call, each bit-identical to
:class:`fcplan.World` with the same seed.

Learners need 10^7-10^9 environment steps. A single world's tick is a few dozen numpy calls on
arrays of 4-30 elements, so its cost is the interpreter's per-call overhead, not arithmetic.
:class:`BatchWorld` takes every per-tick array of the single world and gives it a leading batch
axis, so one numpy call serves all ``B`` worlds: there is no Python loop over worlds, fronts,
agents or cells on the per-tick path. What remains per world are events: a reset, a refill of a
world's random draws ahead (one generator call per world and block), an episode's metrics.

The model is the single world's, tick for tick (:mod:`fcplan.world`): team motion, fire steps,
sensing, dumps, facility counts, trace row. World ``b`` of a batch is bit for bit the single
world reset with the same seed (fire, team, sensing, pruning, counts, trace, metrics), whatever
``B``, whatever the other worlds do and whenever each world is reset; ``tests/batch`` check it on
the practice scenario, #1, #24 and an open world, with both wind models, several tick rates,
fires of more than 256 fronts and the 2020 dump gate.

Data layout (one scenario per batch, so fronts, agents and facilities are not ragged):

======================  =================  =========================================================
array                   shape, dtype       notes
======================  =================  =========================================================
fire ``x``, ``y``       (B, n) float64     front positions; ``alive``, ``frozen`` (B, n) bool
fire ``cell``           (B, n) int64       flat ``x W + y`` of each front's cell
``region_active``       (B, R) bool        ``n_steps``, ``n_burning``, ``n_pruned`` (B,) int64
``burn_box``            (B, 4) int64       box around each world's burning cells (a superset)
wind ahead              (B, L, 2, n) f64   per world the next ``L`` steps' wind, as the single fire
                                           draws it (``L = min(64, 4096 // n)``), and C/R (B, L, n)
terrain                 (B, 6) uint64      per world the PCG64 state before its terrain; values are
                                           computed where fronts stand (:mod:`~fcplan.batch.streams`)
cells                   (B, nb^2, 256) u8  one byte per cell, stored by 16 x 16 blocks: fire state
                                           in bits 0-1, sensed in bit 2 (:mod:`~fcplan.batch.cells`)
block counts            (B, nb^2) int32    burning cells per block, and per 64-px super-block
                                           (the scans skip empty ones)
team ``pos``, ``goal``  (B, N, 2) float64  ``z``, ``battery``, ``tank``, ``mode``, ... (B, N)
routes                  (B, N, R, 2) f64   padded; ``route_len`` (B, N)
sensing, pruning draws  (B, 4096) float64  per world uniforms drawn ahead, and a cursor (B,)
facility counts         (B, F) int64       burning and pruned cells per footprint
trace                   (4, B, T) int32    active, pruned, sensed-active, sensed-ever per tick;
                                           facility rows (2, B, T, F); agents' rows optional
======================  =================  =========================================================

At 1,200 px a world takes about 2 MB (1.44 MB of cells; ``bench/bench_vector.py`` measures it);
the single world's 5.8 MB float32 terrain and 5.8 MB of front visits are not kept (no rule reads
the visits).

Sensing and dumps look for the burning cells of every (world, agent) field of view at once: the
field of view is clipped to the map and the world's fire box, its blocks with burning cells are
gathered as 256-byte rows, and the hits are sorted into the single world's scan order (agents in
row order, cells row-major) so that each world consumes its own sensing and pruning streams in the
same order. A dump changes what the next agent of its world finds, so dumps are taken in rounds,
round ``r`` the ``r``-th dumping agent of every world: the rounds are bounded by the team, not by
``B``. Worlds that finish are held (not stepped) until reset, or reset by ``step(autoreset=True)``
from their own reseed generators (:mod:`fcplan.batch.world`).

Modules: :mod:`~fcplan.batch.world` (the tick, episodes, trace), :mod:`~fcplan.batch.fire`,
:mod:`~fcplan.batch.team`, :mod:`~fcplan.batch.cells`, :mod:`~fcplan.batch.streams`. The batched
environments on it are :mod:`fcplan.env.vector` (motion and task levels).

Examples
--------
>>> import numpy as np
>>> from fcplan import load_scenario
>>> from fcplan.batch import BatchWorld
>>> from fcplan.mission import Mission
>>> sc = load_scenario(1).replace(duration_s=3)
>>> batch = BatchWorld(sc, 5)
>>> batch.reset(seeds=[0, 1, 2, 3, 4])
>>> while not batch.done.all():
...     info = batch.step()
>>> single = Mission(sc, 3, belief=False)  # world 3's seed, alone
>>> single.advance(sc.n_ticks)
30
>>> state, sensed = batch.cells(3)
>>> from fcplan.metrics import compute_all
>>> same = batch.metrics(3)["manual"].as_dict() == compute_all(single.world.trace())["manual"].as_dict()
>>> bool(np.array_equal(state, single.world.fire.state)), same
(True, True)
"""

from __future__ import annotations

from fcplan.batch.world import BatchStepInfo, BatchWorld

__all__ = ["BatchWorld", "BatchStepInfo"]
