"""bench/bench_copies.py runs end to end: one row per env configuration with positive times, a
copy cost in steps that is the ratio of its columns, and a pickle size; the script itself
stops if a copy does not step as the original."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(r"(single motion|single task|batched motion B=2|batched task B=2)\s+"
                 r"([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)$")  # fmt: skip


def test_one_row_per_configuration():
    """Two rounds on practice with two batched worlds."""
    out = subprocess.run(
        [sys.executable, "bench/bench_copies.py", "--scenario", "practice", "--worlds", "2",
         "--rounds", "2", "--warm", "2", "--steps", "2"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=300,
    ).stdout  # fmt: skip
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    assert [m[1] for m in rows] == [
        "single motion", "single task", "batched motion B=2", "batched task B=2"
    ]  # fmt: skip
    for m in rows:
        step, deep, in_steps, size = float(m[2]), float(m[3]), float(m[4]), float(m[7])
        assert step > 0 and deep > 0 and size > 0
        # (the columns are rounded to 0.01 ms and 0.1 steps)
        slack = in_steps * (0.005 / step + 0.005 / deep) + 0.05
        assert abs(in_steps - deep / step) <= slack + 1e-9
