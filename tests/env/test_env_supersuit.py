"""SuperSuit's vector wrappers on both levels (pettingzoo_env_to_vec_env_v1, then
concat_vec_envs_v1 with the Gymnasium base class)."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env import parallel_env
from tests.conftest import scenario_with

pytest.importorskip("supersuit")
from supersuit import concat_vec_envs_v1, pettingzoo_env_to_vec_env_v1  # noqa: E402


def _vec(env, copies=2):
    vec = pettingzoo_env_to_vec_env_v1(env)
    return concat_vec_envs_v1(vec, copies, num_cpus=0, base_class="gymnasium")


def _roll(venv, steps, seed):
    """Masked random actions for ``steps`` vector steps; returns the rewards and the number
    of finished episodes."""
    obs, _ = venv.reset(seed=seed)
    rng = np.random.default_rng(seed)
    rewards, done = [], 0
    for _ in range(steps):
        act = np.array([rng.choice(np.flatnonzero(m)) for m in obs["action_mask"]])
        obs, rew, term, trunc, _ = venv.step(act)
        rewards.append(rew.copy())
        done += int(np.sum(term | trunc))
        assert all(v.shape[0] == venv.num_envs for v in obs.values())
    return np.array(rewards), done


@pytest.mark.parametrize("options", [{}, {"obs_layout": "flat"}])
def test_task_level_vectorises(options):
    """The task level (equal spaces already) runs through both wrappers; an agent per vector
    slot; episodes auto-reset; two runs with one seed agree."""
    env = parallel_env(24, k=4, max_steps=3, **options)
    venv = _vec(env)
    assert venv.num_envs == 2 * len(env.possible_agents)
    r1, done = _roll(venv, 7, seed=0)
    assert done == 2 * venv.num_envs  # two episodes of 3 steps ended in every slot
    r2, _ = _roll(_vec(parallel_env(24, k=4, max_steps=3, **options)), 7, seed=0)
    assert np.array_equal(r1, r2)
    venv.close()


@pytest.mark.parametrize(
    "scenario, layout",
    [("practice", "dict"), ("practice", "flat"), ("base", "flat"), ("cmplx1", "dict")],
)
def test_motion_level_vectorises_with_padded_actions(scenario, layout):
    """The motion level (Discrete(7) vs Discrete(6)) is refused as is, and runs through both
    wrappers with pad_actions=True: one Discrete(n_max), masks padded with 0."""
    if scenario == "practice":
        scenario = scenario_with("practice", duration_s=1.0)
    with pytest.raises(AssertionError, match="spaces not consistent"):
        pettingzoo_env_to_vec_env_v1(parallel_env(scenario, mode="motion"))
    env = parallel_env(scenario, mode="motion", pad_actions=True, obs_layout=layout)
    venv = _vec(env)
    rewards, _ = _roll(venv, 12, seed=3)
    assert rewards.shape == (12, venv.num_envs) and np.isfinite(rewards).all()
    venv.close()
