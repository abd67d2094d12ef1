"""Robustness audit (issue 17): bad inputs through the ``fcplan`` command line, counted by outcome.

Every case runs ``fcplan.cli.main(argv)`` in a forked child of this process (the same code path
as the console script, without the interpreter's start-up), with a memory limit
(``RLIMIT_AS``) and a time limit, and is classified from its exit status and stderr
(``tests/hardening/mutate.py``: ``Outcome``):

* clean error: exit 2, exactly one line ``fcplan: error: ...`` on stderr, no traceback;
* ran: exit 0; traceback: anything else; hang: over the time limit; OOM: MemoryError, "out of
  memory" or killed at the memory limit; orphan: a process the case started that is still alive
  5 s after it ended (this process is the children's sub-reaper, so orphans come back to it).

Categories:

1. ``mutants``: mutated shipped scenario files (``tests.hardening.mutate.mutant``), each through
   ``fcplan scenario validate`` and, when valid, ``fcplan run`` (its own duration, greedy);
2. ``files``: special paths as scenarios and sweep files (``/dev/zero``, a FIFO, a 1 GiB sparse
   file, a folder, deep nesting);
3. ``arguments``: bad arguments and scheduler specs for every command;
4. ``sweeps``: kill -9 of a sweep's parent, SIGTERM, kill -9 of a worker, two sweeps into one
   folder, a full disk (ENOSPC injected in the writer).

Usage::

    PYTHONPATH=$PWD nice python bench/audit_hardening.py --mutants 600 --seed 0
    PYTHONPATH=$PWD nice python bench/audit_hardening.py --only arguments,sweeps
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import os
import random
import resource
import signal
import sys
import tempfile
import time
import traceback
from collections import Counter
from pathlib import Path

from tests.hardening.mutate import Outcome, classify, mutant, to_toml

MEMORY_LIMIT = 6 * 2**30
_PR_SET_CHILD_SUBREAPER = 36


def _children() -> set[int]:
    """Pids of this process's live (non-zombie) children."""
    me, out = os.getpid(), set()
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == me and fields[0] != "Z":
            out.add(int(d.name))
    return out


def _reap() -> None:
    with contextlib.suppress(ChildProcessError):
        while os.waitpid(-1, os.WNOHANG)[0]:
            pass


def run_case(argv: list[str], timeout: float, prepare=None) -> tuple[str, str]:
    """Run ``fcplan argv`` in a forked child; return (outcome, first stderr line)."""
    err = tempfile.TemporaryFile()  # noqa: SIM115 - shared with the forked child
    pid = os.fork()
    if pid == 0:  # child
        try:
            resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
            os.dup2(err.fileno(), 2)
            os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
            if prepare is not None:
                prepare()
            from fcplan.cli import main

            code = main(argv)
        except BaseException:  # noqa: BLE001 - anything escaping main is the finding
            traceback.print_exc()
            code = 1
        sys.stderr.flush()
        os._exit(code)
    t0, status = time.monotonic(), None
    while time.monotonic() - t0 < timeout:
        done, raw = os.waitpid(pid, os.WNOHANG)
        if done:
            status = os.waitstatus_to_exitcode(raw)
            break
        time.sleep(0.05)
    else:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    err.seek(0)
    text = err.read().decode("utf-8", "replace")
    outcome = classify(status, text)
    if _orphans(5.0):
        outcome = Outcome.ORPHAN
    first = next((ln for ln in text.splitlines() if ln.strip()), "")
    return outcome, first[:160]


def _orphans(grace: float) -> int:
    """Processes left behind by the last case (killed after ``grace`` seconds); how many."""
    deadline = time.monotonic() + grace
    while True:
        _reap()
        left = _children()
        if not left or time.monotonic() > deadline:
            break
        time.sleep(0.1)
    for pid in left:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    _reap()
    return len(left)


