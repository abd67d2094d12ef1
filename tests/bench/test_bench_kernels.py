"""bench/bench_kernels.py checks its compiled kernels equal to the numpy rules and prints its table."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
#: a table row: rule, kernel, numpy ms, kernel ms, ratio [min, max], share %, saved %, us, budget %
ROW = re.compile(
    r"(crops|scan)\s+(numpy|numba|jax)\s+([\d.]+)\s+([\d.]+)\s+([\d.]+) \[([\d.]+), ([\d.]+)\]"
    r"\s+([\d.]+)%\s+(-?[\d.]+)%\s+([\d.]+)\s+([\d.]+)%$"
)
HAVE = [m for m in ("numba", "jax") if importlib.util.find_spec(m) is not None]


@pytest.mark.skipif(not HAVE, reason="needs numba or jax")
def test_kernels_equal_to_the_rules_and_one_row_per_kernel():
    """A short episode of 4 worlds: the script's own equality check passes on every recorded
    input (it exits with an error otherwise); it prints the single env's budget and one row per
    rule and kernel (numpy first, at ratio 1), each ratio the median of its range (the
    arithmetic, not the timings)."""
    out = subprocess.run(
        [sys.executable, "bench/bench_kernels.py", "--num", "4", "--scenario", "practice",
         "--rounds", "3", "--every", "10", "--single-episodes", "1"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=600,
    ).stdout  # fmt: skip
    assert "outputs equal bit for bit" in out
    assert re.search(r"at 20x a world-step may cost [\d.]+ us in all", out)
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    want = [("crops", "numpy")] + [("crops", k) for k in HAVE]
    if "numba" in HAVE:
        want += [("scan", "numpy"), ("scan", "numba")]
    assert [(m[1], m[2]) for m in rows] == want
    for m in rows:
        median, lo, hi = float(m[5]), float(m[6]), float(m[7])
        assert lo <= median <= hi
        if m[2] == "numpy":
            assert (median, lo, hi) == (1.0, 1.0, 1.0) and m[3] == m[4]
