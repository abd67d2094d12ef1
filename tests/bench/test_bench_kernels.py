"""bench/bench_kernels.py checks its numba kernels equal to the numpy rules and prints its table."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: a table row: rule, numpy ms, numba ms, ratio [min, max], share %, saved %
ROW = re.compile(
    r"(crops|scan)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+) \[([\d.]+), ([\d.]+)\]\s+([\d.]+)%"
)


def test_kernels_equal_to_the_rules_and_one_row_per_rule():
    """A short episode of 4 worlds: the script's own equality check passes on every recorded
    input (it exits with an error otherwise), and it prints one row per rule whose ratio is the
    median of its range (the arithmetic, not the timings)."""
    pytest.importorskip("numba")
    out = subprocess.run(
        [sys.executable, "bench/bench_kernels.py", "--num", "4", "--scenario", "practice",
         "--rounds", "3", "--every", "10"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=600,
    ).stdout  # fmt: skip
    assert "outputs equal bit for bit" in out
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    assert [m[1] for m in rows] == ["crops", "scan"]
    for m in rows:
        median, lo, hi = float(m[4]), float(m[5]), float(m[6])
        assert lo <= median <= hi
