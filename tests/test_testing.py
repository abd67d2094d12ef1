"""The scheduler conformance kit (:mod:`fcplan.testing`): it passes every built-in scheduler (the
README's example: tests/test_readme.py) and catches the faults it promises to catch."""

from __future__ import annotations

import itertools
from typing import Any

import pytest

from fcplan import Plan
from fcplan.scheduling import available_schedulers, make_scheduler
from fcplan.testing import check_scheduler, episode_graphs

#: a spread of shipped scenarios for the default suite (all of them: the slow test below)
SUBSET = ("practice", "1", "12", "24", "open_world_example", "scale_example")
BUILTIN = ("greedy", "idle", "random", "routing", "routing-pyvrp", "milp", "milp-cvxpy", "cbba",
           "oracle")  # fmt: skip
#: settings that make a scheduler's plans independent of wall time and load
DETERMINISTIC = {
    "routing": {"deterministic": True},
    "routing-pyvrp": {"deterministic": True},
    # wall-clock solvers: a limit far above their solve times (ms) keeps the run load-proof
    "milp": {"time_limit": 30.0},
    "milp-cvxpy": {"time_limit": 30.0},
}


def _factory(name: str, **extra: Any):
    settings = {**DETERMINISTIC.get(name, {}), **extra}
    return lambda: make_scheduler(name, **settings)


def test_the_kit_runs_on_every_registered_scheduler():
    """BUILTIN names every scheduler of the package's entry-point table in pyproject.toml (a new
    one is added to the kit); tests may register more at run time, which are not built in."""
    import tomllib
    from pathlib import Path

    pyproject = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    table = set(pyproject["project"]["entry-points"]["fcplan.schedulers"])
    assert set(BUILTIN) == table
    assert table <= set(available_schedulers())


@pytest.mark.parametrize("name", BUILTIN)
def test_builtin_schedulers_conform(name):
    """Every built-in scheduler, in its deterministic mode, returns valid plans, the same plan
    for the same seed, and leaves the graph unchanged, on graphs of several shipped scenarios."""
    report = check_scheduler(
        _factory(name), scenarios=SUBSET, ticks=(0, 300), time_limit=None, timeout_limit=None
    )  # (the time-out check: test_builtin_schedulers_answer_a_time_out)
    assert report.graphs == 2 * len(SUBSET) and report.failures == []


@pytest.mark.parametrize("name", BUILTIN)
def test_builtin_schedulers_answer_a_time_out(name):
    """At a limit nobody can meet (1 us) every built-in scheduler, in its wall-clock mode, still
    answers with a valid plan that leaves no role with work idle (or, for schedulers that
    declare their plans independent of the clock, its own decision): the kit's time-out check."""
    report = check_scheduler(
        lambda: make_scheduler(name), scenarios=SUBSET, ticks=(0, 300), time_limit=None,
        timeout_limit=1e-6, determinism_every=0, raise_on_failure=False,
    )  # fmt: skip
    assert report.failures == []


def test_the_time_out_check_catches_an_idle_answer_and_a_raise():
    """The kit fails a clock-bound scheduler that answers a time-out with an empty plan, and
    one that raises, naming the limit; a scheduler declaring ``deterministic = True`` may
    answer with an empty plan."""

    class GivesUp:
        name = "gives-up"

        def plan(self, graph, *, time_limit=None, rng=None):
            if time_limit is not None and time_limit < 1e-3:
                return Plan()
            return make_scheduler("greedy").plan(graph, time_limit=None, rng=rng)

    class Raises(GivesUp):
        def plan(self, graph, *, time_limit=None, rng=None):
            if time_limit is not None and time_limit < 1e-3:
                raise RuntimeError("no time")
            return super().plan(graph, time_limit=time_limit, rng=rng)

    kw = {"scenarios": ["24"], "ticks": (300,), "time_limit": None, "raise_on_failure": False}
    idle = check_scheduler(GivesUp, **kw)
    assert idle.failures and "time_limit=1e-06" in idle.failures[0] and "idle" in idle.failures[0]
    raising = check_scheduler(Raises, **kw)
    assert raising.failures and "RuntimeError: no time" in raising.failures[0]
    assert check_scheduler(lambda: make_scheduler("idle"), **kw).failures == []


