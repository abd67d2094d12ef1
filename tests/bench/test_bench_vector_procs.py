"""bench/bench_vector_procs.py runs end to end at either level: the one-process baseline, the
independent processes and the sharded env (with and without the copy) for each process count,
each with its ratio to the baseline of the same rounds (exactly 1 for the baseline)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ROW = re.compile(
    r"(one process|independent|sharded(?: copy=False)?)\s+(\d+)\s+(\d+)\s+([\d.]+)"
    r"\s+\[([\d.]+), ([\d.]+)\]"
)


@pytest.mark.parametrize("level, expert", [("motion", None), ("task", None), ("motion", "greedy"),
                                           ("task", "greedy")])  # fmt: skip
def test_rows_per_process_count(level, expert):
    """Two rounds of a few steps of 4 worlds of practice in 1 and 2 processes, by random actions
    or by greedy's plans (the one-process and the sharded experts): the four rows, with positive
    rates and ratio ranges that hold their medians, and the header names the actions."""
    more = ["--expert", expert] if expert else []
    out = subprocess.run(
        [sys.executable, "bench/bench_vector_procs.py", "--scenario", "practice",
         "--worlds", "4", "--procs", "2", "--steps", "3", "--rounds", "2", "--level", level,
         *more],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=300,
    ).stdout  # fmt: skip
    header = out.splitlines()[0]
    assert (f"actions of the {expert} expert" if expert else "random actions") in header
    rows = [m for m in (ROW.match(line) for line in out.splitlines()) if m]
    assert [(m[1], int(m[2])) for m in rows] == [
        ("one process", 1),
        ("independent", 2),
        ("sharded", 2),
        ("sharded copy=False", 2),
    ]
    for m in rows:
        median, lo, hi = float(m[4]), float(m[5]), float(m[6])
        assert int(m[3]) > 0 and lo <= median <= hi
    assert float(rows[0][4]) == 1.0
