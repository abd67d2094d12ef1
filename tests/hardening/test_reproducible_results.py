"""Reproducible results under load (issue 17): a comparison gives the same scores whether it runs
its episodes in one process or in two, and an optimisation scheduler in its default compare mode
gives the same trace, byte for byte, on a quiet machine and beside processes that keep every
core busy. A time limit that binds on the wall clock would break both: these tests make the load
differ on purpose (busy-loop processes beside the second run)."""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import subprocess
import sys
from collections.abc import Iterator

import pytest

from fcplan import load_scenario, run_episode
from fcplan.experiments import compare
from fcplan.experiments.compare import scheduler_variant
from fcplan.scheduling import available_schedulers, make_scheduler

BUILT_IN = ("greedy", "routing", "routing-pyvrp", "cbba", "milp", "milp-cvxpy", "oracle",
            "random", "idle")  # fmt: skip
OPTIMISING = ("routing", "routing-pyvrp", "cbba", "milp", "milp-cvxpy")
#: Columns that measure time, not the episode: they may differ between two runs.
TIMING = frozenset({"wall_time_s", "solve_p50_ms", "solve_p95_ms"})
SECONDS = 12.0  # simulated seconds per episode: 12-25 replans each


@contextlib.contextmanager
def busy(n: int = os.cpu_count() or 2) -> Iterator[None]:
    """``n`` processes spinning on the CPU for as long as the block runs."""
    procs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(max(n, 1))]
    try:
        yield
    finally:
        for p in procs:
            p.kill()
            p.wait()


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_every_built_in_scheduler_is_covered():
    """The lists above name every registered built-in scheduler (a new one must be added)."""
    assert set(BUILT_IN) <= set(available_schedulers())
    assert set(OPTIMISING) <= set(BUILT_IN)


@pytest.mark.parametrize("scheduler", BUILT_IN)
def test_compare_gives_the_same_scores_with_one_and_two_jobs(scheduler):
    """compare(..., jobs=1) and compare(..., jobs=2) under extra load give identical episode
    rows (every score, outcome, replan and fallback count; timing columns aside) on 2 scenarios
    x 2 seeds, in the default (deterministic) compare mode."""
    scenarios = [load_scenario(n).replace(duration_s=SECONDS) for n in (12, 24)]
    serial = compare(scenarios, [scheduler], [0, 1], jobs=1)
    with busy():
        parallel = compare(scenarios, [scheduler], [0, 1], jobs=2)
    assert serial.settings["deterministic"] and parallel.settings["jobs"] == 2
    for a, b in zip(serial.episodes, parallel.episodes, strict=True):
        assert not a["error"] and not b["error"], (a["error"], b["error"])
        differ = {k: (a[k], b.get(k)) for k in a if k not in TIMING and not _same(a[k], b.get(k))}
        assert not differ, f"{a['scenario']} seed {a['seed']}: {differ}"


def _trace_digest(spec: str, loaded: bool) -> tuple[str, list[str]]:
    """SHA-256 of every trace array's bytes, and the replan statuses, of one episode of #24
    played with ``spec`` in its default compare mode (beside busy processes if ``loaded``)."""
    name, settings = scheduler_variant(spec)
    scenario = load_scenario(24).replace(duration_s=SECONDS)
    with busy() if loaded else contextlib.nullcontext():
        res = run_episode(scenario, make_scheduler(name, **settings), seed=3)
    h = hashlib.sha256()
    for key, arr in sorted(res.trace.arrays().items()):
        h.update(key.encode())
        h.update(arr.tobytes())
    return h.hexdigest(), [s.status for s in res.solves]


@pytest.mark.parametrize("scheduler", OPTIMISING)
def test_an_optimising_scheduler_gives_the_same_trace_under_load(scheduler):
    """An optimisation scheduler in its default compare mode plays the same episode twice, once
    alone and once beside a busy loop on every core: the traces are equal byte for byte and
    every replan ends with the same status."""
    quiet = _trace_digest(scheduler, loaded=False)
    loaded = _trace_digest(scheduler, loaded=True)
    assert quiet[1] == loaded[1]
    assert quiet[0] == loaded[0]
