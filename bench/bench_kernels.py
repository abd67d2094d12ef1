"""Would compiled kernels make the batched motion level much faster? Two rules, measured.

The batched motion level (:mod:`fcplan.env.vector_motion`) runs every rule as whole-array numpy
passes over all ``B`` worlds. The usual next steps are a compiled kernel per rule (numba, a C
extension) or a port of the whole tick to an array compiler (JAX, as Jumanji has; torch, as VMAS
has), which skip numpy's temporaries and its per-call cost. This script measures them on the
two rules where a kernel has the most to gain, on inputs recorded from a real episode of ``B``
worlds (scenario #1 by default, random legal actions), before anyone adds a compiled dependency
or starts a port:

* **crops**: the observation's field-of-view crops (``7 x 15 x 15`` float32 each)
  with their staleness (:meth:`fcplan.env.vector_obs.BatchMotionObs.observe`: one fancy-indexed
  gather of a sliding-window view, then ``min(1, seen + stamp)`` in place), against one numba
  loop that copies each crop into a C-contiguous array and computes the staleness on the way,
  and against one ``jax.jit`` function (a ``vmap`` of ``dynamic_slice`` over the crops, the
  staleness and the channel transpose fused by XLA) on maps already held by JAX (as a port
  would hold them), its result handed back as a numpy array;
* **scan**: the sensing and dump scan for burning cells inside every field of view
  (:func:`fcplan.batch.cells.scan_boxes`: only the 16 x 16 blocks that hold fire, each gathered
  as a 256-byte row, tested, then sorted into the single world's order), against a numba loop
  over the same blocks in block order that writes one sortable key per hit and sorts them. Its
  output's size depends on the data, which ``jax.jit`` does not allow without padding every
  field of view to its largest count: not measured in JAX.

Each kernel's output is first checked equal (bit for bit, NaN and infinity included) to the numpy
rule's on every recorded input. They are then timed in ``--rounds`` interleaved rounds (numpy,
then each kernel, each round over all inputs; the CPU clock of the whole process, which counts
JAX's worker threads; every kernel compiled before the first round); the script prints the
median CPU ms per batch step of each, their ratio to numpy with its range over the rounds, the
rule's share of a whole batched step measured in the same episode (so that the saving on a
whole step can be read off), and the kernel's CPU microseconds per world-step. Against these it
prints what the issue's target allows: the single env's CPU time per step, measured in the
same run (``--single-episodes`` whole episodes of :class:`fcplan.env.motion.MotionEnv`, once
before the timings and once after, their mean), over 20, the whole cost of a world-step at 20x.

Usage::

    pip install numba jax                 # neither is a dependency of fcplan; either will do
    python bench/bench_kernels.py         # about 30 seconds
    python bench/bench_kernels.py --num 64 --scenario 24
"""

from __future__ import annotations

import argparse
import collections
import os
import platform
import time
from typing import Any

import numpy as np

import fcplan.batch.world as bworld
from fcplan.batch.cells import STATE_BITS, scan_boxes
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_obs import D_SEEN, N_FOV
from fcplan.fire import BURNING
from fcplan.scenario import load_scenario

_CPU = time.process_time  # (every thread: JAX computes on its own)


