"""bench/bench_vector_expert.py runs end to end and prints its interleaved table."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(r"(single|B=\d+(?: apart)?)\s+\d+\s+([\d.]+) \[([\d.]+), ([\d.]+)\]\s+(\d+%|-)")


@pytest.mark.parametrize("level", ["motion", "task"])
def test_rows_per_size_with_ratio_ranges(level):
    """Two rounds of 2-s episodes at either level: one row for the single rollout and one per
    ``B``, each with a ratio range that holds its median (the single row's is exactly 1) and
    the expert's share at the motion level ("-" at the task level, where whole calls are
    timed); ``--apart`` adds a row per ``B`` with one scheduler instance per world."""
    out = subprocess.run(
        [sys.executable, "bench/bench_vector_expert.py", "--scenario", "practice",
         "--duration", "2", "--sizes", "1", "3", "--episodes", "1", "--rounds", "2",
         "--level", level, "--apart"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=300,
    ).stdout  # fmt: skip
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    assert [m[1] for m in rows] == ["single", "B=1", "B=3", "B=1 apart", "B=3 apart"]
    for m in rows:
        median, lo, hi = float(m[2]), float(m[3]), float(m[4])
        assert lo <= median <= hi
        assert m[1] != "single" or median == lo == hi == 1.0
        assert (m[5] == "-") == (level == "task")
    assert re.search(r"same round: B=1 [\d.]+x \[[\d.]+, [\d.]+\], B=3 [\d.]+x", out)
