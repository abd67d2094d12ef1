"""Whole-process start-up of the ``fcplan`` command (issue 16).

Times complete processes, as a user's shell does: ``python -m fcplan --help``,
``python -m fcplan scenarios`` and ``python -m fcplan run 1`` (a whole 180-s episode of #1 with
greedy, start-up included), with ``python -c pass`` as the baseline of the interpreter itself.
The commands are run interleaved (round k runs every command once, in a shuffled order), so a
change of machine load hits all of them alike; the table gives the median and the spread of the
wall time and the median CPU time (user + system of the child, which load distorts less), and
the median minus the baseline's. ``--old PATH`` adds the same commands run from another source
tree (``PYTHONPATH=PATH``, e.g. an export of ``main``) in the same rounds, for before/after, with
the ratio new/old of the medians.

Usage::

    python bench/bench_startup.py                  # 15 rounds, about a minute
    python bench/bench_startup.py --rounds 30 --old /tmp/main_tree
"""

from __future__ import annotations

import argparse
import os
import random
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "python -c pass": ["-c", "pass"],
    "fcplan --help": ["-m", "fcplan", "--help"],
    "fcplan scenarios": ["-m", "fcplan", "scenarios"],
    "fcplan run 1": ["-m", "fcplan", "run", "1"],
}


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def time_once(args: list[str], tree: Path) -> tuple[float, float]:
    """Wall and CPU seconds of one ``python args`` process with ``tree`` on ``PYTHONPATH``."""
    env = {**os.environ, "PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1"}
    cpu0, t0 = _child_cpu(), time.perf_counter()
    subprocess.run(
        [sys.executable, *args], cwd=tree, env=env, check=True, stdout=subprocess.DEVNULL
    )
    return time.perf_counter() - t0, _child_cpu() - cpu0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15, help="runs of each command (15)")
    ap.add_argument("--old", type=Path, help="another source tree to time in the same rounds")
    ap.add_argument("--seed", type=int, default=0, help="order of the commands in each round")
    args = ap.parse_args()
    trees = {"new": ROOT, **({"old": args.old.resolve()} if args.old else {})}
    jobs = [(tree, name) for tree in trees for name in COMMANDS]
    for tree, name in jobs:  # warm the file cache and the bytecode once, untimed
        time_once(COMMANDS[name], trees[tree])
    wall: dict[tuple[str, str], list[float]] = {job: [] for job in jobs}
    cpu: dict[tuple[str, str], list[float]] = {job: [] for job in jobs}
    rng = random.Random(args.seed)
    load0 = os.getloadavg()
    for _ in range(args.rounds):
        rng.shuffle(jobs)
        for tree, name in jobs:
            w, c = time_once(COMMANDS[name], trees[tree])
            wall[tree, name].append(w)
            cpu[tree, name].append(c)
    load1 = os.getloadavg()
    print(
        f"{args.rounds} rounds, interleaved; Python {sys.version.split()[0]}, {os.cpu_count()} CPUs"
    )
    print(f"load average before {load0[0]:.2f} / after {load1[0]:.2f} (1 min)")
    print(f"new: {trees['new']}" + (f"; old: {trees['old']}" if "old" in trees else ""))
    head = f"{'command':<18} {'tree':<4} {'wall p50 s':>10} {'p10-p90 s':>13} {'CPU p50 s':>10}"
    print(head + f" {'- baseline':>11}" + (f" {'new/old':>8}" if "old" in trees else ""))
    for name in COMMANDS:
        for tree in trees:
            w, c = wall[tree, name], cpu[tree, name]
            q = statistics.quantiles(w, n=10)
            base = statistics.median(wall[tree, "python -c pass"])
            line = (
                f"{name:<18} {tree:<4} {statistics.median(w):>10.3f} "
                f"{q[0]:>6.3f}-{q[-1]:<6.3f} {statistics.median(c):>10.3f} "
                f"{statistics.median(w) - base:>11.3f}"
            )
            if tree == "new" and "old" in trees:
                ratio = statistics.median(w) / statistics.median(wall["old", name])
                line += f" {ratio:>8.2f}"
            print(line)


if __name__ == "__main__":
    main()