def record(scenario: str, num: int, every: int, seed: int = 0) -> dict[str, Any]:
    """Play one episode of ``num`` worlds; keep the inputs of every ``every``-th step's crops and
    of every scan, and the CPU time of the whole steps, of the simulator and of the scans."""
    sc = load_scenario(scenario)
    env = VectorMotionEnv(sc, num)
    views, batch = env.views, env.batch
    rng = np.random.default_rng(seed)
    cpu: collections.defaultdict[str, float] = collections.defaultdict(float)
    scans: list[tuple] = []
    inner_scan = bworld.scan_boxes

    def timed_scan(grid: Any, world: np.ndarray, *box_test: Any) -> Any:
        c = _CPU()
        out = inner_scan(grid, world, *box_test)
        cpu["scan"] += _CPU() - c
        scans.append((world, *box_test))
        return out

    bworld.scan_boxes = timed_scan  # type: ignore[assignment]
    inner_step = batch.step

    def timed_step(*a: Any, **k: Any) -> Any:
        c = _CPU()
        out = inner_step(*a, **k)
        cpu["sim"] += _CPU() - c
        return out

    batch.step = timed_step  # type: ignore[method-assign]
    crops: list[tuple] = []
    try:
        obs, _ = env.reset(seed=seed)
        for step in range(sc.n_ticks):
            m = obs["action_mask"]
            act = (rng.random(m.shape) * m).argmax(axis=2)
            c = _CPU()
            obs, *_ = env.step(act)
            cpu["step"] += _CPU() - c
            if step % every == every - 1:
                pos = batch.team.pos
                cx = (pos[..., 0] // views.cell_px).astype(np.int64).reshape(-1)
                cy = (pos[..., 1] // views.cell_px).astype(np.int64).reshape(-1)
                stamp = (batch.tick * views.seen_scale).astype(np.float32)
                crops.append((cx, cy, stamp))
    finally:
        bworld.scan_boxes = inner_scan
        del batch.step
    steps = sc.n_ticks
    return {"env": env, "crops": crops, "scans": scans, "steps": steps,
            "scan_ms": cpu["scan"] / steps * 1e3, "step_ms": cpu["step"] / steps * 1e3,
            "sim_ms": cpu["sim"] / steps * 1e3}  # fmt: skip


def numpy_crops(views: Any, maps: np.ndarray, cx: np.ndarray, cy: np.ndarray,
                stamp: np.ndarray) -> np.ndarray:  # fmt: skip
    """The observe rule's crops and staleness: its own operations, on the maps given."""
    from numpy.lib.stride_tricks import sliding_window_view

    v = views.view
    fov = sliding_window_view(maps, (v, v), axis=(1, 2))[views._world_of, cx, cy]
    stale = fov.reshape(views.num, views.n, N_FOV, v * v)[:, :, D_SEEN]
    stale += stamp[:, None, None]
    np.minimum(stale, np.float32(1.0), out=stale)
    return fov


def numba_kernels() -> tuple[Any, Any] | None:
    """The two numba kernels (compiled on first call); None without numba."""
    try:
        import numba
    except ImportError:
        return None

    @numba.njit(boundscheck=False, cache=False)
    def crops(maps, world, cx, cy, v, stamp, seen, out):  # type: ignore[no-untyped-def]
        one = np.float32(1.0)
        for k in range(world.size):
            b, x0, y0, s = world[k], cx[k], cy[k], stamp[world[k]]
            for c in range(maps.shape[3]):
                for i in range(v):
                    for j in range(v):
                        out[k, c, i, j] = maps[b, x0 + i, y0 + j, c]
                if c == seen:
                    for i in range(v):
                        for j in range(v):
                            out[k, c, i, j] = min(out[k, c, i, j] + s, one)
        return out

    @numba.njit(boundscheck=False, cache=False)
    def _walk(state, blocks, nb, world, x0, x1, y0, y1, mask, value, shift, keys, fill):  # type: ignore[no-untyped-def]  # noqa: E501
        n = 0
        for p in range(world.size):
            w = world[p]
            for bx in range(x0[p] >> 4, (x1[p] >> 4) + 1):
                xa, xb = max(x0[p], bx << 4), min(x1[p], (bx << 4) + 15)
                for by in range(y0[p] >> 4, (y1[p] >> 4) + 1):
                    blk = bx * nb + by
                    if blocks[w, blk] == 0:
                        continue
                    ya, yb = max(y0[p], by << 4), min(y1[p], (by << 4) + 15)
                    for x in range(xa, xb + 1):
                        row = (x & 15) << 4
                        for y in range(ya, yb + 1):
                            if (state[w, blk, row + (y & 15)] & mask) == value:
                                if fill:
                                    keys[n] = (p << (2 * shift)) | (x << shift) | y
                                n += 1
        return n

    @numba.njit(boundscheck=False, cache=False)
    def scan(state, blocks, nb, world, x0, x1, y0, y1, mask, value, shift):  # type: ignore[no-untyped-def]  # noqa: E501
        empty = np.empty(0, np.int64)
        n = _walk(state, blocks, nb, world, x0, x1, y0, y1, mask, value, shift, empty, False)
        keys = np.empty(n, np.int64)
        _walk(state, blocks, nb, world, x0, x1, y0, y1, mask, value, shift, keys, True)
        keys.sort()
        low = (1 << shift) - 1
        return keys >> (2 * shift), (keys >> shift) & low, keys & low

    return crops, scan


def jax_crops(views: Any) -> Any:
    """The crops and their staleness as one ``jax.jit`` function of ``(cx, cy, stamp)`` on
    the maps of ``views`` put on JAX's device once; None without JAX."""
    try:
        import jax
        import jax.numpy as jnp
    except ImportError:
        return None
    v, one = views.view, np.float32(1.0)
    maps = jax.device_put(views.maps)
    world = jax.device_put(views._world_of.astype(np.int32))

    @jax.jit
    def crops(maps: Any, world: Any, cx: Any, cy: Any, stamp: Any) -> Any:
        def crop(b: Any, x: Any, y: Any, s: Any) -> Any:
            c = jax.lax.dynamic_slice(maps[b], (x, y, 0), (v, v, N_FOV))
            c = c.at[..., D_SEEN].set(jnp.minimum(c[..., D_SEEN] + s, one))
            return jnp.transpose(c, (2, 0, 1))

        return jax.vmap(crop)(world, cx, cy, stamp[world])

    def run(cx: np.ndarray, cy: np.ndarray, stamp: np.ndarray) -> np.ndarray:
        return np.asarray(crops(maps, world, cx.astype(np.int32), cy.astype(np.int32), stamp))

    return run


def _test_bits(test: Any) -> tuple[np.uint8, np.uint8]:
    """(mask, value) with ``test(v) == ((v & mask) == value)`` for the world's two scan tests."""
    if test is bworld._burning:
        return np.uint8(STATE_BITS), np.uint8(BURNING)
    if test is bworld._burning_sensed:
        return np.uint8(255), np.uint8(bworld._BURNING_SENSED)
    raise ValueError(f"unknown scan test {test!r}")


def single_us(scenario: str, episodes: int) -> float:
    """CPU microseconds per step of the single motion env (random legal actions)."""
    from bench_vector import single_env

    steps, clock = single_env(load_scenario(scenario), episodes)
    return clock.cpu["step"] / steps * 1e6


def _rounds(fns: list[Any], inputs: list[tuple], rounds: int, per_step: float) -> np.ndarray:
    """(rounds, len(fns)) CPU ms per batch step of each function over all ``inputs``, the
    functions interleaved within each round."""
    times = np.zeros((rounds, len(fns)))
    for r in range(rounds):
        for j, fn in enumerate(fns):
            c = _CPU()
            for a in inputs:
                fn(*a)
            times[r, j] = (_CPU() - c) / len(inputs) * per_step * 1e3
    return times


def _kernels(
    views: Any, grid: Any, nb: Any, jx: Any
) -> tuple[dict[str, dict[str, Any]], list[str]]:
    """The kernels of each rule by name, called as the numpy rules are (numba's wrapped around
    the episode's maps and cells), and the versions of what computes them."""
    shift = int(grid.world_size - 1).bit_length()
    kernels: dict[str, dict[str, Any]] = {"crops": {}, "scan": {}}
    versions = [f"numpy {np.__version__}"]
    if nb is not None:
        import numba

        crops_nb, scan_nb = nb
        versions.append(f"numba {numba.__version__}")

        def crops_numba(cx: np.ndarray, cy: np.ndarray, stamp: np.ndarray) -> Any:
            out = np.empty((cx.size, N_FOV, views.view, views.view), np.float32)
            return crops_nb(views.maps, views._world_of, cx, cy, views.view, stamp, D_SEEN, out)

        def scan_numba(world: np.ndarray, x0: Any, x1: Any, y0: Any, y1: Any, test: Any) -> Any:
            mask, value = _test_bits(test)
            return scan_nb(
                grid.state, grid.blocks, grid.nb, world, x0, x1, y0, y1, mask, value, shift
            )

        kernels["crops"]["numba"], kernels["scan"]["numba"] = crops_numba, scan_numba
    if jx is not None:
        import jax

        versions.append(f"jax {jax.__version__}")
        kernels["crops"]["jax"] = jx
    return kernels, versions


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--num", type=int, default=256, help="worlds B")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--every", type=int, default=20, help="keep the crops of every n-th step")
    ap.add_argument("--single-episodes", type=int, default=2, help="episodes of the single env")
    args = ap.parse_args(argv)
    nb = numba_kernels()
    rec = record(args.scenario, args.num, args.every)
    env, grid = rec["env"], rec["env"].batch.grid
    views = env.views
    jx = jax_crops(views)
    if nb is None and jx is None:
        print("neither numba nor jax is installed: pip install numba jax")
        return 0
    kernels, versions = _kernels(views, grid, nb, jx)
    # both rules are replayed on the state of the episode's end: the crops on its maps (the
    # positions and ticks of the recorded steps), the scans on its cells (not those each scan
    # saw: both sides scan the last tick's fire, equal work, compared bit for bit)
    rules: dict[str, tuple[list[tuple], Any]] = {
        "crops": (rec["crops"], lambda *a: numpy_crops(views, views.maps, *a)),
        "scan": (rec["scans"], lambda *a: scan_boxes(grid, *a)),
    }
    for name, (inputs, ref) in rules.items():
        for kernel, fast in kernels[name].items():
            for a in inputs:
                want, got = ref(*a), fast(*a)
                pairs = zip(want, got, strict=True) if name == "scan" else [(want, got)]
                if not all(np.array_equal(u, w, equal_nan=True) for u, w in pairs):
                    raise SystemExit(f"{name}: the {kernel} kernel differs from the numpy rule")
    # the single env before and after the timings: the budget is the mean of the two runs
    before = single_us(args.scenario, args.single_episodes)
    timed = {name: _rounds([ref, *kernels[name].values()], inputs, args.rounds,
                           len(inputs) / (rec["steps"] if name == "scan" else len(inputs)))
             for name, (inputs, ref) in rules.items() if kernels[name]}  # fmt: skip
    after = single_us(args.scenario, args.single_episodes)
    single = (before + after) / 2
    budget = single / 20  # (us: a whole world-step at 20x the single env)
    print(f"# compiled kernels against the numpy rules, scenario #{args.scenario}, B={args.num}; "
          f"Python {platform.python_version()}, {', '.join(versions)}; "
          f"{os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"# a whole batched step: {rec['step_ms']:.3f} CPU ms "
          f"({rec['step_ms'] * 1e3 / args.num:.2f} us per world-step, the simulator's "
          f"BatchWorld.step {rec['sim_ms'] * 1e3 / args.num:.2f}); outputs equal bit for bit "
          f"on {len(rec['crops'])} crop inputs and {len(rec['scans'])} scans")  # fmt: skip
    print(f"# the single env in this run: {single:.2f} CPU us per step ({before:.2f} before the "
          f"timings, {after:.2f} after); at 20x a world-step may cost {budget:.2f} us in all")  # fmt: skip
    print("# ms per batch step of each rule on the recorded inputs (the scans on the last tick's\n"
          "# cells), numpy over the kernel, the rule's share of a step in the episode, the part\n"
          "# of a whole step the kernel would save, the kernel's us per world-step and their part\n"
          "# of the whole cost of a world-step at 20x")  # fmt: skip
    print(f"{'rule':6s} {'kernel':6s} {'numpy ms/step':>14s} {'kernel ms/step':>14s} {'ratio':>6s} "
          f"{'[min, max]':>12s} {'share of step':>14s} {'step saved':>10s} {'us/world-step':>13s} {'of 20x':>7s}")  # fmt: skip
    for name, times in timed.items():
        # (the crops' share: their numpy time here, the same operations on the same sizes as in
        # the episode; the scans': their time in the episode, whose fires were smaller)
        own = float(np.median(times[:, 0])) if name == "crops" else rec["scan_ms"]
        share = own / rec["step_ms"]
        rows = [("numpy", times[:, 0])] + list(zip(kernels[name], times[:, 1:].T, strict=True))
        for kernel, t in rows:
            ratio = times[:, 0] / t
            med, ms = float(np.median(ratio)), float(np.median(t))
            us = ms * 1e3 / args.num
            print(f"{name:6s} {kernel:6s} {np.median(times[:, 0]):14.3f} {ms:14.3f} "
                  f"{med:6.2f} [{ratio.min():4.2f}, {ratio.max():4.2f}] {100 * share:13.1f}% "
                  f"{100 * share * (1 - 1 / med):9.1f}% {us:13.2f} {100 * us / budget:6.1f}%")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
