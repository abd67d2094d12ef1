"""Benchmark the hardened readers of outside files (issues 15 and 17).

Prints

* for synthetic 2020 GUI folders (``tests/legacy/folders.py``: a full 180-s episode with greedy,
  written as the GUI's 13 pickles): per file, its size, ``pickle.loads`` vs
  :func:`fcplan.legacy.restricted_loads` (best of ``--repeats``), and whether both build equal
  values when the file is re-pickled in protocols 0-5; then the whole :func:`import_legacy`;
  times are CPU seconds (``time.process_time``), best of ``--repeats``;
* for a 180-s recording of #24 with greedy: :func:`fcplan.recording.load_recording` vs a bare
  ``numpy.load`` of every entry (what the reader did before, without its checks).

Usage (from the repository root)::

    PYTHONPATH=$PWD nice python bench/bench_readers.py                # about 2 minutes
    PYTHONPATH=$PWD nice python bench/bench_readers.py --scenarios practice --repeats 1
"""

from __future__ import annotations

import argparse
import io
import os
import pickle
import sys
import tempfile
import time
from collections.abc import Callable
from typing import Any

import numpy as np

sys.path.insert(0, os.getcwd())  # tests/legacy/folders.py writes the synthetic folders

from fcplan import run_episode  # noqa: E402
from fcplan.legacy import import_legacy, restricted_loads  # noqa: E402
from fcplan.recording import load_recording  # noqa: E402


def _best(fn: Callable[[], Any], repeats: int) -> float:
    """Best CPU time of ``repeats`` calls (CPU, not wall: robust on a shared machine)."""
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return min(times)


def _same(a: Any, b: Any) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        if a.dtype != b.dtype or a.shape != b.shape:
            return False
        if a.dtype.kind == "O":
            return all(_same(x, y) for x, y in zip(a.ravel(), b.ravel(), strict=True))
        return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    return bool(a == b or (a != a and b != b))


def legacy_table(scenario: str, repeats: int, tmp: str) -> None:
    from tests.legacy.folders import write_legacy_folder

    folder = os.path.join(tmp, scenario)
    write_legacy_folder(folder, scenario_name=scenario)
    print(f"\n#### legacy folder of {scenario} (180 s, greedy, seed 0)\n")
    print("| file | bytes | pickle.loads ms | restricted_loads ms | ratio | equal, protocols 0-5 |")
    print("|---|---|---|---|---|---|")
    total_p = total_r = 0.0
    for name in sorted(os.listdir(folder)):
        with open(os.path.join(folder, name), "rb") as f:
            data = f.read()
        tp = _best(lambda d=data: pickle.loads(d, encoding="latin1"), repeats)
        tr = _best(lambda d=data: restricted_loads(d), repeats)
        total_p, total_r = total_p + tp, total_r + tr
        obj = pickle.loads(data, encoding="latin1")
        equal = all(
            _same(restricted_loads(d), pickle.loads(d, encoding="latin1"))
            for d in (pickle.dumps(obj, protocol=p) for p in range(6))
        )
        ratio = tr / tp if tp else float("nan")
        print(
            f"| {name} | {len(data):,} | {1e3 * tp:.1f} | {1e3 * tr:.1f} | {ratio:.0f}x | "
            f"{'yes' if equal else 'NO'} |"
        )
    print(f"| all | | {1e3 * total_p:.0f} | {1e3 * total_r:.0f} | {total_r / total_p:.0f}x | |")
    t = _best(lambda: import_legacy(folder), repeats)
    print(f"\nimport_legacy({scenario}): {t:.2f} s CPU")


def recording_table(repeats: int, tmp: str) -> None:
    path = os.path.join(tmp, "24.npz")
    run_episode(24, "greedy", seed=0, record=path)

    def bare() -> None:
        with open(path, "rb") as f, np.load(io.BytesIO(f.read()), allow_pickle=False) as z:
            for k in z.files:
                z[k]

    tb = _best(bare, repeats)
    tl = _best(lambda: load_recording(path), repeats)
    print("\n#### recording of #24 (180 s, greedy, seed 0)\n")
    print("| file bytes | numpy.load of every entry ms | load_recording ms |")
    print("|---|---|---|")
    print(f"| {os.path.getsize(path):,} | {1e3 * tb:.1f} | {1e3 * tl:.1f} |")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenarios", default="practice,24")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        for scenario in args.scenarios.split(","):
            legacy_table(scenario, args.repeats, tmp)
        recording_table(args.repeats, tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
