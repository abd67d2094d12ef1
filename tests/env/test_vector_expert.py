"""fcplan.env.vector_expert: world ``b``'s actions are the single PlanFollower's on world ``b``."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env.motion import MotionEnv
from fcplan.env.motion_expert import PlanFollower
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from fcplan.taskgraph import TaskGraphParams


def _singles(sc, seeds, **kw):
    envs = [MotionEnv(sc) for _ in seeds]
    experts = [PlanFollower(e, "greedy", **kw) for e in envs]
    obs = []
    for env, ex, s in zip(envs, experts, seeds, strict=True):
        o, _ = env.reset(seed=s)
        ex.reset()
        obs.append(o)
    return envs, experts, obs


def _single_actions(experts, obs, ids):
    """The single followers' actions of one tick, one call each, as a (B, N) array."""
    chosen = [ex.actions(o) for ex, o in zip(experts, obs, strict=True)]
    return np.array([[c[a] for a in ids] for c in chosen])


@pytest.mark.parametrize("name", ["practice", "open_world_example"])
def test_every_world_follows_as_the_single_follower_through_resets(name):
    """Three worlds with greedy plans: every tick, world ``b``'s actions equal the single
    follower's on the single env of seed ``b``, through a whole episode, the env's next-step
    autoreset into a second episode (the single env reset without a seed), and a reset of one
    world alone mid-episode with a new seed (worlds resetting at different ticks); the plans
    made are counted per world (perception, action and hybrid agents on the open world)."""
    sc = load_scenario(name).replace(duration_s=12)
    venv = VectorMotionEnv(sc, 3)
    expert = BatchPlanFollower(venv, "greedy")
    ids = venv.agent_ids
    obs_b, _ = venv.reset(seed=0)
    envs, experts, obs_s = _singles(sc, [0, 1, 2])

    def play(steps):
        nonlocal obs_b
        for _ in range(steps):
            act = expert.actions(obs_b)
            assert np.array_equal(act, _single_actions(experts, obs_s, ids))
            obs_b, *_ = venv.step(act)
            for i, env in enumerate(envs):
                obs_s[i], *_ = env.step(dict(zip(ids, act[i].tolist(), strict=True)))

    play(sc.n_ticks)
    assert expert.replans.tolist() == [ex.replans for ex in experts]
    assert not any(env.agents for env in envs)
    obs_b, *_ = venv.step(expert.actions(obs_b))  # (the autoreset step)
    for i, (env, ex) in enumerate(zip(envs, experts, strict=True)):
        obs_s[i], _ = env.reset()
        ex.reset()
    play(40)
    obs_b, _ = venv.reset(seed=[9], options={"reset_mask": np.array([False, True, False])})
    obs_s[1], _ = envs[1].reset(seed=9)
    experts[1].reset()
    play(50)
    assert expert.replans.tolist() == [ex.replans for ex in experts]


def test_graph_params_reach_the_graphs_of_both_followers():
    """``graph_params`` is honoured: with 200-px search blocks the single and the batched
    followers plan on graphs of 36 search tasks (the defaults give 144), and act alike."""
    sc = load_scenario("practice").replace(duration_s=5)
    params = TaskGraphParams(search_block_px=200)
    envs, experts, obs_s = _singles(sc, [4], graph_params=params)
    venv = VectorMotionEnv(sc, 1)
    expert = BatchPlanFollower(venv, "greedy", graph_params=params)
    obs_b, _ = venv.reset(seed=4)
    ids = venv.agent_ids
    for _ in range(sc.n_ticks):
        act = expert.actions(obs_b)
        assert np.array_equal(act, _single_actions(experts, obs_s, ids))
        obs_b, *_ = venv.step(act)
        obs_s[0], *_ = envs[0].step(dict(zip(ids, act[0].tolist(), strict=True)))
    assert experts[0].mission.graph.search_tasks.size == 36
    assert expert.plans[0] is not None and expert.replans[0] == experts[0].replans


def test_bad_arguments_are_named():
    """A wrong env, a shared instance without plan_batch, a wrong count of schedulers or a bad
    period is an EnvError naming the argument; so is asking for actions before the env's first
    reset."""
    venv = VectorMotionEnv("practice", 2)
    with pytest.raises(EnvError, match="reset the env first"):
        BatchPlanFollower(venv, "greedy").actions({})
    from fcplan.scheduling import make_scheduler

    for kwargs, word in [
        ({"scheduler": make_scheduler("routing")}, "one instance per world"),
        ({"scheduler": [make_scheduler("greedy")]}, "need 2 schedulers"),
        ({"scheduler": "greedy", "replan_period": 0}, "replan_period"),
        ({"scheduler": "greedy", "replan_period": float("inf")}, "^replan_period: must be a fin"),
        ({"scheduler": "greedy", "replan_period": "1"}, "^replan_period: must be a fin"),
    ]:
        with pytest.raises(EnvError, match=word):
            BatchPlanFollower(venv, **kwargs)
    with pytest.raises(EnvError, match="VectorMotionEnv"):
        BatchPlanFollower(MotionEnv("practice"), "greedy")  # type: ignore[arg-type]


def test_specs_plan_in_their_deterministic_mode():
    """A spec given to either follower runs in the scheduler's deterministic mode unless it
    sets the mode (cbba: ``deterministic`` True on every instance, False when the spec says
    so); an instance is used as it was built."""
    from solvers.cbba import CBBAScheduler

    sc = load_scenario("practice").replace(duration_s=2)
    assert PlanFollower(MotionEnv(sc), "cbba").scheduler.deterministic is True
    off = PlanFollower(MotionEnv(sc), "cbba:deterministic=false").scheduler
    assert off.deterministic is False
    batch = BatchPlanFollower(VectorMotionEnv(sc, 2), "cbba")
    assert [s.deterministic for s in batch.schedulers] == [True, True]
    mine = CBBAScheduler()
    assert PlanFollower(MotionEnv(sc), mine).scheduler is mine and not mine.deterministic
