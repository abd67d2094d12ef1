"""Tests of fcplan.env.action_input: actions are integers, or floats of whole values taken as
those integers; a fractional, non-finite or non-numeric action is an error naming its entry
(never truncated in silence), raised before the env steps, so the worlds lose nothing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.env.action_input import integer_action, integer_actions
from fcplan.env.gym_view import TaskGymEnv
from fcplan.env.joint_gym import JointGymEnv
from fcplan.env.task import TaskEnv
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from tests._fast.bits import bits


@given(st.lists(st.integers(-(2**40), 2**40), min_size=1, max_size=12))
def test_whole_values_of_any_dtype_are_the_integers(values):
    """Ints, bools and whole floats (float64, and float32 where exact) give the same int64s."""
    ref = np.array(values, dtype=np.int64)
    shape = (len(values),)
    assert integer_actions(values, shape).tolist() == values
    assert integer_actions(ref.astype(np.float64), shape).tolist() == values
    small = np.clip(ref, -(2**24), 2**24)
    assert integer_actions(small.astype(np.float32), shape).tolist() == small.tolist()
    assert integer_actions(np.array(values, dtype=object), shape).tolist() == values
    assert integer_actions([True, False], (2,)).tolist() == [1, 0]


@pytest.mark.parametrize(
    "bad, where",
    [
        ([0.0, 1.5], "[1]"),
        ([np.nan, 0], "[0]"),
        ([0, np.inf], "[1]"),
        ([[0, 0], [2, -0.25]], "[1, 1]"),
    ],
)
def test_fractional_and_non_finite_values_are_named(bad, where):
    """The first fractional or non-finite entry is named by its index."""
    shape = np.shape(bad)
    with pytest.raises(EnvError, match=rf"actions\{where[:-1]}\]: must be a whole number"):
        integer_actions(bad, shape)


def test_shapes_and_types():
    """Another shape, strings and other non-numbers are errors naming the expected shape."""
    with pytest.raises(EnvError, match=r"actions: must be integers of shape \(2, 3\)"):
        integer_actions(np.zeros(5), (2, 3))
    with pytest.raises(EnvError, match="must be integers of shape"):
        integer_actions(["a", "b"], (2,))
    with pytest.raises(EnvError, match="must be integers of shape"):
        integer_actions([object(), 1], (2,))


def test_one_agent_value():
    """One agent's value: an integer or a whole float; anything else is named."""
    assert integer_action(np.int16(4), "a") == 4
    assert integer_action(2.0, "a") == 2
    for bad, msg in ((2.5, "whole number"), (float("nan"), "whole number"), ("x", "integer")):
        with pytest.raises(EnvError, match=f"action of u: must be an? {msg}"):
            integer_action(bad, "action of u")


def test_envs_reject_fractions_before_stepping():
    """The Gym views, the PettingZoo task env and both batched envs raise on a fractional
    action and have not stepped: the next legal step is the one a fresh env takes."""
    sc = load_scenario("practice").replace(duration_s=3)
    pairs = [
        (lambda: JointGymEnv(sc), np.zeros(4), np.full(4, 0.5)),
        (lambda: TaskGymEnv(sc), np.full(4, 8), np.full(4, 7.5)),
        (lambda: VectorMotionEnv(sc, 2), np.zeros((2, 4)), np.full((2, 4), 1.25)),
        (lambda: VectorTaskEnv(sc, 2), np.full((2, 4), 8.0), np.full((2, 4), 0.5)),
    ]
    for make, good, bad in pairs:
        env, ref = make(), make()
        env.reset(seed=1)
        ref.reset(seed=1)
        with pytest.raises(EnvError, match="must be a whole number"):
            env.step(bad)
        out, want = env.step(good), ref.step(good)
        assert all(bits(out[0][k]) == bits(want[0][k]) for k in want[0])
        assert bits(np.asarray(out[1])) == bits(np.asarray(want[1]))
    pz = TaskEnv(sc)
    pz.reset(seed=0)
    with pytest.raises(EnvError, match="action of .*: must be a whole number"):
        pz.step({pz.possible_agents[0]: 1.5})
