"""Tests for fcplan._fast.taskgraph: the fast frozen-dataclass constructor equals the plain one."""

from __future__ import annotations

import dataclasses

import numpy as np

from fcplan._fast.taskgraph import new_frozen
from fcplan.taskgraph import TaskGraph, synthetic_task_graph


def test_new_frozen_equals_the_dataclass_constructor():
    """A task graph made by new_frozen has the fields the constructor gives it (the same
    objects), the cached views it was given, computes the others as usual, and stays frozen."""
    g = synthetic_task_graph(4, 9, np.random.default_rng(0))
    fields = {f.name: getattr(g, f.name) for f in dataclasses.fields(g)}
    d = np.zeros((4, 9))
    fast = new_frozen(TaskGraph, fields, {"agent_task_distance": d})
    plain = TaskGraph(**fields)
    plain.__dict__.update(agent_task_distance=d)
    assert type(fast) is TaskGraph
    assert vars(fast).keys() == vars(plain).keys()
    for name, value in vars(plain).items():
        assert getattr(fast, name) is value, name
    assert fast.agent_task_distance is d
    assert np.array_equal(fast.task_home_distance, g.task_home_distance)
    try:
        fast.tick = 3  # type: ignore[misc]
    except dataclasses.FrozenInstanceError:
        pass
    else:
        raise AssertionError("a graph made by new_frozen is not frozen")
