"""Tests of fcplan.env.vector_motion: world ``i`` of the batched motion env is, observation for
observation, reward for reward and episode for episode, the single env ``fcplan/Motion-v0`` with
seed ``s + i`` (what Gymnasium's SyncVectorEnv of it gives), in every autoreset mode; and the
batched env passes the checks Gymnasium offers for vector envs."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_match import check_environments_match

import fcplan.env  # noqa: F401  (registers the ids)
from fcplan.env import vector_env
from fcplan.env.joint_gym import JointGymEnv
from fcplan.env.motion import MotionEnv
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from tests._fast.bits import bits


def _actions(rng, masks, n_actions):
    """Random actions, mostly legal (by the masks), some masked ones (executed as stay)."""
    b, n, _ = masks.shape
    act = np.zeros((b, n), dtype=np.int64)
    for i in range(b):
        for j in range(n):
            legal = np.flatnonzero(masks[i, j]) if rng.random() < 0.9 else np.arange(n_actions[j])
            act[i, j] = rng.choice(legal)
    return act


def _same_obs(obs, i, single):
    return all(bits(obs[k][i]) == bits(single[k]) for k in single)


def compare(scenario, num, steps, mode="next_step", seed=10):
    """Step the batched env and ``num`` single envs with the same actions; assert equality."""
    venv = VectorMotionEnv(scenario, num, autoreset_mode=mode)
    singles = [JointGymEnv(scenario) for _ in range(num)]
    obs, _ = venv.reset(seed=seed)
    sobs = [e.reset(seed=seed + i)[0] for i, e in enumerate(singles)]
    rng = np.random.default_rng(seed)
    ended = np.zeros(num, dtype=bool)
    for t in range(steps):
        for i in range(num):
            assert _same_obs(obs, i, sobs[i]), f"observation of world {i} at step {t}"
        act = _actions(rng, obs["action_mask"], venv.views.n_actions)
        obs, rew, term, trunc, info = venv.step(act)
        for i, e in enumerate(singles):
            if ended[i] and mode == "next_step":
                sobs[i], _ = e.reset()
                sr, st = 0.0, False
            else:
                sobs[i], sr, _, st, sinfo = e.step(act[i])
                if st:
                    assert info["metrics"][i] == sinfo["metrics"]
                    if mode == "same_step":
                        final = info["final_obs"][i]
                        assert all(bits(final[k]) == bits(sobs[i][k]) for k in final)
                        sobs[i], _ = e.reset()
            assert rew[i] == sr and trunc[i] == st and not term[i], f"world {i} at step {t}"
        ended = trunc.copy()


@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
@pytest.mark.parametrize("num", [1, 7])
def test_equals_single_envs(name, num):
    """Random (partly masked) actions over two and a half short episodes (autoresets at the
    next step)."""
    sc = load_scenario(name).replace(duration_s=4)
    compare(sc, num, 100)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
def test_equals_single_envs_64(name):
    """64 worlds over a whole episode and the first steps of the next."""
    sc = load_scenario(name)
    compare(sc, 64, sc.n_ticks + 20)


def test_same_step_autoreset():
    """``same_step``: the final observation and metrics go into the infos, the reset observation
    is returned at once."""
    compare(load_scenario(24).replace(duration_s=3), 3, 70, mode="same_step")


def test_disabled_autoreset_holds_worlds():
    """``disabled``: a finished world is held (reward 0, not stepped) until it is reset by mask,
    which starts its next seed, as the single env's ``reset()``."""
    sc = load_scenario("practice").replace(duration_s=1)
    env = VectorMotionEnv(sc, 2, autoreset_mode="disabled")
    obs, _ = env.reset(seed=[4, 9])
    zero = np.zeros((2, 4), dtype=np.int64)
    for _ in range(sc.n_ticks):
        obs, rew, term, trunc, info = env.step(zero)
    assert trunc.all() and "metrics" in info
    held, rew, _, trunc, _ = env.step(zero)
    assert not trunc.any() and (rew == 0).all()
    assert all(bits(held[k]) == bits(obs[k]) for k in obs)
    obs, _ = env.reset(options={"reset_mask": np.array([False, True])})
    single = JointGymEnv(sc)
    single.reset(seed=9)
    for _ in range(sc.n_ticks):
        single.step(zero[0])
    ref, _ = single.reset()
    assert _same_obs(obs, 1, ref)


def test_make_vec_and_gymnasium_checks():
    """``make_vec`` builds the batched env; it matches Gymnasium's SyncVectorEnv of the single
    env (``check_environments_match``); observations lie in the observation space."""
    sc = load_scenario(1).replace(duration_s=3)
    env = gymnasium.make_vec("fcplan/Motion-v0", num_envs=3, scenario=sc)
    assert isinstance(env, VectorMotionEnv)
    sync = gymnasium.make_vec(
        "fcplan/Motion-v0", num_envs=3, scenario=sc, vectorization_mode="sync"
    )
    # (Gymnasium's matcher reads the episode-end flags as single booleans: one world)
    one = gymnasium.make_vec("fcplan/Motion-v0", num_envs=1, scenario=sc)
    one_sync = gymnasium.make_vec("fcplan/Motion-v0", 1, "sync", scenario=sc)
    check_environments_match(one, one_sync, num_steps=70, seed=3, info_comparison="skip")
    env.reset(seed=5)
    sync.reset(seed=5)
    for _ in range(35):
        act = env.action_space.sample()
        a, b = env.step(act), sync.step(act)
        for k in (1, 2, 3):
            assert bits(a[k]) == bits(np.asarray(b[k], dtype=a[k].dtype))
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    assert env.single_observation_space == sync.single_observation_space


def test_state_equals_single_state():
    """``state()`` of every world equals the single env's global state."""
    sc = load_scenario(24).replace(duration_s=5)
    venv = vector_env(sc, "motion", num_envs=2)
    venv.reset(seed=[1, 2])
    singles = [MotionEnv(sc) for _ in range(2)]
    for s, e in zip([1, 2], singles, strict=True):
        e.reset(seed=s)
    rng = np.random.default_rng(0)
    for _ in range(40):
        act = rng.integers(0, 6, (2, 4))
        venv.step(act)
        for i, e in enumerate(singles):
            e.step(dict(zip(e.possible_agents, act[i].tolist(), strict=True)))
    state = venv.state()
    for i, e in enumerate(singles):
        assert bits(state[i]) == bits(e.state())


def test_errors():
    """Bad options and actions give one-line errors naming the field and the allowed range."""
    with pytest.raises(EnvError, match="autoreset_mode"):
        VectorMotionEnv("practice", 2, autoreset_mode="never")
    with pytest.raises(EnvError, match="num_envs"):
        VectorMotionEnv("practice", 0)
    with pytest.raises(EnvError, match="view"):
        VectorMotionEnv("practice", 1, view=4)
    with pytest.raises(EnvError, match="reward_fn"):
        VectorMotionEnv("practice", 1, reward_fn=object())
    with pytest.raises(EnvError, match="mode"):
        vector_env("practice", mode="grid")
    env = VectorMotionEnv("practice", 2)
    with pytest.raises(EnvError, match="reset"):
        env.step(np.zeros((2, 4), dtype=np.int64))
    env.reset(seed=0)
    with pytest.raises(EnvError, match=r"actions\[1, 2\] \(A1\): must be an integer in 0..5"):
        env.step(np.array([[0, 0, 0, 0], [0, 0, 6, 0]]))
    with pytest.raises(EnvError, match="shape"):
        env.step(np.zeros(3, dtype=np.int64))
