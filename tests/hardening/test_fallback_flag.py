"""A run whose scheduler fell back on more than half of its replans is flagged end to end (issue
17): in the EpisodeResult, in the compare table and its text, in the sweep's rows and in the
report."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan import load_scenario, run_episode, scheduling
from fcplan.episode import fell_back_mostly
from fcplan.experiments import compare, load_results, report, sweep


class FailsSome:
    """Greedy, except that it raises on ``fail`` of every ``period`` calls (so the episode falls
    back on about that fraction of its replans)."""

    name = "fails-some-test"

    def __init__(self, fail: int = 1, period: int = 1) -> None:
        self.fail, self.period, self.calls = fail, period, 0
        self._greedy = scheduling.make_scheduler("greedy")

    def plan(self, graph, *, time_limit=None, rng=None):
        self.calls += 1
        if (self.calls - 1) % self.period < self.fail:
            raise RuntimeError("planned failure")
        return self._greedy.plan(graph, time_limit=time_limit, rng=rng)


@pytest.fixture
def failing(monkeypatch):
    monkeypatch.setitem(scheduling._RUNTIME, "fails-some-test", FailsSome)
    return load_scenario("practice").replace(duration_s=6.0)


@given(st.integers(0, 10_000), st.integers(0, 10_000))
def test_the_rule_is_strictly_more_than_half(fallbacks, replans):
    """fell_back_mostly is fallbacks > replans / 2, and False without replans."""
    assert fell_back_mostly(fallbacks, replans) == (replans > 0 and 2 * fallbacks > replans)


@pytest.mark.parametrize(
    "spec, flagged",
    [("fails-some-test", True), ("fails-some-test:fail=2:period=3", True),
     ("fails-some-test:fail=1:period=3", False), ("fails-some-test:fail=0", False)],
)  # fmt: skip
def test_the_episode_result_flags_mostly_fallen_back_runs(failing, spec, flagged):
    """EpisodeResult.fallback_majority (and its summary) is set exactly when more than half of
    the replans fell back."""
    name, settings = scheduling.parse_scheduler_spec(spec)
    res = run_episode(failing, scheduling.make_scheduler(name, **settings), seed=0)
    assert res.fallbacks == sum(s.status == "fallback" for s in res.solves)
    assert res.fallback_majority is flagged
    assert res.fallback_majority == fell_back_mostly(res.fallbacks, len(res.solves))
    assert res.summary()["fallback_majority"] is flagged


def test_compare_sweep_and_report_carry_the_flag(failing, tmp_path):
    """The same episodes flagged in compare's rows, table and text, in the sweep's stored rows
    and in the report's fallback warning; a scheduler that never falls back is not flagged."""
    schedulers = ["greedy", "fails-some-test"]
    res = compare([failing], schedulers, [0, 1], jobs=1)
    by = {r["scheduler"]: r for r in res.table()}
    assert (by["fails-some-test"]["fallback_majority"], by["greedy"]["fallback_majority"]) == (2, 0)
    assert "fails-some-test: 2 of 2 episode(s) fell back to greedy" in res.format()
    config = {"scenarios": ["practice"], "schedulers": schedulers, "seeds": [0, 1],
              "overrides": {"duration_s": 6}}  # fmt: skip
    sweep(config, tmp_path, jobs=1, progress=False)
    df = load_results(tmp_path)
    flags = df.groupby("scheduler")["fallback_majority"].sum().to_dict()
    assert flags == {"fails-some-test": 2, "greedy": 0}
    md = report(tmp_path, plots=False).markdown
    warning = md.split("## Fallback warning")[1]
    assert "| fails-some-test | 2 | 2 |" in warning and "| greedy |" not in warning