# ------------------------------------------------------------------------------------ categories
def mutants(n: int, seed: int, folder: Path, timeout: float) -> Counter:
    rng = random.Random(seed)
    counts: Counter = Counter()
    examples: dict[str, str] = {}
    for k in range(n):
        what, doc = mutant(rng)
        f = folder / f"mutant{k}.toml"
        f.write_text(to_toml(doc), encoding="utf-8")
        outcome, line = run_case(["scenario", "validate", str(f)], timeout)
        if outcome == Outcome.RAN:
            outcome, line = run_case(["run", str(f), "--seed", "0"], timeout)
        counts[outcome] += 1
        if outcome not in (Outcome.CLEAN, Outcome.RAN):
            examples.setdefault(outcome, f"{what} -> {line}")
    for outcome, text in examples.items():
        print(f"  mutants {outcome}: {text}")
    return counts


def special_files(folder: Path, timeout: float) -> Counter:
    fifo = folder / "fifo.toml"
    os.mkfifo(fifo)
    big = folder / "big.toml"
    with open(big, "wb") as fh:
        fh.truncate(2**30)
    deep = folder / "deep.toml"
    deep.write_text('name = "x"\nnotes = ' + "[" * 50_000 + "]" * 50_000 + "\n")
    dotted = folder / "dotted.toml"
    dotted.write_text(".".join(["a"] * 50_000) + " = 1\n")
    paths = ["/dev/zero", str(fifo), str(big), str(folder), str(deep), str(dotted)]
    counts: Counter = Counter()
    for p in paths:
        for argv in (
            ["scenario", "validate", p],
            ["run", p],
            ["sweep", p, "--results", str(folder / "r")],
            ["compare", "--schedulers", "idle", "--scenarios", p],
        ):
            outcome, line = run_case(argv, timeout)
            counts[outcome] += 1
            if outcome != Outcome.CLEAN:
                print(f"  files {outcome}: {' '.join(argv)} -> {line}")
    return counts


BAD_SPECS = (
    "milp:slots=0", "routing:time_limit=nan", "routing:time_limit=0", "routing:time_limit=-1",
    "routing:max_visits=0", "greedy:route_length=0", "greedy:route_length=x", "greedy:nope=1",
    "cbba:search_altitude=nan", "milp-cvxpy:time_limit=-1", "random:keep_probability=2",
    "idle:x=1", "nosuch", "greedy:", "greedy:=1", ":x=1", "greedy:route_length=1e999",
)  # fmt: skip


def arguments(folder: Path, timeout: float) -> Counter:
    cases: list[list[str]] = []
    for spec in BAD_SPECS:
        cases += [
            ["run", "practice", "-s", spec],
            [
                "compare",
                "--schedulers",
                spec,
                "--scenarios",
                "practice",
                "--seeds",
                "0",
                "--jobs",
                "1",
            ],
        ]
        sweep = folder / f"sweep-{len(cases)}.toml"
        sweep.write_text(f'scenarios = ["practice"]\nschedulers = ["{spec}"]\nseeds = "0"\n')
        cases.append(["sweep", str(sweep), "--results", str(folder / "r2"), "-j", "1"])
    cases += [
        ["run", "practice", "--seed", "-1"], ["run", "practice", "--replan-period", "nan"],
        ["run", "practice", "--time-limit", "0"], ["run", "nosuch"], ["run", "missing.toml"],
        ["compare", "--schedulers", ""], ["compare", "--schedulers", "greedy", "--seeds", "5-1"],
        ["compare", "--schedulers", "greedy", "--jobs", "0"],
        ["compare", "--schedulers", "greedy", "--json", "/nonexistent/x.json"],
        ["sweep", "missing.toml"], ["sweep", str(folder), "--jobs", "-3"],
        ["report", "/nonexistent"], ["report", "/dev/null"], ["replay", "/nonexistent.npz"],
        ["replay", "/dev/zero"], ["scenario", "validate"], ["scenario", "nosuch"],
        ["import-legacy", "/nonexistent"], ["play", "--seed", "x"], ["scenarios", "--nope"],
        ["--nope"], [],
    ]  # fmt: skip
    counts: Counter = Counter()
    for argv in cases:
        outcome, line = run_case(argv, timeout)
        counts[outcome] += 1
        if outcome != Outcome.CLEAN:
            print(f"  arguments {outcome}: {' '.join(argv)} -> {line}")
    return counts