@pytest.mark.slow  # a wall-clock check: meaningful on a quiet machine only, so not by default
@pytest.mark.parametrize("name", ["greedy", "routing", "milp", "cbba"])
def test_builtin_schedulers_respect_a_time_limit(name):
    """In wall-clock mode each optimisation scheduler returns within its limit (+10 % +50 ms)."""
    settings = {"deterministic": False} if name == "routing" else {}
    report = check_scheduler(
        _factory(name, **settings),
        scenarios=("1", "24"),
        ticks=(0, 300),
        time_limit=0.2,
        timeout_limit=None,
        determinism_every=0,
    )
    assert report.failures == []


@pytest.mark.slow
@pytest.mark.parametrize("name", BUILTIN)
def test_builtin_schedulers_conform_on_every_shipped_scenario(name):
    """The same checks on every shipped scenario at three ticks of the episode."""
    check_scheduler(_factory(name), time_limit=None, timeout_limit=None)


_CALLS = itertools.count()


class _Faulty:
    """A scheduler whose fault is chosen by ``kind``."""

    name = "faulty"

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self.calls = 0

    def plan(self, graph, *, time_limit=None, rng=None) -> Plan:
        self.calls += 1
        if self.kind == "invalid":
            return Plan(routes={graph.agent_ids[0]: ("no-such-task",)})
        if self.kind == "mutates":
            graph.agent_pos[0, 0] += 1.0
        if self.kind == "stateful":  # a process-wide counter: each call differs from the last
            agent = graph.agent_ids[next(_CALLS) % graph.n_agents]
            return Plan(routes={agent: ()})
        return Plan()


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("invalid", "invalid plan"),
        ("mutates", "changed graph arrays"),
        ("stateful", "deterministic"),
    ],
)
def test_kit_reports_each_fault(kind, message):
    """An invalid plan, a mutated graph and state shared between instances each fail the kit with a
    line naming the scenario, the tick and the fault."""
    report = check_scheduler(
        lambda: _Faulty(kind),
        scenarios=["1"],
        ticks=(0, 100, 200, 300),
        time_limit=None,
        determinism_every=1,
        raise_on_failure=False,
    )
    assert any(message in f and "scenario 1 tick" in f for f in report.failures), report.failures
    with pytest.raises(AssertionError, match="conformance"):
        check_scheduler(lambda: _Faulty(kind), scenarios=["1"], ticks=(0, 100, 200, 300),
                        time_limit=None, determinism_every=1)  # fmt: skip


def test_episode_graphs_are_taken_at_replan_ticks():
    """Graphs come from the greedy episode's replans: ticks round up to the next replan, the
    episode's end drops the rest."""
    graphs = episode_graphs("practice", (0, 5, 10, 10**6))
    assert [g.tick for g in graphs] == [0, 10]


class _BatchDiffers:
    """Greedy whose ``plan_batch`` drops the last graph's routes (or raises)."""

    name = "batch-differs"

    def __init__(self, how: str) -> None:
        from solvers.greedy import GreedyScheduler

        self._g, self.how = GreedyScheduler(), how

    def plan(self, graph, *, time_limit=None, rng=None):
        return self._g.plan(graph, time_limit=time_limit, rng=rng)

    def plan_batch(self, graphs, *, time_limit=None, rngs=None):
        if self.how == "raises":
            raise RuntimeError("no batch today")
        plans = self._g.plan_batch(graphs)
        plans[-1] = Plan()
        return plans


@pytest.mark.parametrize(("how", "message"), [("differs", "differs from plan's"),
                                              ("raises", "plan_batch: RuntimeError")])  # fmt: skip
def test_kit_checks_plan_batch_against_plan(how, message):
    """A scheduler with ``plan_batch`` must return plan's plans graph for graph: one that differs
    on a graph (named by scenario and tick) or raises fails the kit; greedy's passes."""
    kw = {"scenarios": ["1"], "ticks": (0, 300), "time_limit": None, "raise_on_failure": False}
    report = check_scheduler(lambda: _BatchDiffers(how), **kw)
    assert len(report.failures) == 1 and message in report.failures[0], report.failures
    assert how == "raises" or "scenario 1 tick 300" in report.failures[0]
    assert check_scheduler(lambda: make_scheduler("greedy"), **kw).failures == []
