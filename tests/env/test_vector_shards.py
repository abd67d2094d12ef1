"""Tests of fcplan.env.vector_shards: the worlds of a batched env split over processes are, step
for step, the worlds of one batched env (observations, rewards, flags and infos, episode ends
and autoresets included, at both levels); bad input fails before any shard steps; a failed
shard is named and stops the env; the workers are gone after ``close``."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env import vector_env
from fcplan.env.vector_shards import ShardedVectorEnv, merge_infos
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from tests._fast.bits import bits, same_values


def _actions(rng, obs, level, nvec):
    """Random actions: mostly legal slots or moves by the masks, some out of the masks."""
    m = obs["action_mask"]
    act = (rng.random(m.shape) * m).argmax(axis=2)
    wild = rng.random(act.shape) < 0.1
    return np.where(wild, rng.integers(0, nvec, act.shape), act)


@pytest.mark.parametrize("level, duration, steps", [("motion", 2, 45), ("task", 3, 8)])
@pytest.mark.parametrize("mode", ["next_step", "same_step"])
def test_same_as_one_batched_env(level, duration, steps, mode):
    """7 worlds in 3 processes against one batched env of 7: every step's observations,
    rewards, terminations, truncations and infos (metrics, final observations) are equal,
    through two episode ends and their autoresets."""
    sc = load_scenario("practice").replace(duration_s=duration)
    ref = vector_env(sc, mode=level, num_envs=7, autoreset_mode=mode)
    env = vector_env(sc, mode=level, num_envs=7, autoreset_mode=mode, processes=3)
    try:
        assert isinstance(env, ShardedVectorEnv) and env.shards == [(0, 3), (3, 5), (5, 7)]
        assert env.single_observation_space == ref.single_observation_space
        assert env.single_action_space == ref.single_action_space
        out, want = env.reset(seed=4), ref.reset(seed=4)
        assert same_values(out[0], want[0]) and same_values(out[1], want[1])
        rng = np.random.default_rng(0)
        nvec = ref.single_action_space.nvec
        ended = 0
        for t in range(steps):
            act = _actions(rng, want[0], level, nvec)
            out, want = env.step(act), ref.step(act)
            assert same_values(out, want), t
            ended += int(want[3].any())
        assert ended >= 2
    finally:
        env.close()


def test_masked_resets_and_held_worlds():
    """``autoreset_mode="disabled"``: seeds by list and by int with a reset mask that touches
    some shards only give the one-process env's worlds; held worlds stay held."""
    sc = load_scenario("practice").replace(duration_s=1)
    ref = vector_env(sc, mode="motion", num_envs=5, autoreset_mode="disabled")
    env = vector_env(sc, mode="motion", num_envs=5, autoreset_mode="disabled", processes=2)
    try:
        zero = np.zeros((5, 4), dtype=np.int64)
        for call in (
            {"seed": [3, 4, 5, 6, 7]},
            {"seed": 11, "options": {"reset_mask": np.array([0, 1, 0, 0, 1], dtype=bool)}},
            {"seed": [8], "options": {"reset_mask": np.array([0, 0, 0, 1, 0], dtype=bool)}},
            {"options": {"reset_mask": np.array([1, 0, 0, 0, 0], dtype=bool)}},
        ):
            assert same_values(env.reset(**call), ref.reset(**call))
            for _ in range(sc.n_ticks + 2):
                assert same_values(env.step(zero), ref.step(zero))
        assert bits(env.state()) == bits(ref.state())
    finally:
        env.close()


