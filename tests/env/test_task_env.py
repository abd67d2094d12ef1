"""Tests for fcplan.env.task: the PettingZoo API suites, seeding and determinism, reward, truncation."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings

import numpy as np
import pytest
from pettingzoo.test import api_test, parallel_api_test
from pettingzoo.utils import parallel_to_aec

from fcplan import compute_all, load_scenario
from fcplan.env import EnvError, aec_env, parallel_env
from fcplan.env.task import TaskEnv

SCENARIOS = ["practice", 1, 24, "open_world_example"]


def _quiet():
    """Silence PettingZoo's style recommendations (Dict observations, agent names)."""
    warnings.simplefilter("ignore")


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_parallel_api(scenario):
    """The task env passes PettingZoo's parallel API test on every scenario family."""
    with warnings.catch_warnings():
        _quiet()
        parallel_api_test(parallel_env(scenario, k=6, max_steps=12), num_cycles=15)


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_aec_api(scenario):
    """The AEC conversion (parallel_to_aec) passes PettingZoo's api_test."""
    with warnings.catch_warnings():
        _quiet()
        api_test(parallel_to_aec(parallel_env(scenario, k=6, max_steps=12)), num_cycles=15)
        api_test(aec_env(scenario, k=3, max_steps=4), num_cycles=6)


def _rollout(scenario, seed, steps, k=6):
    """Random legal actions drawn from a generator seeded by ``seed``; all outputs collected."""
    env = parallel_env(scenario, k=k, max_steps=steps)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    out = [obs]
    while env.agents:
        acts = {a: int(rng.choice(np.flatnonzero(obs[a]["action_mask"]))) for a in env.agents}
        obs, rew, term, trunc, infos = env.step(acts)
        out.append((obs, rew, trunc, {a: {k: v for k, v in i.items()} for a, i in infos.items()}))
    out.append(env.state())
    return out


def _equal(a, b):
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and np.array_equal(a, b)
    return a == b


def test_multi_step_determinism_fresh_envs():
    """Two fresh envs with the same seed and actions agree on every observation, reward, info
    and the final metrics over many steps; another seed differs."""
    a = _rollout(24, 3, 25)
    b = _rollout(24, 3, 25)
    assert _equal(a, b)
    assert not _equal(a, _rollout(24, 4, 25))


_ROLLOUT = """
import json, numpy as np
from fcplan.env import parallel_env


def rollout():
    env = parallel_env(1, k=6, max_steps=20)
    obs, _ = env.reset(seed=7)
    rng = np.random.default_rng(7)
    rewards = []
    while env.agents:
        acts = {a: int(rng.choice(np.flatnonzero(obs[a]["action_mask"]))) for a in env.agents}
        obs, rew, term, trunc, infos = env.step(acts)
        rewards.append(rew["P1"])
    tasks = float(obs["A1"]["tasks"].astype(np.float64).sum())
    return {"rewards": rewards, "metrics": infos["P1"]["metrics"], "obs": tasks}
"""


def test_determinism_across_processes():
    """A rollout in a fresh Python process gives bit-identical rewards, observations and metrics."""
    code = _ROLLOUT + "\nprint(json.dumps(rollout()))\n"
    child = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    namespace: dict = {}
    exec(_ROLLOUT, namespace)  # noqa: S102 - our own code, run the same way as in the child
    mine = namespace["rollout"]()
    assert json.loads(json.dumps(mine)) == json.loads(child.stdout)


def test_reset_without_seed_continues_deterministically():
    """reset() after reset(seed=s) follows a sequence fixed by s."""
    e1, e2 = TaskEnv("practice", k=4), TaskEnv("practice", k=4)
    for e in (e1, e2):
        e.reset(seed=5)
    o1, _ = e1.reset()
    o2, _ = e2.reset()
    for _ in range(15):
        o1 = e1.step({})[0]
        o2 = e2.step({})[0]
    assert _equal(o1, o2)


def test_rewards_sum_to_manual_negative_reward():
    """Unshaped rewards over a whole episode sum to minus the manual total negative reward, and
    the final infos carry compute_all(world.trace())."""
    sc = load_scenario("practice").replace(duration_s=30)
    env = TaskEnv(sc, k=4)
    obs, _ = env.reset(seed=0)
    total = 0.0
    steps = 0
    while env.agents:
        obs, rew, term, trunc, infos = env.step({a: 0 for a in env.agents})
        total += rew["A1"]
        steps += 1
        assert not any(term.values())
    assert steps == 30 and all(trunc.values())
    manual = compute_all(env.world.trace())["manual"]
    assert infos["P1"]["metrics"]["manual"] == manual.as_dict()
    assert total == pytest.approx(-manual.total_negative_reward, rel=1e-12)
    assert infos["P1"]["return"] == pytest.approx(total)


def test_same_fire_as_run_episode_seed():
    """reset(seed=s) with only no-ops reproduces an idle run_episode with seed s exactly."""
    from fcplan import run_episode

    sc = load_scenario(1).replace(duration_s=20)
    env = TaskEnv(sc, k=4)
    env.reset(seed=2)
    while env.agents:
        _, _, _, _, infos = env.step({})
    ref = run_episode(sc, "idle", seed=2)
    assert infos["A1"]["metrics"]["manual"] == ref.metrics["manual"].as_dict()


