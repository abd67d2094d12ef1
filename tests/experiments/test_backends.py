"""Tests for fcplan.experiments.backends: which backend runs a batch, and substitute players."""

from __future__ import annotations

import pytest

from fcplan.experiments.backends import select_backend


class _Spec:
    def __init__(self, key: str):
        self.key = key


def _square(spec: _Spec) -> int:
    """A module-level (so picklable) player: the square of the spec's key."""
    return int(spec.key) ** 2


def test_backend_choice():
    """jobs=1 or a single spec runs here; more run on a pool of at most one worker per spec;
    a Dask address names the Dask backend but starts nothing for no specs."""
    specs = [_Spec(str(k)) for k in range(3)]
    assert select_backend(specs, 1)[0] == "serial"
    assert select_backend(specs[:1], 8)[0] == "serial"
    name, outcomes = select_backend(specs, 8, play=_square)
    outcomes.close()
    assert name == "pool:3"
    name, outcomes = select_backend([], 2, dask="tcp://nowhere:1")
    assert (name, list(outcomes)) == ("dask:tcp://nowhere:1", [])


def test_substitute_player_runs_on_every_backend():
    """``play`` replaces the sweep episode player, in this process and in pool workers alike."""
    specs = [_Spec(str(k)) for k in range(4)]
    for jobs in (1, 2):
        _, outcomes = select_backend(specs, jobs, play=_square)
        got = {spec.key: (result, lost) for spec, result, lost in outcomes}
        assert got == {str(k): (k * k, None) for k in range(4)}


@pytest.mark.parametrize("method", ["fork", "forkserver", "spawn"])
def test_workers_that_die_with_their_parent_run_under_every_start_method(method):
    """init_worker's parent watch (the sweep's pid, and the process that forked the worker,
    which is a fork server under 'forkserver') does not end healthy workers."""
    import multiprocessing as mp
    import os
    from concurrent.futures import ProcessPoolExecutor

    from fcplan.experiments.workers import init_worker

    ctx = mp.get_context(method)
    with ProcessPoolExecutor(
        2, mp_context=ctx, initializer=init_worker, initargs=({}, os.getpid())
    ) as ex:
        assert list(ex.map(abs, [-1, -2, -3])) == [1, 2, 3]
