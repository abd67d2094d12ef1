"""Robustness audit (issues 15 and 17): bad inputs through the ``fcplan`` command line, counted
by outcome.

Every case runs ``fcplan argv`` in a forked child of this process, in a session of its own, with
an address-space limit (``RLIMIT_AS``, 6 GiB) and a time bound, and is classified from its exit
status and stderr (:mod:`tests.hardening.runner`):

* clean error: exit 2, exactly one line ``fcplan: error: ...`` on stderr, no traceback;
* ran: exit 0; traceback: anything else; hang: over the time bound; OOM: a MemoryError, "out of
  memory" or killed at the memory limit; orphan: a process of the case's session still alive
  5 s after the case ended (pool workers must notice their parent's death within 1 s).

Categories:

1. ``mutants``: mutated shipped scenario files (:func:`tests.hardening.mutate.mutant`), each
   through ``fcplan scenario validate`` and, when valid, ``fcplan run`` (its own duration, greedy);
2. ``files``: special paths as scenarios and sweep files (``/dev/zero``, a FIFO, a 1 GiB sparse
   file, a folder, deep nesting, a 50,000-part dotted key) and scenarios of 1,000 and 10,000
   agents (validation time printed: it must grow linearly);
3. ``specs``: bad scheduler specs through ``run``, ``compare`` and ``sweep``; every setting of
   every registered scheduler given NaN, infinities, signs, zero, huge and non-numbers (a
   setting accepted is "ran": listed, since a scheduler may legitimately accept it);
4. ``arguments``: the hand-written bad arguments of ``tests/cli/test_cli_abuse.py``, and every
   option and positional of every command given each hostile value
   (:mod:`tests.hardening.options`, generated from the parser);
5. ``recordings``: damaged recordings through ``fcplan replay --video`` (``tests.hardening.damage``);
6. ``results``: damaged results folders through ``fcplan report`` and a resuming ``fcplan sweep``;
7. ``legacy``: damaged legacy folders through ``fcplan import-legacy``;
8. ``sweeps``: kill -9 of a sweep's parent, SIGTERM, kill -9 of a worker, two sweeps into one
   folder, a full disk (ENOSPC injected in the writer, and a real 64 KiB tmpfs when this process
   may mount one in a user namespace).

Usage::

    PYTHONPATH=$PWD nice python bench/audit_hardening.py                    # everything
    PYTHONPATH=$PWD nice python bench/audit_hardening.py --only specs,sweeps
    PYTHONPATH=$PWD nice python bench/audit_hardening.py --mutants 600 --damaged 100 --seed 0
"""

from __future__ import annotations

import argparse
import os
import random
import signal
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path

from tests.hardening import damage
from tests.hardening.mutate import mutant, to_toml
from tests.hardening.options import Fixtures, option_cases
from tests.hardening.runner import MEMORY_LIMIT, Case, Outcome, run_cli

SPEC_VALUES = ("nan", "inf", "-inf", "-1", "0", "1e-300", "1e300", "99999999999999999999", "x",
               "true", "[1]")  # fmt: skip
BAD_SPECS = (
    "milp:slots=0", "milp:slots=x", "routing:time_limit=nan", "routing:time_limit=0",
    "routing:time_limit=-1", "routing:max_visits=-1", "greedy:route_length=0", "greedy:route_length=x", "greedy:nope=1",
    "cbba:search_altitude=nan", "milp-cvxpy:time_limit=-1", "random:keep_probability=2",
    "idle:x=1", "nosuch", "greedy:", "greedy:=1", ":x=1", "greedy:route_length=1e999",
)  # fmt: skip


