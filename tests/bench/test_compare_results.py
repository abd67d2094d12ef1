"""bench/compare_results.py pairs two results folders' episodes by (scheduler, scenario, seed):
the paired mean, wins/ties/losses and the count of unpaired episodes are those of the data."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from fcplan.experiments.results import write_row

ROOT = Path(__file__).resolve().parents[2]


def _write(folder: Path, rows: list[tuple[str, str, int, float]]) -> None:
    folder.mkdir()
    for i, (sched, scen, seed, score) in enumerate(rows):
        write_row(folder, {"key": f"{i:016x}", "status": "ok", "scheduler": sched,
                           "scenario": scen, "seed": seed, "manual.final_score": score})  # fmt: skip


def test_pairs_by_scenario_and_seed(tmp_path):
    """Greedy's three shared episodes moved by +1, +2 and 0 (mean +1.00, 2/1/0), one episode is
    in the new folder only; another scenario is filtered out by --scenarios."""
    old, new = tmp_path / "old", tmp_path / "new"
    _write(old, [("greedy", "s/hard-03", 0, 10.0), ("greedy", "s/hard-03", 1, 20.0),
                 ("greedy", "s/hard-03", 2, 5.0), ("greedy", "s/hard-01", 0, 0.0)])  # fmt: skip
    _write(new, [("greedy", "s/hard-03", 0, 11.0), ("greedy", "s/hard-03", 1, 22.0),
                 ("greedy", "s/hard-03", 2, 5.0), ("greedy", "s/hard-03", 3, 9.0),
                 ("greedy", "s/hard-01", 0, 50.0)])  # fmt: skip
    out = subprocess.run(
        [sys.executable, "bench/compare_results.py", str(old), str(new), "--scenarios", "hard-03"],
        cwd=ROOT, capture_output=True, text=True, check=True, timeout=120,
    ).stdout  # fmt: skip
    row = re.search(r"greedy\s+(\d+)\s+([+-][\d.]+) \[\s*([+-][\d.]+),\s*([+-][\d.]+)\]"
                    r"\s+(\S+)\s+(\S+)\s+(\d+)", out)  # fmt: skip
    assert row is not None, out
    n, mean, lo, hi, wtl, _p, alone = row.groups()
    assert (n, mean, wtl, alone) == ("3", "+1.00", "2/1/0", "1")
    assert float(lo) < 1.0 < float(hi)