def _full_disk_after(rows: int):
    """A ``prepare`` for :func:`run_case`: the parquet writer fails with ENOSPC after ``rows``."""

    def prepare() -> None:
        import errno

        import pyarrow.parquet as pq

        write, calls = pq.write_table, [0]

        def full(table, where, *a, **kw):
            calls[0] += 1
            if calls[0] > rows:
                raise OSError(errno.ENOSPC, "No space left on device")
            return write(table, where, *a, **kw)

        pq.write_table = full

    return prepare


def sweep_abuse(folder: Path, timeout: float) -> Counter:
    """kill -9 / SIGTERM of the parent, kill -9 of a worker, two sweeps, a full disk."""
    from fcplan.experiments import load_results
    from tests.hardening import sweeps as sw

    counts: Counter = Counter()

    def finished(t: sw.Trial, expect_status: int | None) -> str:
        if t.orphans:
            return Outcome.ORPHAN
        ok = t.resume_status == 0 and t.resumed_rows == sw.EPISODES and not t.stray_temporaries
        if "Traceback" in t.stderr or not ok:
            return Outcome.TRACEBACK
        if expect_status == 143:
            clean = t.status == 143 and t.stderr.splitlines()[0] == "fcplan: terminated"
            return Outcome.CLEAN if clean else Outcome.TRACEBACK
        return Outcome.RAN

    for label, run, expect in (
        ("kill -9 parent", lambda d: sw.kill_parent(d, signal.SIGKILL), None),
        ("SIGTERM parent", lambda d: sw.kill_parent(d, signal.SIGTERM), 143),
        ("kill -9 worker", sw.kill_worker, None),
    ):
        d = folder / label.replace(" ", "_")
        d.mkdir()
        outcome = finished(run(d), expect)
        counts[outcome] += 1
        print(f"  sweeps {label}: {outcome}")
    d = folder / "two"
    d.mkdir()
    first, second = sw.two_sweeps(d)
    lines = second.stderr.strip().splitlines()
    for _t, outcome in (
        (first, finished(first, None)),
        (second, Outcome.CLEAN if second.status == 2 and len(lines) == 1 else Outcome.TRACEBACK),
    ):
        counts[outcome] += 1
    print(f"  sweeps two sweeps: first {finished(first, None)}, second {lines[:1]}")
    d = folder / "enospc"
    d.mkdir()
    config = sw.write_config(d, duration=5.0)
    argv = ["sweep", str(config), "--results", str(d / "r"), "-j", "1", "-q"]
    outcome, line = run_case(argv, timeout, prepare=_full_disk_after(2))
    intact = len(load_results(d / "r")) == 2 and not list((d / "r").glob(".*.tmp"))
    counts[outcome if intact else Outcome.TRACEBACK] += 1
    print(f"  sweeps full disk: {outcome}, rows intact {intact}: {line}")
    return counts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mutants", type=int, default=600)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=180.0)
    ap.add_argument("--only", default="mutants,files,arguments,sweeps")
    args = ap.parse_args()
    libc = ctypes.CDLL(None)
    libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    runs = {
        "mutants": lambda d: mutants(args.mutants, args.seed, d, args.timeout),
        "files": lambda d: special_files(d, args.timeout),
        "arguments": lambda d: arguments(d, args.timeout),
        "sweeps": lambda d: sweep_abuse(d, args.timeout),
    }
    rows = {}
    t0 = time.time()
    for name in args.only.split(","):
        with tempfile.TemporaryDirectory() as tmp:
            rows[name] = runs[name](Path(tmp))
        print(f"{name}: " + ", ".join(f"{o} {rows[name][o]}" for o in Outcome.ALL), flush=True)
    print(f"\n{'category':<10} {'tried':>6} " + " ".join(f"{o:>12}" for o in Outcome.ALL))
    for name, c in rows.items():
        print(f"{name:<10} {sum(c.values()):>6} " + " ".join(f"{c[o]:>12}" for o in Outcome.ALL))
    print(f"\n{time.time() - t0:.0f} s; memory limit {MEMORY_LIMIT / 2**30:g} GiB per case")


if __name__ == "__main__":
    main()
