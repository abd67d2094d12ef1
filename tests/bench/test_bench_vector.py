"""bench/bench_vector.py runs end to end and prints the interleaved table it documents."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: a table row: name, CPU rate (wall rate), ratio [min, max], ...
ROW = re.compile(r"(single|B=\d+|sync B=\d+)\s+\d+ \(\s*\d+\)\s+([\d.]+) \[([\d.]+), ([\d.]+)\]")


def test_interleaved_rounds_print_medians_and_ratio_ranges(tmp_path):
    """Two rounds of tiny episodes at both levels: every level's table names its rounds, has a
    row per ``B`` and per sync ``B`` (Gymnasium's SyncVectorEnv of the single env) with a ratio
    range ``[min, max]`` that holds its median, the batched env over the sync one at their common
    ``B``, the memory per world of both levels (traced, and resident over a whole episode), and
    the plot is written (the script's own arithmetic on real runs, not the figures, which are
    timings)."""
    plot = tmp_path / "vector.png"
    out = subprocess.run(
        [sys.executable, "bench/bench_vector.py", "--sizes", "1", "3", "--duration", "2",
         "--scenarios", "practice", "--rounds", "2", "--episodes", "1", "--sync-sizes", "3",
         "--plot", str(plot)],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=300,
    ).stdout  # fmt: skip
    assert out.count("median of 2 interleaved round(s)") == 2
    starts = ("single ", "B=", "sync ")
    rows = [ROW.match(line) for line in out.splitlines() if line.startswith(starts)]
    assert all(rows)
    assert [m[1] for m in rows if m] == ["single", "B=1", "B=3", "sync B=3"] * 2
    assert len(re.findall(r"batched over sync at the same B: B=3 [\d.]+x", out)) == 2
    for m in rows:
        assert m is not None
        median, lo, hi = float(m[2]), float(m[3]), float(m[4])
        assert lo <= median <= hi
        assert m[1] != "single" or median == lo == hi == 1.0
    for level in ("motion", "task"):  # the memory per world of each level
        m = re.search(rf"memory, {level} level \(#practice, traced\): ([\d.]+) MB per world", out)
        assert m is not None and float(m[1]) > 0, out
        m = re.search(
            rf"memory, {level} level \(#practice, resident\): ([\d.]+) MB per world \(peak RSS "
            r"of a whole 2-s episode, 16 against \d+ worlds\)", out
        )  # fmt: skip
        assert m is not None and float(m[1]) > 0, out  # (every world's fire map is resident)
    assert plot.stat().st_size > 0