class Tally:
    """Outcome counts of one category, with the first example of each non-clean outcome."""

    def __init__(self, name: str, timeout: float, cwd: Path, show_ran: bool = False) -> None:
        self.name, self.timeout, self.show_ran = name, timeout, show_ran
        self.cwd = cwd  # relative paths in hostile arguments land here
        self.counts: Counter = Counter()
        self.seen: set[tuple[str, str]] = set()
        self.peak_mb, self.slowest = 0.0, 0.0

    def run(self, argv: list[str], what: str = "", **kw) -> Case:
        case = run_cli(argv, cwd=self.cwd, timeout=self.timeout, fork=True, **kw)
        self.add(case, what or " ".join(argv))
        return case

    def add(self, case: Case, what: str) -> None:
        self.counts[case.outcome] += 1
        self.peak_mb, self.slowest = (
            max(self.peak_mb, case.peak_mb),
            max(self.slowest, case.seconds),
        )
        show = case.outcome not in (Outcome.CLEAN, Outcome.RAN) or (
            self.show_ran and case.outcome == Outcome.RAN
        )
        if show and (case.outcome, what) not in self.seen:
            self.seen.add((case.outcome, what))
            print(f"  {self.name} {case.outcome}: {what[:150]} -> {case.first_line[:150]}")


# ------------------------------------------------------------------------------------ categories
def mutants(t: Tally, folder: Path, n: int, seed: int) -> None:
    rng = random.Random(seed)
    for k in range(n):
        what, doc = mutant(rng)
        f = folder / f"mutant{k}.toml"
        f.write_text(to_toml(doc), encoding="utf-8")
        case = run_cli(["scenario", "validate", str(f)], cwd=folder, timeout=t.timeout, fork=True)
        if case.outcome == Outcome.RAN:
            argv = ["run", str(f), "--seed", "0"]
            case = run_cli(argv, cwd=folder, timeout=t.timeout, fork=True)
        t.add(case, what)


def special_files(t: Tally, folder: Path) -> None:
    fifo = folder / "fifo.toml"
    os.mkfifo(fifo)
    big = folder / "big.toml"
    with open(big, "wb") as fh:
        fh.truncate(2**30)
    deep = folder / "deep.toml"
    deep.write_text('name = "x"\nnotes = ' + "[" * 50_000 + "]" * 50_000 + "\n")
    dotted = folder / "dotted.toml"
    dotted.write_text(".".join(["a"] * 50_000) + " = 1\n")
    for p in ["/dev/zero", str(fifo), str(big), str(folder), str(deep), str(dotted)]:
        t.run(["scenario", "validate", p])
        t.run(["run", p])
        t.run(["sweep", p, "--results", str(folder / "r")])
        t.run(["compare", "--schedulers", "idle", "--scenarios", p])
    for n in (1_000, 10_000):
        f = folder / f"team{n}.toml"
        f.write_text(to_toml(_big_team(n)), encoding="utf-8")
        case = t.run(["scenario", "validate", str(f)], f"validate a team of {n:,} agents")
        print(f"  files: a team of {n:,} agents validates in {case.seconds:.2f} s "
              f"({case.outcome}; load {os.getloadavg()[0]:.1f})")  # fmt: skip


