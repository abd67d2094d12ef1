"""Tests of fcplan.env.vector_base: the batched envs take ``reset``'s seeds by Gymnasium's rule
(an int ``s`` seeds world ``b`` with ``s + b`` also when a reset mask picks the worlds; a list
has one seed per world), so a masked reset restarts the same episodes as Gymnasium's
SyncVectorEnv of the single env."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import fcplan.env  # noqa: F401  (registers the ids)
from fcplan.env.gym_view import TaskGymEnv
from fcplan.env.joint_gym import JointGymEnv
from fcplan.env.vector_base import reset_seeds
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from tests._fast.bits import bits


def test_reset_seeds_follow_gymnasium():
    """An int gives world ``b`` the seed ``s + b`` whichever worlds are reset; a list of one
    seed per world gives each reset world its own; a list of one per reset world goes in order;
    None continues every world's seeds; any other length is an error naming both counts."""
    rows = np.array([1, 3])
    assert reset_seeds(4, rows, 10) == [11, 13]
    assert reset_seeds(4, rows, np.int64(10)) == [11, 13]
    assert reset_seeds(4, rows, [5, 6, 7, 8]) == [6, 8]
    assert reset_seeds(4, rows, [70, 80]) == [70, 80]
    assert reset_seeds(4, rows, None) == [None, None]
    assert reset_seeds(3, np.arange(3), 0) == [0, 1, 2]
    with pytest.raises(EnvError, match="need 4 seeds, one per world .or 2, one per world reset"):
        reset_seeds(4, rows, [1, 2, 3])


_LEVELS = {
    "motion": (VectorMotionEnv, JointGymEnv, "fcplan/Motion-v0"),
    "task": (VectorTaskEnv, TaskGymEnv, "fcplan/Task-v1"),
}


@pytest.mark.parametrize("level", sorted(_LEVELS))
@pytest.mark.parametrize("seed", [5, [20, 21, 22]])
def test_masked_reset_matches_sync_vector_env(level, seed):
    """After a full reset, ``reset(seed=..., options={"reset_mask": m})`` restarts the masked
    worlds on the seeds Gymnasium's SyncVectorEnv gives them (world 1 of 3: ``s + 1``, or the
    list's second seed: the same fire, so the same rewards, step for step) and leaves the
    others' observations as they were."""
    batched, single, env_id = _LEVELS[level]
    sc = load_scenario("practice").replace(duration_s=5)
    venv = batched(sc, 3, autoreset_mode="disabled")
    sync = gymnasium.make_vec(
        env_id, num_envs=3, scenario=sc, vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": gymnasium.vector.AutoresetMode.DISABLED},
    )  # fmt: skip
    first, _ = venv.reset(seed=0)
    sync.reset(seed=0)
    mask = np.array([False, True, False])
    obs, _ = venv.reset(seed=seed, options={"reset_mask": mask})
    ref, _ = sync.reset(seed=seed, options={"reset_mask": mask})
    assert all(bits(obs[k][[0, 2]]) == bits(first[k][[0, 2]]) for k in obs)
    alone = single(sc)
    alone.reset(seed=6 if seed == 5 else 21)
    nvec = np.tile(venv.single_action_space.nvec, (3, 1))
    noop = nvec - 1 if level == "task" else np.zeros_like(nvec)  # (hold course; stay)
    steps = 30 if level == "motion" else 3
    for t in range(steps):
        for k in obs:
            assert bits(obs[k]) == bits(ref[k]), (t, k)
        obs, rew, _, _, _ = venv.step(noop)
        ref, ref_rew, _, _, _ = sync.step(noop)
        _, one_rew, *_ = alone.step(noop[1])
        assert bits(rew) == bits(ref_rew) and rew[1] == one_rew, t