def test_bad_input_fails_before_any_shard_steps():
    """A bad action (out of an agent's range, fractional, wrong shape) raises EnvError and no
    world has stepped: the next step is the one-process env's first; bad options, process
    counts, an unknown level and the task level's state() are errors before or without any
    step."""
    sc = load_scenario("practice").replace(duration_s=2)
    ref = vector_env(sc, mode="motion", num_envs=4)
    env = vector_env(sc, mode="motion", num_envs=4, processes=2)
    try:
        env.reset(seed=1), ref.reset(seed=1)
        bad = np.zeros((4, 4), dtype=np.int64)
        bad[3, 2] = 99
        with pytest.raises(EnvError, match=r"actions\[3, 2\] \(A1\): must be an integer in 0..5"):
            env.step(bad)
        with pytest.raises(EnvError, match="whole number"):
            env.step(np.full((4, 4), 0.5))
        with pytest.raises(EnvError, match=r"shape \(4, 4\)"):
            env.step(np.zeros(3))
        zero = np.zeros((4, 4), dtype=np.int64)
        assert same_values(env.step(zero), ref.step(zero))
    finally:
        env.close()
    with pytest.raises(EnvError, match="processes: must be in 1..num_envs=2"):
        vector_env(sc, mode="motion", num_envs=2, processes=3)
    with pytest.raises(EnvError, match="view"):
        vector_env(sc, mode="motion", num_envs=2, processes=2, view=4)
    for procs in (None, 2):
        with pytest.raises(EnvError, match="mode: must be one of motion, task .got 'grid'"):
            vector_env(sc, mode="grid", num_envs=2, processes=procs)
    task = vector_env(sc, mode="task", num_envs=2, processes=1)
    with pytest.raises(EnvError, match="only the motion level"):
        task.state()
    task.close()


def test_failed_shard_is_named_and_stops_the_env():
    """A call that fails names the shard and leaves the env usable; a worker that dies is
    reported with its worlds at the next step, after which the env refuses to go on; close()
    still returns and the workers are gone."""
    env = vector_env("practice", mode="motion", num_envs=4, processes=2)
    env.reset(seed=0)
    zero = np.zeros((4, 4), dtype=np.int64)
    with pytest.raises(EnvError, match=r"call: shard 0 \(worlds 0..1\): AttributeError"):
        env.call_shards("no_such_attribute")
    assert env.call_shards("num_envs") == [2, 2]
    env.step(zero)
    env._procs[0].kill()
    env._procs[0].join()
    with pytest.raises(EnvError, match=r"shard 1 \(worlds 2..3\): the worker process exited"):
        env.step(zero)
    with pytest.raises(EnvError, match="failed earlier"):
        env.step(zero)
    procs = list(env._procs)
    env.close()
    env.close()
    assert not any(p.is_alive() for p in procs)
    with pytest.raises(EnvError, match="closed"):
        env.step(zero)


def test_copy_false_returns_the_shared_arrays():
    """``copy=False``: the observations are views of one set of shared arrays, overwritten by
    the next step; ``copy=True`` gives arrays of their own."""
    env = vector_env("practice", mode="motion", num_envs=2, processes=2, copy=False)
    try:
        first, _ = env.reset(seed=0)
        second, *_ = env.step(np.zeros((2, 4), dtype=np.int64))
        assert np.shares_memory(first["fov"], second["fov"])
        env.copy = True
        third, *_ = env.step(np.zeros((2, 4), dtype=np.int64))
        assert not np.shares_memory(third["fov"], second["fov"])
    finally:
        env.close()


def test_merge_infos_fills_missing_keys():
    """Per-world values are concatenated; a key some shards lack is filled as Gymnasium fills
    it (0, False, None) for their worlds; any other value is repeated over its shard."""
    parts = [
        {"tick": np.array([1, 2]), "metrics": np.array([None, {"a": 1}], dtype=object),
         "_metrics": np.array([False, True])},
        {"tick": np.array([3]), "note": "x"},
    ]  # fmt: skip
    m = merge_infos(parts, [2, 1])
    assert m["tick"].tolist() == [1, 2, 3]
    assert m["metrics"].tolist() == [None, {"a": 1}, None]
    assert m["_metrics"].tolist() == [False, True, False]
    assert m["note"].tolist() == [None, None, "x"]


def test_make_vec_takes_processes():
    """``gymnasium.make_vec(..., processes=P)`` makes the sharded env, equal step for step to
    ``make_vec`` without it (the batched env)."""
    import gymnasium

    import fcplan.env  # noqa: F401  (registers the ids)

    sc = load_scenario("practice").replace(duration_s=2)
    env = gymnasium.make_vec("fcplan/Task-v0", num_envs=3, scenario=sc, processes=2)
    ref = gymnasium.make_vec("fcplan/Task-v0", num_envs=3, scenario=sc)
    try:
        assert isinstance(env, ShardedVectorEnv) and not isinstance(ref, ShardedVectorEnv)
        assert same_values(env.reset(seed=2), ref.reset(seed=2))
        act = np.full((3, 4), 8)
        for _ in range(3):
            assert same_values(env.step(act), ref.step(act))
    finally:
        env.close()