def _big_team(n: int) -> dict:
    """#12 on a 2,000-px map with ``n`` agents (half perception, half action), each with its
    own battery and speed (per-agent lists: the validator's per-agent path)."""
    from fcplan.scenario import load_scenario

    doc = load_scenario(12).to_dict()
    doc["world_size"] = 2_000
    for role in ("perception", "action"):
        team = doc["team"][role]
        team["count"] = n // 2
        team["battery"] = [400.0 + k % 200 for k in range(n // 2)]
        team["speed"] = [15.0 + k % 10 for k in range(n // 2)]
    return doc


def specs(t: Tally, folder: Path) -> None:
    for k, spec in enumerate(BAD_SPECS):
        t.run(["run", "practice", "-s", spec])
        t.run(["compare", "--schedulers", spec, "--scenarios", "practice", "--seeds", "0",
               "--jobs", "1"])  # fmt: skip
        sweep = folder / f"sweep-{k}.toml"
        sweep.write_text(f'scenarios = ["practice"]\nschedulers = ["{spec}"]\nseeds = "0"\n')
        t.run(["sweep", str(sweep), "--results", str(folder / "r"), "-j", "1"])
    short = folder / "short.toml"
    from fcplan.scenario import load_scenario
    from fcplan.scenario.write import dump_scenario

    dump_scenario(load_scenario("practice").replace(duration_s=3.0), short)
    accepted = Tally("specs", t.timeout, folder, show_ran=True)
    for name, setting in _settings():
        for value in SPEC_VALUES:
            accepted.run(["run", str(short), "-s", f"{name}:{setting}={value}"])
    t.counts += accepted.counts
    t.peak_mb, t.slowest = max(t.peak_mb, accepted.peak_mb), max(t.slowest, accepted.slowest)


def _settings() -> list[tuple[str, str]]:
    """(scheduler, setting) for every setting of every registered scheduler."""
    import inspect

    from fcplan.scheduling import available_schedulers, scheduler_factory

    out = []
    for name in available_schedulers():
        factory = scheduler_factory(name)
        try:
            params = inspect.signature(factory).parameters.values()
        except (TypeError, ValueError):
            continue
        kinds = (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
        out += [(name, p.name) for p in params if p.kind in kinds]
    return out


def arguments(t: Tally, folder: Path) -> None:
    from tests.cli.test_cli_abuse import BAD_ARGUMENTS

    for argv in BAD_ARGUMENTS:
        t.run(list(argv))
    grid = folder / "grid.toml"  # 240 episodes: --jobs is not capped by a small grid
    grid.write_text('scenarios = ["1-24"]\nschedulers = ["idle"]\nseeds = "0-9"\n')
    for jobs in ("99999999999999999999", "1000"):
        t.run(["sweep", str(grid), "--results", str(folder / "grid"), "--jobs", jobs])
        t.run(["compare", "--schedulers", "idle", "--scenarios", "1-24", "--seeds", "0-9",
               "--jobs", jobs])  # fmt: skip
    fx = Fixtures.make(folder / "fx")
    for c in option_cases(fx):
        t.run(c.argv, f"{c.command} {c.option}={c.value!r}")


def recordings(t: Tally, folder: Path, n: int, seed: int) -> None:
    fx = Fixtures.make(folder / "fx")
    out = str(folder / "out.gif")
    for what, path in damage.recordings(str(folder / "rec"), fx.recording, fx.legacy, n,
                                        random.Random(seed)):  # fmt: skip
        t.run(["replay", path, "--video", out, "--size", "64"], what)


def results(t: Tally, folder: Path, n: int, seed: int) -> None:
    fx = Fixtures.make(folder / "fx")
    for what, path in damage.results_folders(str(folder / "res"), fx.results, n,
                                             random.Random(seed)):  # fmt: skip
        t.run(["report", path, "--out", str(folder / "report")], f"report: {what}")
        t.run(["sweep", fx.study, "--results", path, "-j", "1", "-q"], f"sweep: {what}")


def legacy(t: Tally, folder: Path, n: int, seed: int) -> None:
    fx = Fixtures.make(folder / "fx")
    out = str(folder / "imported.npz")
    for what, path in damage.legacy_folders(str(folder / "leg"), fx.legacy, fx.recording, n,
                                            random.Random(seed)):  # fmt: skip
        t.run(["import-legacy", path, "--out", out], what)


def _full_disk_after(rows: int) -> Callable[[], None]:
    """A ``prepare`` for :func:`run_cli`: the parquet writer fails with ENOSPC after ``rows``."""

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


def sweeps(t: Tally, folder: Path) -> None:
    """kill -9 / SIGTERM of the parent, kill -9 of a worker, two sweeps, a full disk."""
    from fcplan.experiments import load_results
    from tests.hardening import sweeps as sw

    for label, trial in (
        ("kill -9 parent", lambda d: sw.kill_parent(d, signal.SIGKILL)),
        ("SIGTERM parent", lambda d: sw.kill_parent(d, signal.SIGTERM)),
        ("kill -9 worker", sw.kill_worker),
        ("two sweeps, first", lambda d: sw.two_sweeps(d)[0]),
        ("two sweeps, second", lambda d: sw.two_sweeps(d)[1]),
        ("full tmpfs", sw.full_tmpfs),
    ):
        d = folder / label.replace(" ", "_").replace(",", "")
        d.mkdir()
        result = trial(d)
        if result is None:
            print(f"  sweeps {label}: skipped (cannot mount a tmpfs here)")
            continue
        outcome = sw.outcome(result)
        t.counts[outcome] += 1
        print(f"  sweeps {label}: {outcome} (exit {result.status}, rows {result.rows}, "
              f"resumed {result.resumed_rows}/{sw.EPISODES})")  # fmt: skip
    d = folder / "enospc"
    d.mkdir()
    config = sw.write_config(d, duration=5.0)
    argv = ["sweep", str(config), "--results", str(d / "r"), "-j", "1", "-q"]
    case = run_cli(argv, cwd=d, timeout=t.timeout, fork=True, prepare=_full_disk_after(2))
    intact = len(load_results(d / "r")) == 2 and not list((d / "r").glob(".*.tmp"))
    t.add(case if intact else Case(argv, Outcome.TRACEBACK, 1, "rows lost", 0, 0), "ENOSPC")
    print(f"  sweeps ENOSPC injected: {case.outcome}, rows intact {intact}: {case.first_line}")


CATEGORIES = ("mutants", "files", "specs", "arguments", "recordings", "results", "legacy", "sweeps")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mutants", type=int, default=600)
    ap.add_argument("--damaged", type=int, default=100, help="random damaged files per reader")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=180.0)
    ap.add_argument("--only", default=",".join(CATEGORIES))
    args = ap.parse_args()
    runs = {
        "mutants": lambda t, d: mutants(t, d, args.mutants, args.seed),
        "files": special_files,
        "specs": specs,
        "arguments": arguments,
        "recordings": lambda t, d: recordings(t, d, args.damaged, args.seed),
        "results": lambda t, d: results(t, d, args.damaged, args.seed),
        "legacy": lambda t, d: legacy(t, d, args.damaged, args.seed),
        "sweeps": sweeps,
    }
    tallies = []
    t0 = time.time()
    os.environ["SDL_VIDEODRIVER"] = "dummy"  # fcplan play --screenshot, headless
    os.environ["SDL_AUDIODRIVER"] = "dummy"
    print(f"load average at start: {os.getloadavg()}", flush=True)
    for name in args.only.split(","):
        t1 = time.time()
        with tempfile.TemporaryDirectory() as tmp:
            scratch = Path(tmp) / "cwd"
            scratch.mkdir()
            tally = Tally(name, args.timeout, scratch)
            os.environ["FCPLAN_DATA_DIR"] = str(scratch)  # games are recorded there
            runs[name](tally, Path(tmp))
        c = tally.counts
        print(f"{name}: " + ", ".join(f"{o} {c[o]}" for o in Outcome.ALL)
              + f"; slowest {tally.slowest:.1f} s, peak RSS {tally.peak_mb:.0f} MB, "
              f"{time.time() - t1:.0f} s", flush=True)  # fmt: skip
        tallies.append(tally)
    print("\n| category | tried | " + " | ".join(Outcome.ALL) + " | slowest s | peak MB |")
    print("|" + " --- |" * (len(Outcome.ALL) + 4))
    for tl in tallies:
        cells = " | ".join(str(tl.counts[o]) for o in Outcome.ALL)
        print(f"| {tl.name} | {sum(tl.counts.values())} | {cells} | {tl.slowest:.1f} | "
              f"{tl.peak_mb:.0f} |")  # fmt: skip
    print(
        f"\n{time.time() - t0:.0f} s; bound {args.timeout:g} s and "
        f"{MEMORY_LIMIT / 2**30:g} GiB per case; load average at end {os.getloadavg()}"
    )


if __name__ == "__main__":
    sys.exit(main())