def test_illegal_actions():
    """A masked-out action is the no-op (reported) by default and an EnvError on request."""
    env = TaskEnv(1, k=6)
    obs, _ = env.reset(seed=0)
    bad = int(np.flatnonzero(obs["A1"]["action_mask"] == 0)[0])
    _, _, _, _, infos = env.step({"A1": bad})
    assert infos["A1"]["illegal"] and infos["A1"]["task"] is None
    strict = TaskEnv(1, k=6, illegal_action="raise")
    strict.reset(seed=0)
    with pytest.raises(EnvError, match="agent A1: action"):
        strict.step({"A1": bad})
    with pytest.raises(EnvError, match="agent P1"):
        strict.step({"P1": 99})


def test_conflicts_resolved_by_arrival():
    """Two agents of one role choosing one task: the first to arrive keeps it, the other holds
    course (reported as a conflict); agents of different roles may share a task."""
    env = TaskEnv(1, k=8)
    env.reset(seed=0)
    c, g = env.candidates, env.graph
    p1, p2 = g.agent_index["P1"], g.agent_index["P2"]
    shared = np.intersect1d(c.rows[p1][c.valid[p1]], c.rows[p2][c.valid[p2]])
    t = int(shared[0])
    s1, s2 = int(np.flatnonzero(c.rows[p1] == t)[0]), int(np.flatnonzero(c.rows[p2] == t)[0])
    first = (
        "P1"
        if c.start_distance[p1, t] / g.agent_speed[p1]
        <= (c.start_distance[p2, t] / g.agent_speed[p2])
        else "P2"
    )
    _, _, _, _, infos = env.step({"P1": s1, "P2": s2})
    loser = "P2" if first == "P1" else "P1"
    assert infos[first]["task"] == g.task_ids[t] and not infos[first]["conflict"]
    assert infos[loser]["conflict"] and infos[loser]["task"] is None


def test_state_and_spaces():
    """state() lies in state_space; observations lie in their spaces."""
    env = TaskEnv("open_world_example", k=5)
    obs, _ = env.reset(seed=1)
    for _ in range(5):
        obs = env.step({a: 0 for a in env.agents})[0]
    assert env.state_space.contains(env.state())
    for a in env.agents:
        assert env.observation_space(a).contains(obs[a])


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"k": 0}, "k"),
        ({"replan_period": 0}, "replan_period"),
        ({"replan_period": float("inf")}, "^replan_period: must be a finite number > 0"),
        ({"replan_period": "1"}, "^replan_period: must be a finite number > 0"),
        ({"max_steps": -1}, "max_steps"),
        ({"illegal_action": "x"}, "illegal_action"),
        ({"render_mode": "human"}, "render_mode"),
    ],
)
def test_bad_arguments(kwargs, field):
    """Bad arguments raise EnvError naming the argument."""
    with pytest.raises(EnvError, match=field):
        TaskEnv("practice", **kwargs)


def test_bad_mode():
    """An unknown mode names the allowed ones."""
    with pytest.raises(EnvError, match="task, motion"):
        parallel_env("practice", mode="tasks")


def test_render_rgb_array():
    """render_mode="rgb_array" gives an (H, W, 3) uint8 image that changes as the episode runs;
    without a render mode render() returns None."""
    from fcplan.env import gym_env

    env = TaskEnv(24, k=4, render_mode="rgb_array")
    env.reset(seed=0)
    first = env.render()
    for _ in range(30):
        env.step({a: 0 for a in env.agents})
    later = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert first.shape == later.shape and not np.array_equal(first, later)
    assert TaskEnv(24, k=4).render() is None
    g = gym_env(24, k=4, render_mode="rgb_array")
    g.reset(seed=0)
    assert g.render().shape == first.shape


def test_validate_catches_a_plan_the_mask_should_have_prevented(monkeypatch):
    """With validate=True a chosen task that is not legal for its agent (a decoding bug) raises
    validate_plan's PlanError naming the agent; validate=False skips the check."""
    import fcplan.env.task as task_mod
    from fcplan.errors import PlanError

    env = TaskEnv(1, k=4)
    env.reset(seed=0)
    i = int(np.flatnonzero(~env.graph.agent_can_sense)[0])
    search = int(np.flatnonzero(env.graph.task_kind == 1)[0])  # no camera: never legal
    agent = env.possible_agents[i]

    def broken(graph, cand, act, illegal="noop"):
        rows = np.full(graph.n_agents, -1, dtype=np.int64)
        rows[i] = search
        no = np.zeros(graph.n_agents, dtype=bool)
        return rows, no, no.copy()

    monkeypatch.setattr(task_mod, "decode_actions", broken)
    with pytest.raises(PlanError, match=f"agent {agent}: cannot serve search task"):
        env.step({})
    loose = TaskEnv(1, k=4, validate=False)
    loose.reset(seed=0)
    loose.step({})
