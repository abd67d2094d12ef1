"""Tests of fcplan.env.vector_task: world ``i`` of the batched task env is, observation for
observation, reward for reward, info for info and episode for episode, ``fcplan/Task-v0`` with
seed ``s + i`` (its own seed sequence after), in every autoreset mode."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import fcplan.env  # noqa: F401  (registers the ids)
from fcplan.env import vector_env
from fcplan.env.gym_view import TaskGymEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from tests._fast.bits import bits


def compare(sc, num, steps, mode="next_step", seed=10, **kw):
    """Step the batched env and ``num`` single envs with the same (partly masked) actions."""
    venv = VectorTaskEnv(sc, num, autoreset_mode=mode, **kw)
    singles = [TaskGymEnv(sc, **kw) for _ in range(num)]
    obs, _ = venv.reset(seed=seed)
    sobs = [e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]
    rng = np.random.default_rng(seed)
    ended = np.zeros(num, dtype=bool)
    n_act = venv.one.k + 1
    for t in range(steps):
        for i in range(num):
            assert all(bits(obs[k][i]) == bits(sobs[i][k]) for k in sobs[i]), (t, i)
        m = obs["action_mask"]
        act = np.zeros(m.shape[:2], dtype=np.int64)
        for i, j in np.ndindex(*act.shape):
            legal = np.flatnonzero(m[i, j]) if rng.random() < 0.9 else np.arange(n_act)
            act[i, j] = rng.choice(legal)
        obs, rew, term, trunc, info = venv.step(act)
        for i, e in enumerate(singles):
            if ended[i] and mode == "next_step":
                sobs[i], _ = e.reset()
                sr, st = 0.0, False
            else:
                sobs[i], sr, _, st, si = e.step(act[i])
                assert bits(info["illegal"][i]) == bits(si["illegal"])
                assert bits(info["conflict"][i]) == bits(si["conflict"])
                assert info["tick"][i] == si["tick"]
                if st:
                    assert info["metrics"][i] == si["metrics"]
                    assert info["return"][i] == si["return"]
                    if mode == "same_step":
                        assert all(
                            bits(info["final_obs"][i][k]) == bits(sobs[i][k]) for k in sobs[i]
                        )
                        sobs[i], _ = e.reset()
            assert rew[i] == sr and trunc[i] == st and not term[i], (t, i)
        ended = trunc.copy()


@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
@pytest.mark.parametrize("num", [1, 7])
def test_equals_single_envs(name, num):
    """Random (partly masked) actions over more than two short episodes."""
    compare(load_scenario(name).replace(duration_s=6), num, 14, k=5)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
def test_equals_single_envs_64(name):
    """64 worlds over a whole episode and the first steps of the next."""
    sc = load_scenario(name)
    compare(sc, 64, sc.n_ticks // sc.ticks_per_second + 3)


@pytest.mark.parametrize("dump", [None, 60.0])
def test_equals_single_envs_with_the_dump_altitude(dump):
    """``dump_altitude`` (``fcplan/Task-v1``'s None, or metres): the batched env's decoding of
    hybrids sent to fires equals the single env's, on the open world's hybrids."""
    compare(load_scenario("open_world_example").replace(duration_s=8), 5, 16, k=5,
            dump_altitude=dump)  # fmt: skip


def test_v1_rule_flies_hybrids_at_the_top_on_fires():
    """Under ``fcplan/Task-v1`` a hybrid with water sent to a fire is commanded to the top of
    its bounds; under ``fcplan/Task-v0`` to ``watch_altitude``; checked on every such choice of
    a random 30-step open-world episode (at least one)."""
    seen = 0
    for dump, want in ((None, "top"), ("watch", "watch")):
        env = VectorTaskEnv("open_world_example", 1, k=5, dump_altitude=dump)
        obs, _ = env.reset(seed=4)
        rng = np.random.default_rng(4)
        team, one = env.batch.team, env.one
        for _ in range(30):
            m = obs["action_mask"][0]
            act = np.array([[rng.choice(np.flatnonzero(m[j])) for j in range(m.shape[0])]])
            g = env.graphs[0]
            fire_slot = [j < one.k and bool(env._slot_fire[0, i, j]) for i, j in enumerate(act[0])]
            tank = team.tank[0].copy()
            obs, _, _, _, info = env.step(act)
            sent = ~(info["conflict"][0] | info["illegal"][0])
            for i in range(one.n_agents):
                hybrid = g.agent_can_sense[i] and g.agent_can_act[i] and tank[i] > 0
                if sent[i] and fire_slot[i] and hybrid:
                    lo, hi = (float(v) for v in g.agent_alt_range[i])
                    z = hi if want == "top" else min(max(one.watch_altitude, lo), hi)
                    assert team.z_target[0, i] == z
                    seen += 1
    assert seen


def test_other_modes_and_options():
    """Same-step autoreset; ``max_steps`` truncation; a replan period of one tick and shaping."""
    sc = load_scenario(24).replace(duration_s=4)
    compare(sc, 3, 10, mode="same_step")
    compare(sc, 2, 9, max_steps=3)
    compare(sc, 2, 50, replan_period=0.1, prune_bonus=0.5, k=3)


def test_held_worlds_and_make_vec():
    """``disabled``: a finished world is held until reset by mask; ``make_vec`` builds the
    batched env; observations lie in its space."""
    sc = load_scenario("practice").replace(duration_s=2)
    env = gymnasium.make_vec("fcplan/Task-v0", num_envs=2, scenario=sc, autoreset_mode="disabled")
    assert isinstance(env, VectorTaskEnv)
    obs, _ = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    noop = np.full((2, 4), env.one.k)
    for _ in range(2):
        obs, rew, _, trunc, info = env.step(noop)
    assert trunc.all() and set(info) >= {"metrics", "return"}
    held, rew, _, trunc, info = env.step(noop)
    assert not trunc.any() and (rew == 0).all() and (info["tick"] == 20).all()
    obs, _ = env.reset(options={"reset_mask": [True, False]})
    assert env.batch.tick.tolist() == [0, 20]


def test_errors():
    """Bad options and actions give one-line errors."""
    with pytest.raises(EnvError, match="render_mode"):
        vector_env("practice", "task", 2, render_mode="rgb_array")
    with pytest.raises(EnvError, match="k:"):
        vector_env("practice", "task", 2, k=0)
    for bad in (0.0, -1.0, float("nan"), "top", True):
        with pytest.raises(EnvError, match="dump_altitude"):
            vector_env("practice", "task", 2, dump_altitude=bad)
    env = vector_env("practice", "task", 2)
    with pytest.raises(EnvError, match="reset"):
        env.step(np.zeros((2, 4), dtype=np.int64))
    with pytest.raises(EnvError, match="need 2 seeds"):
        env.reset(seed=[1, 2, 3])
    env.reset(seed=0)
    with pytest.raises(EnvError, match="shape"):
        env.step(np.zeros(3, dtype=np.int64))
