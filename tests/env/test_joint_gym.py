"""fcplan.env.joint_gym: the joint observation is the parallel env's, stacked and padded."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from fcplan.env.joint_gym import JointGymEnv
from fcplan.scenario import load_scenario


def _stacked(per: dict[str, Any], ids: list[str]) -> dict[str, np.ndarray]:
    """The plain stacking: ``np.stack`` per field, masks padded with 0 one agent at a time."""
    n_max = max(len(per[a]["action_mask"]) for a in ids)
    mask = np.zeros((len(ids), n_max), dtype=np.int8)
    for i, a in enumerate(ids):
        mask[i, : len(per[a]["action_mask"])] = per[a]["action_mask"]
    return {
        "fov": np.stack([per[a]["fov"] for a in ids]),
        "agent": np.stack([per[a]["agent"] for a in ids]),
        "action_mask": mask,
    }


def _assert_same(obs: dict[str, np.ndarray], want: dict[str, np.ndarray]) -> None:
    assert obs.keys() == want.keys()
    for key, value in want.items():
        assert obs[key].dtype == value.dtype, key
        assert obs[key].shape == value.shape and np.array_equal(obs[key], value), key


@pytest.mark.parametrize("scenario", ["practice", "open_world_example"])
def test_joint_observation_is_the_per_agent_one_stacked_and_padded(scenario):
    """At the reset and every step of an episode of random legal actions (perception, action
    and hybrid agents: 7, 6 and 8 actions), the joint observation equals the plain stacking of
    what the parallel env returned, dtypes and shapes included (the fast path against the
    plain one)."""
    sc = load_scenario(scenario).replace(duration_s=20)
    env = JointGymEnv(sc)
    inner, ids = env.env, env.env.possible_agents
    seen: list[dict[str, Any]] = []
    step, reset = inner.step, inner.reset
    inner.step = lambda a: (out := step(a), seen.append(out[0]))[0]  # type: ignore[method-assign]
    inner.reset = lambda **k: (out := reset(**k), seen.append(out[0]))[0]  # type: ignore[method-assign]
    obs, _ = env.reset(seed=3)
    rng = np.random.default_rng(0)
    for _ in range(sc.n_ticks):
        _assert_same(obs, _stacked(seen[-1], ids))
        m = obs["action_mask"]
        obs, _, term, trunc, _ = env.step((rng.random(m.shape) * m).argmax(axis=1))
    _assert_same(obs, _stacked(seen[-1], ids))
    assert trunc or term
    assert len(seen) == sc.n_ticks + 1
