"""Interleaved A/B runs of a bench script on two source trees: medians and new/old ratios.

A change's speed is judged against the code before it, measured in the same run on the same
machine, alternating the two so that drift of a shared, noisy machine hits both alike. This
script runs ``python BENCH [ARGS]`` with ``PYTHONPATH`` set to the *old* tree and to the *new*
tree in turn (old, new, old, new, ...; each tree's own copy of the bench script), reads every
output line that both runs print with the same label, and prints, per numeric cell, the median
over the rounds for each tree and the ratio new/old.

Rows match by their label (the line's words before its first number) and their order among rows
of that label; numbers inside a label (``#1``) are part of it. A ratio above 1 means the new
figure is larger: for a rate (steps/s) that is faster, for a time (us/tick) that is slower, so
read it with the column.

Usage::

    git worktree add ../fcplan-old <old commit>
    python bench/ab.py ../fcplan-old . bench/bench_env.py --quick --rounds 5

Examples
--------
>>> _cells("motion #1   4   1800   13426 ( 14181)   74.5")
('motion #1', [4.0, 1800.0, 13426.0, 14181.0, 74.5])
>>> _cells("   24   random     1187    1637")
('24 random', [1187.0, 1637.0])
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

_NUM = re.compile(r"^\(?[-+]?\d[\d,]*\.?\d*(e[-+]?\d+)?\)?%?x?$", re.IGNORECASE)


def _cells(line: str) -> tuple[str, list[float]]:
    """Split a line into its label (the words before the first number) and its numbers."""
    words = line.replace("( ", "(").split()
    label: list[str] = []
    if len(words) > 1 and _NUM.match(words[0]) and not _NUM.match(words[1]):
        label, words = words[:2], words[2:]  # a row keyed by a number and a word: "1 random"
    values: list[float] = []
    for w in words:
        if _NUM.match(w) and (values or not w.startswith("#")):
            values.append(float(w.strip("()%xX").replace(",", "")))
        elif not values:
            label.append(w)
        else:
            break  # text after the numbers: not a table row we compare
    return " ".join(label), values


def _rows(text: str) -> dict[tuple[str, int], list[float]]:
    seen: dict[str, int] = defaultdict(int)
    out = {}
    for line in text.splitlines():
        label, values = _cells(line)
        if label and values:
            out[(label, seen[label])] = values
            seen[label] += 1
    return out


def run(tree: Path, bench: str, args: list[str]) -> str:
    """Output of ``python <tree>/<bench> ARGS`` with the tree first on ``PYTHONPATH``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    proc = subprocess.run(
        [sys.executable, str(tree / bench), *args],
        env=env,
        cwd=tree,
        capture_output=True,
        text=True,
        check=True,
    )
    return proc.stdout


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path, help="the baseline source tree")
    ap.add_argument("new", type=Path, help="the changed source tree")
    ap.add_argument("bench", help="bench script path inside each tree, e.g. bench/bench_env.py")
    ap.add_argument("--rounds", type=int, default=5, help="runs of each tree (default 5)")
    ns, rest = ap.parse_known_args(argv)
    old_runs: list[dict] = []
    new_runs: list[dict] = []
    for r in range(ns.rounds):
        old_runs.append(_rows(run(ns.old.resolve(), ns.bench, rest)))
        new_runs.append(_rows(run(ns.new.resolve(), ns.bench, rest)))
        print(f"round {r + 1}/{ns.rounds} done", file=sys.stderr)
    keys = [k for k in old_runs[0] if all(k in run_ for run_ in old_runs + new_runs)]
    print(f"# {ns.bench} {' '.join(rest)}: {ns.rounds} interleaved rounds, medians; ratio new/old")
    for key in keys:
        n = min(len(run_[key]) for run_ in old_runs + new_runs)
        old = [statistics.median(run_[key][i] for run_ in old_runs) for i in range(n)]
        new = [statistics.median(run_[key][i] for run_ in new_runs) for i in range(n)]
        cells = [
            f"{o:g}->{v:g} ({v / o:.3f})" if o else f"{o:g}->{v:g}"
            for o, v in zip(old, new, strict=True)
        ]
        print(f"{key[0]:<24} " + "  ".join(cells))


if __name__ == "__main__":
    main()
