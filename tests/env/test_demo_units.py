"""Tests for fcplan.env.demo_units: demonstrations played in worker processes (``jobs``) are the
dataset of one process, whatever the units' completion order; failures name their episodes."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env.demo_units import demo_units, play_unit, play_units
from fcplan.env.demonstrations import DemonstrationError, demonstrations
from fcplan.errors import FcplanError
from fcplan.scenario import load_scenario
from fcplan.scheduling import make_scheduler
from solvers.greedy import GreedyScheduler

KW = {"k": 4, "max_steps": 6}


def _same(a, b):
    for name, arr in a.arrays.items():
        assert b.arrays[name].dtype == arr.dtype and np.array_equal(b.arrays[name], arr), name
    for key in ("episodes", "mapping", "conflicts", "fallbacks", "scenarios"):
        assert b.metadata[key] == a.metadata[key], key


@pytest.mark.parametrize("num_envs", [1, 2])
def test_jobs_give_the_dataset_of_one_process(num_envs):
    """Two worker processes give the dataset of one process, array for array, with the same
    episode records, scenario documents and mapping counts (single and batched envs); the
    progress callback counts every episode up to the total."""
    one = demonstrations("greedy", ["practice", 24], [3, 4, 5], env_kwargs=KW, num_envs=num_envs,
                         progress=False)  # fmt: skip
    calls = []
    two = demonstrations("greedy", ["practice", 24], [3, 4, 5], env_kwargs=KW, num_envs=num_envs,
                         jobs=2, progress=lambda d, t, row: calls.append((d, t)))  # fmt: skip
    _same(one, two)
    assert [t for _, t in calls] == [6] * len(calls) and calls[-1] == (6, 6)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)


def test_a_scheduler_object_goes_to_the_workers():
    """A scheduler object with its settings plans in the workers as it does here."""
    sched = GreedyScheduler(route_length=1)
    one = demonstrations(sched, ["practice"], [0, 1], env_kwargs=KW, progress=False)
    two = demonstrations(sched, ["practice"], [0, 1], env_kwargs=KW, jobs=2, progress=False)
    _same(one, two)
    assert two.metadata["scheduler_settings"]["route_length"] == 1


def test_units():
    """One unit per seed at ``num_envs=1``; ``num_envs`` seeds per batched unit in one process,
    at most ``ceil(seeds / jobs)`` with more jobs; units keep the dataset's order."""
    sc = load_scenario("practice")
    g = make_scheduler("greedy")

    def seeds(num_envs, jobs):
        units = demo_units([(sc, "a"), (sc, "b")], list(range(5)), g, "greedy", env_kwargs={},
                           time_limit=None, num_envs=num_envs, jobs=jobs)  # fmt: skip
        assert len({u.key for u in units}) == len(units)
        return [(u.scenario_key, u.seeds) for u in units]

    assert seeds(1, 1) == [(k, (s,)) for k in "ab" for s in range(5)]
    assert seeds(4, 1) == [(k, c) for k in "ab" for c in ((0, 1, 2, 3), (4,))]
    assert seeds(4, 2) == [(k, c) for k in "ab" for c in ((0, 1, 2), (3, 4))]
    assert seeds(2, 8) == [(k, (s,)) for k in "ab" for s in range(5)]


def test_a_unit_that_cannot_reach_a_worker_is_named():
    """A unit that fails in the pool (here: a scheduler that cannot be pickled) stops the run
    with one error naming its scenario and seeds."""
    sched = GreedyScheduler()
    sched.hook = lambda: None  # (a lambda does not pickle)
    sc = load_scenario("practice")
    units = demo_units([(sc, "practice")], [0, 1], sched, sched, env_kwargs=KW, time_limit=None,
                       num_envs=1, jobs=2)  # fmt: skip
    with pytest.raises(FcplanError, match=r"practice seeds \[0\] produced nothing: .*ickl"):
        play_units(units, 2)
    assert [r.seed for r in play_unit(units[1]).records] == [1]


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_bad_counts(bad):
    """``jobs`` and ``num_envs`` must be positive integers: one-line errors before any episode."""
    with pytest.raises(FcplanError, match="jobs must be an integer"):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, jobs=bad)
    with pytest.raises(DemonstrationError, match="num_envs: must be an integer >= 1"):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, num_envs=bad)
