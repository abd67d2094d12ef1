"""Gymnasium registration of the single-agent views: every id makes an env that passes
Gymnasium's checker, with its spec, in both render modes."""

from __future__ import annotations

import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import fcplan.env
from fcplan.env.registration import ENV_IDS

# small settings per id so that the checker's episodes stay short
SMALL = {
    "fcplan/Task-v0": {"k": 4, "max_steps": 6},
    "fcplan/Task-v1": {"k": 4, "max_steps": 6},
    "fcplan/Motion-v0": {"render_size": 96},
    "fcplan/MotionBase-v0": {"max_steps": 20},
    "fcplan/MotionCmplx1-v0": {"max_steps": 20},
    "fcplan/MotionCmplx2-v0": {"max_steps": 20},
}


def test_every_id_is_registered():
    """Importing fcplan.env registers every id of ENV_IDS, each with the version its name
    ends with."""
    assert set(SMALL) == set(ENV_IDS)
    for env_id in ENV_IDS:
        spec = gymnasium.spec(env_id)
        assert spec.namespace == "fcplan" and spec.version == int(env_id.rsplit("-v", 1)[1])


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_check_env_rgb_array(env_id, monkeypatch):
    """gymnasium.make(id, render_mode="rgb_array") sets spec and passes check_env, render
    check included (which also makes the id with every declared mode, "human" too, headless);
    the frame is an (H, W, 3) uint8 image."""
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    env = gymnasium.make(env_id, render_mode="rgb_array", **SMALL[env_id])
    assert env.spec is not None and env.spec.id == env_id
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check_env(env.unwrapped, skip_render_check=False)
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    env.close()


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_same_seed_same_episode(env_id):
    """Two envs made from one id give identical observations and rewards for one seed and
    one action sequence."""
    runs = []
    for _ in range(2):
        env = gymnasium.make(env_id, **SMALL[env_id])
        obs, _ = env.reset(seed=5)
        env.action_space.seed(1)
        trace = [obs]
        for _ in range(4):
            obs, r, term, trunc, _ = env.step(env.action_space.sample())
            trace += [obs, r]
            if term or trunc:
                break
        runs.append(trace)
    for x, y in zip(*runs, strict=True):
        if isinstance(x, dict):
            assert all(np.array_equal(x[k], y[k]) for k in x)
        else:
            assert x == y


def test_scenario_and_options_pass_through():
    """Keyword arguments of make reach the env: the scenario, k, a preset's reward."""
    env = gymnasium.make("fcplan/Task-v0", scenario=24, k=3, max_steps=2)
    assert env.unwrapped.env.scenario.name == fcplan.load_scenario(24).name
    assert env.unwrapped.action_space.nvec.tolist() == [4] * env.unwrapped.env.n_agents
    base = gymnasium.make("fcplan/MotionBase-v0", reward="rf1")
    assert base.unwrapped.env.reward_name == "rf1"


def test_make_with_module_prefix_after_importing_gymnasium_alone():
    """gymnasium.make("fcplan.env:fcplan/Task-v0") works in a process that imported only
    gymnasium (Gymnasium 1.x reads no plugin entry points)."""
    code = (
        "import gymnasium\n"
        "env = gymnasium.make('fcplan.env:fcplan/Task-v0', k=2, max_steps=1)\n"
        "print(env.spec.id)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "fcplan/Task-v0"
