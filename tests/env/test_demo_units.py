"""Tests for fcplan.env.demo_units: demonstrations played in worker processes (``jobs``) are the
dataset of one process, whatever the units' completion order; failures name their episodes."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env.demo_units import demo_units, play_unit, play_units
from fcplan.env.demonstrations import DemonstrationError, demonstrations
from fcplan.env.task import TaskEnv
from fcplan.errors import FcplanError, SeedError
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


def test_dask_local_gives_the_dataset_of_one_process(tmp_path):
    """``dask="local"`` (a LocalCluster of two workers, the backend of ``sweep --dask``) gives
    the dataset of one process, and its checkpoint resumes as the pool's does."""
    pytest.importorskip("distributed")
    one = demonstrations("greedy", ["practice", 24], [3, 4], env_kwargs=KW, progress=False)
    ck = tmp_path / "ck"
    on_dask = demonstrations("greedy", ["practice", 24], [3, 4], env_kwargs=KW, jobs=2,
                             dask="local", checkpoint=ck, progress=False)  # fmt: skip
    _same(one, on_dask)
    again = demonstrations("greedy", ["practice", 24], [3, 4], env_kwargs=KW, jobs=2,
                           dask="local", checkpoint=ck, progress=False)  # fmt: skip
    _same(one, again)


@pytest.mark.parametrize("bad", ["", "  ", 3])
def test_a_bad_dask_address_is_one_line(bad):
    """A ``dask`` that is not ``"local"`` or an address is refused in one line, before any
    episode, with sweep's message."""
    with pytest.raises(FcplanError, match="dask must be 'local' or a scheduler address"):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, dask=bad, progress=False)


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
        units = demo_units([(sc, "a", range(5)), (sc, "b", range(5))], g, "greedy", env_kwargs={},
                           time_limit=None, num_envs=num_envs, jobs=jobs)  # fmt: skip
        assert len({u.key for u in units}) == len(units)
        return [(u.scenario_key, u.seeds) for u in units]

    assert seeds(1, 1) == [(k, (s,)) for k in "ab" for s in range(5)]
    assert seeds(4, 1) == [(k, c) for k in "ab" for c in ((0, 1, 2, 3), (4,))]
    assert seeds(4, 2) == [(k, c) for k in "ab" for c in ((0, 1, 2), (3, 4))]
    assert seeds(2, 8) == [(k, (s,)) for k in "ab" for s in range(5)]


def _refuse() -> None:
    raise RuntimeError("refused in the worker")


class _RefusedInWorkers(GreedyScheduler):
    """A greedy scheduler that pickles but cannot be unpickled."""

    def __reduce__(self):
        return (_refuse, ())


def test_a_scheduler_that_cannot_be_pickled_is_refused_before_any_episode():
    """A scheduler object that cannot go to the workers (here: it holds a lambda) is refused in
    one line before the pool starts; with ``jobs=1`` the same object plays."""
    sched = GreedyScheduler()
    sched.hook = lambda: None  # (a lambda does not pickle)
    with pytest.raises(FcplanError, match="jobs=2 sends the scheduler to worker processes, and"):
        demonstrations(sched, ["practice"], [0, 1], env_kwargs=KW, jobs=2, progress=False)
    with pytest.raises(FcplanError, match="dask='local' sends the scheduler to worker processes"):
        demonstrations(sched, ["practice"], [0], env_kwargs=KW, dask="local", progress=False)
    assert demonstrations(sched, ["practice"], [0], env_kwargs=KW, progress=False).n_episodes == 1


def test_a_unit_that_fails_in_a_worker_is_named():
    """A unit whose worker keeps dying (here: its scheduler cannot be unpickled there, which
    ends the worker) stops the run with one error naming its scenario and seeds, after the
    pool's restarts; the unit plays in this process."""
    sched = _RefusedInWorkers()
    sc = load_scenario("practice")
    units = demo_units([(sc, "practice", [0, 1])], sched, sched, env_kwargs=KW, time_limit=None,
                       num_envs=1, jobs=2)  # fmt: skip
    with pytest.raises(
        FcplanError, match=r"practice seeds \[[01]\] produced nothing: worker processes died"
    ):
        play_units(units, 2)
    assert [r.seed for r in play_unit(units[1]).records] == [1]


def test_bad_env_arguments_fail_as_in_one_process():
    """Bad env arguments raise the env's own error before any worker starts, as with jobs=1."""
    from fcplan.errors import EnvError

    for jobs in (1, 2):
        with pytest.raises(EnvError, match="k"):
            demonstrations("greedy", ["practice"], [0, 1], env_kwargs={"k": 0}, jobs=jobs,
                           progress=False)  # fmt: skip


@pytest.mark.parametrize("bad", [["x"], [-1], [1.5], [True], "12", 1.0, None])
def test_bad_seeds_are_one_line(bad):
    """Seeds follow fcplan.world.seed_list: a string, a float, a bool, a negative seed or a
    non-list is a one-line SeedError before any episode."""
    with pytest.raises(SeedError, match=r"^seeds: must be "):
        demonstrations("greedy", ["practice"], bad, env_kwargs=KW, progress=False)


def test_repeated_seeds_play_once():
    """A seed given twice is one episode (the order of first appearance kept), as in compare."""
    d = demonstrations("greedy", ["practice"], [1, 0, 1], env_kwargs=KW, progress=False)
    assert [e["seed"] for e in d.episodes] == [1, 0]


@pytest.mark.parametrize("bad", [0, -1, 1.5, True, "2"])
def test_bad_counts(bad):
    """``jobs`` and ``num_envs`` must be positive integers: one-line errors before any episode."""
    with pytest.raises(FcplanError, match="jobs must be an integer"):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, jobs=bad)
    with pytest.raises(DemonstrationError, match="num_envs: must be an integer >= 1"):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, num_envs=bad)


def test_each_episode_keeps_its_own_mapping_counts():
    """A batched unit's episodes carry the mapping counts of their sequential rollouts, one
    episode each; their sum is the dataset's ``mapping``."""
    sc = load_scenario(24)
    g = make_scheduler("greedy")
    one, many = (demo_units([(sc, "24", [3, 4, 5])], g, "greedy", env_kwargs=KW, time_limit=None,
                            num_envs=b, jobs=1) for b in (1, 3))  # fmt: skip
    seq = [r.counts for u in one for r in play_unit(u).records]
    assert [r.counts for r in play_unit(many[0]).records] == seq
    demo = demonstrations("greedy", [24], [3, 4, 5], env_kwargs=KW, progress=False)
    assert demo.metadata["mapping"] == {k: sum(c[k] for c in seq) for k in seq[0]}
    assert sum(seq[0].values()) == KW["max_steps"] * len(TaskEnv(sc).possible_agents)
