"""Tests for fcplan.env.gym_view: Gymnasium's env checker and agreement with the parallel env."""

from __future__ import annotations

import warnings

import numpy as np
from gymnasium.utils.env_checker import check_env

from fcplan.env import gym_env, parallel_env


def test_check_env():
    """The centralised view passes gymnasium.utils.env_checker.check_env."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(gym_env("practice", k=4, max_steps=6), skip_render_check=True)
        check_env(gym_env("open_world_example", k=3, max_steps=4), skip_render_check=True)


def test_joint_action_matches_parallel_env():
    """The joint action gives the same rewards and final metrics as the parallel env."""
    g = gym_env(24, k=5, max_steps=15)
    p = parallel_env(24, k=5, max_steps=15)
    obs, _ = g.reset(seed=3)
    pobs, _ = p.reset(seed=3)
    rng = np.random.default_rng(0)
    done = False
    while not done:
        act = np.array([rng.choice(np.flatnonzero(m)) for m in obs["action_mask"]])
        obs, r, term, done, info = g.step(act)
        pobs, pr, _, _, pinfo = p.step(dict(zip(p.possible_agents, act.tolist(), strict=True)))
        assert r == pr["P1"] and not term
        assert np.array_equal(obs["tasks"][0], pobs["P1"]["tasks"])
    assert info["metrics"] == pinfo["P1"]["metrics"]


def test_unmasked_sample_is_noop():
    """An unmasked sample may pick padding slots: they act as no-ops and are reported."""
    g = gym_env(1, k=8, max_steps=3)
    obs, _ = g.reset(seed=0)
    act = np.where(obs["action_mask"][:, 0] == 0, 0, 8)
    _, _, _, _, info = g.step(act)
    assert info["illegal"].tolist() == (obs["action_mask"][:, 0] == 0).tolist()
