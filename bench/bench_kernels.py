"""Would compiled kernels make the batched motion level much faster? Two rules, measured.

The batched motion level (:mod:`fcplan.env.vector_motion`) runs every rule as whole-array numpy
passes over all ``B`` worlds. The usual next step is a compiled kernel per rule (numba, a C
extension), which skips numpy's temporaries and its per-call cost. This script measures that
step on the two rules where a kernel has the most to gain, on inputs recorded from a real
episode of ``B`` worlds (scenario #1 by default, random legal actions), before anyone adds a
compiled dependency for them:

* **crops**: the observation's field-of-view crops (``7 x 15 x 15`` float32 each)
  with their staleness (:meth:`fcplan.env.vector_obs.BatchMotionObs.observe`: one fancy-indexed
  gather of a sliding-window view, then ``min(1, seen + stamp)`` in place), against one numba
  loop that copies each crop into a C-contiguous array and computes the staleness on the way;
* **scan**: the sensing and dump scan for burning cells inside every field of view
  (:func:`fcplan.batch.cells.scan_boxes`: only the 16 x 16 blocks that hold fire, each gathered
  as a 256-byte row, tested, then sorted into the single world's order), against a numba loop
  over the same blocks in block order that writes one sortable key per hit and sorts them.

Each kernel's output is first checked equal (bit for bit, NaN and infinity included) to the numpy
rule's on every recorded input. The two are then timed in ``--rounds`` interleaved rounds (numpy,
then numba, each round over all inputs; the CPU clock of the thread; numba compiled before the
first round); the script prints the median CPU ms per batch step of each, their ratio with its
range over the rounds, and the rule's share of a whole batched step measured in the same
episode, so that the saving on a whole step can be read off.

Usage::

    pip install numba                     # not a dependency of fcplan
    python bench/bench_kernels.py         # about 20 seconds
    python bench/bench_kernels.py --num 64 --scenario 24
"""

from __future__ import annotations

import argparse
import collections
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

_CPU = time.thread_time


def record(scenario: str, num: int, every: int, seed: int = 0) -> dict[str, Any]:
    """Play one episode of ``num`` worlds; keep the inputs of every ``every``-th step's crops and
    of every scan, and the CPU time of the whole steps and of the scans."""
    sc = load_scenario(scenario)
    env = VectorMotionEnv(sc, num)
    views, batch = env.views, env.batch
    rng = np.random.default_rng(seed)
    cpu: collections.Counter = collections.Counter()
    scans: list[tuple] = []
    inner_scan = bworld.scan_boxes

    def timed_scan(grid: Any, world: np.ndarray, *box_test: Any) -> Any:
        c = _CPU()
        out = inner_scan(grid, world, *box_test)
        cpu["scan"] += _CPU() - c
        scans.append((world, *box_test))
        return out

    bworld.scan_boxes = timed_scan
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
    steps = sc.n_ticks
    return {"env": env, "crops": crops, "scans": scans, "steps": steps,
            "scan_ms": cpu["scan"] / steps * 1e3, "step_ms": cpu["step"] / steps * 1e3}  # fmt: skip


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


def compile_kernels() -> tuple[Any, Any]:
    """The two numba kernels (compiled on first call)."""
    import numba

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


def _test_bits(test: Any) -> tuple[np.uint8, np.uint8]:
    """(mask, value) with ``test(v) == ((v & mask) == value)`` for the world's two scan tests."""
    if test is bworld._burning:
        return np.uint8(STATE_BITS), np.uint8(BURNING)
    if test is bworld._burning_sensed:
        return np.uint8(255), np.uint8(bworld._BURNING_SENSED)
    raise ValueError(f"unknown scan test {test!r}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--num", type=int, default=256, help="worlds B")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--every", type=int, default=20, help="keep the crops of every n-th step")
    args = ap.parse_args(argv)
    try:
        import numba
    except ImportError:
        print("numba is not installed: pip install numba")
        return 0
    rec = record(args.scenario, args.num, args.every)
    env, grid = rec["env"], rec["env"].batch.grid
    views = env.views
    crops_nb, scan_nb = compile_kernels()
    shift = int(grid.world_size - 1).bit_length()

    def crops_numba(cx: np.ndarray, cy: np.ndarray, stamp: np.ndarray) -> Any:
        out = np.empty((cx.size, N_FOV, views.view, views.view), np.float32)
        return crops_nb(views.maps, views._world_of, cx, cy, views.view, stamp, D_SEEN, out)

    def scan_numba(world: np.ndarray, x0: Any, x1: Any, y0: Any, y1: Any, test: Any) -> Any:
        mask, value = _test_bits(test)
        return scan_nb(grid.state, grid.blocks, grid.nb, world, x0, x1, y0, y1, mask, value, shift)

    # both rules are replayed on the state of the episode's end: the crops on its maps (the
    # positions and ticks of the recorded steps), the scans on its cells (not those each scan
    # saw: both sides scan the last tick's fire, equal work, compared bit for bit)
    rules = {
        "crops": (rec["crops"], lambda *a: numpy_crops(views, views.maps, *a), crops_numba),
        "scan": (rec["scans"], lambda *a: scan_boxes(grid, *a), scan_numba),
    }
    for name, (inputs, ref, fast) in rules.items():
        for a in inputs:
            want, got = ref(*a), fast(*a)
            pairs = zip(want, got, strict=True) if name == "scan" else [(want, got)]
            if not all(np.array_equal(u, w, equal_nan=True) for u, w in pairs):
                raise SystemExit(f"{name}: the numba kernel differs from the numpy rule")
    print(f"# compiled kernels against the numpy rules, scenario #{args.scenario}, B={args.num}; "
          f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}")  # fmt: skip
    print(f"# a whole batched step: {rec['step_ms']:.3f} CPU ms; outputs equal bit for bit on "
          f"{len(rec['crops'])} crop inputs and {len(rec['scans'])} scans")  # fmt: skip
    print("# ms per batch step of each rule on the recorded inputs (the scans on the last tick's\n"
          "# cells), numpy over numba, the rule's share of a step in the episode, and the part\n"
          "# of a whole step the kernel would save")  # fmt: skip
    print(f"{'rule':6s} {'numpy ms/step':>14s} {'numba ms/step':>14s} {'ratio':>6s} "
          f"{'[min, max]':>12s} {'share of step':>14s} {'step saved':>10s}")  # fmt: skip
    for name, (inputs, ref, fast) in rules.items():
        per_step = len(inputs) / (rec["steps"] if name == "scan" else len(inputs))
        times = np.zeros((args.rounds, 2))
        for r in range(args.rounds):
            for j, fn in enumerate((ref, fast)):
                c = _CPU()
                for a in inputs:
                    fn(*a)
                times[r, j] = (_CPU() - c) / len(inputs) * per_step * 1e3
        ratio = times[:, 0] / times[:, 1]
        # (the crops' share: their numpy time here, the same operations on the same sizes as in
        # the episode; the scans': their time in the episode, whose fires were smaller)
        own = float(np.median(times[:, 0])) if name == "crops" else rec["scan_ms"]
        share = own / rec["step_ms"]
        med = float(np.median(ratio))
        print(f"{name:6s} {np.median(times[:, 0]):14.3f} {np.median(times[:, 1]):14.3f} "
              f"{med:6.2f} [{ratio.min():4.2f}, {ratio.max():4.2f}] {100 * share:13.1f}% "
              f"{100 * share * (1 - 1 / med):9.1f}%")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
