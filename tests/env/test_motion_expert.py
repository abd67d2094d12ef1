"""Tests for fcplan.env.motion_expert: a scheduler's plans driving the motion-level env."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env import EnvError
from fcplan.env.motion import MotionEnv, parallel_env
from fcplan.env.motion_expert import PlanFollower


def _play(scenario, scheduler, seed: int, *, check_masks: bool = False):
    """Play one episode; return (actions per step, final manual metrics, follower)."""
    env = MotionEnv(scenario)
    expert = PlanFollower(env, scheduler)
    obs, _ = env.reset(seed=seed)
    expert.reset()
    taken = []
    while env.agents:
        act = expert.actions(obs)
        if check_masks:
            for a, k in act.items():
                assert obs[a]["action_mask"][k] == 1, (env.world.tick, a, k)
        taken.append(tuple(act[a] for a in env.possible_agents))
        obs, _, _, _, infos = env.step(act)
    return taken, infos[env.possible_agents[0]]["metrics"]["manual"], expert


def test_greedy_expert_beats_idle_and_random_policies():
    """Greedy plans followed move by move put fire out: on #1 the episode scores far above an
    idle team and above uniformly random legal actions."""
    _, greedy, _ = _play(1, "greedy", 0)
    _, idle, _ = _play(1, "idle", 0)
    env = MotionEnv(1)
    rng = np.random.default_rng(0)
    obs, _ = env.reset(seed=0)
    while env.agents:
        act = {a: int(rng.choice(np.flatnonzero(obs[a]["action_mask"]))) for a in env.agents}
        obs, _, _, _, infos = env.step(act)
    rand = infos[env.possible_agents[0]]["metrics"]["manual"]
    assert greedy["final_score"] > idle["final_score"] + 300
    assert greedy["final_score"] > rand["final_score"] + 100
    assert greedy["overall_firefighting"] > 90.0


@pytest.mark.parametrize("scenario", ["practice", "open_world_example"])
def test_expert_actions_are_always_legal(scenario):
    """Every action the follower picks is allowed by the agent's action mask (perception, action
    and hybrid agents, forced returns included)."""
    _play(scenario, "greedy", 1, check_masks=True)


def test_expert_episodes_are_deterministic():
    """The same scenario, scheduler and seed give the same actions at every step and the same
    metrics."""
    a, ma, _ = _play(24, "greedy", 3)
    b, mb, _ = _play(24, "greedy", 3)
    assert a == b
    assert ma == mb


def test_replans_once_per_period():
    """With a 2-s replan period the follower plans once every 20 ticks at 10 Hz."""
    env = MotionEnv("practice")
    expert = PlanFollower(env, "greedy", replan_period=2.0)
    obs, _ = env.reset(seed=0)
    expert.reset()
    for _ in range(100):
        obs, *_ = env.step(expert.actions(obs))
    assert expert.replans == 5
    assert expert.plan is not None and expert.plan.stats is not None


def test_idle_plans_keep_agents_at_the_depot():
    """The idle scheduler's empty routes leave every agent where it started."""
    env = MotionEnv(1)
    expert = PlanFollower(env, "idle")
    obs, _ = env.reset(seed=0)
    expert.reset()
    start = env.world.team.pos.copy()
    for _ in range(50):
        obs, *_ = env.step(expert.actions(obs))
    np.testing.assert_array_equal(env.world.team.pos, start)


def test_bad_arguments_are_refused():
    """Presets (no scenario, no plans) and replan periods that are not finite numbers > 0
    (the mission's check_replan_period) raise EnvError."""
    with pytest.raises(EnvError, match="scenario MotionEnv"):
        PlanFollower(parallel_env(preset="base"), "greedy")
    for bad in (0.0, float("inf"), float("nan"), True, "1"):
        with pytest.raises(EnvError, match="^replan_period: must be a finite number > 0"):
            PlanFollower(MotionEnv("practice"), "greedy", replan_period=bad)
    with pytest.raises(EnvError, match="reset the env first"):
        PlanFollower(MotionEnv("practice"), "greedy").reset()


def test_graph_params_shape_the_graphs_it_plans_on():
    """``graph_params`` reaches the mission's graph builder: 200-px search blocks give the
    practice map 36 search tasks (the default 100-px blocks 144), from the first replan of an
    episode and again after the next reset (it once set the parameters after the builder was
    made, so they were ignored)."""
    from fcplan.taskgraph import TaskGraphParams

    env = MotionEnv("practice")
    expert = PlanFollower(env, "greedy", graph_params=TaskGraphParams(search_block_px=200))
    for seed in (0, 1):
        obs, _ = env.reset(seed=seed)
        expert.reset()
        env.step(expert.actions(obs))
        assert expert.mission is not None and expert.mission.graph is not None
        assert expert.mission.graph.search_tasks.size == 36
    plain = PlanFollower(env, "greedy")
    obs, _ = env.reset(seed=0)
    plain.reset()
    env.step(plain.actions(obs))
    assert plain.mission is not None and plain.mission.graph is not None
    assert plain.mission.graph.search_tasks.size == 144
