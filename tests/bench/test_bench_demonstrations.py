"""bench/bench_demonstrations.py runs end to end: one row per (num_envs, jobs) configuration with
a positive rate and a ratio range that holds its median (exactly 1 for the baseline), after
checking that every configuration recorded the baseline's dataset."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(r"\s*(\d+)\s+(\d+)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+) \[([\d.]+), ([\d.]+)\]")


def test_rows_per_configuration():
    """Two rounds of two short practice episodes under 1x1, 1x2 and 2x2."""
    out = subprocess.run(
        [sys.executable, "bench/bench_demonstrations.py", "--scenarios", "practice", "--seeds",
         "2", "--max-steps", "3", "--rounds", "2", "--configs", "1x1", "1x2", "2x2"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=300,
    ).stdout  # fmt: skip
    assert "every configuration gave the baseline's dataset" in out
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    assert [(int(m[1]), int(m[2])) for m in rows] == [(1, 1), (1, 2), (2, 2)]
    for m in rows:
        median, lo, hi = float(m[5]), float(m[6]), float(m[7])
        assert float(m[4]) > 0 and lo <= median <= hi
    assert float(rows[0][5]) == 1.0
