"""fcplan.env.vector_shard_experts: the experts of a sharded env give, world for world, the
one-process experts' actions (motion and task level, through episode ends and resets); bad
input is refused with an EnvError and leaves the env usable."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env import vector_env
from fcplan.env.task_actions import MappingCounts
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_shard_experts import ShardedPlanFollower, ShardedTaskExpert
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from fcplan.scheduling import make_scheduler


def test_motion_follower_equals_the_one_process_follower():
    """5 worlds in 2 processes with greedy plans: every tick's actions, the plans made per world
    and the last plans' routes equal BatchPlanFollower's on one batched env of the same 5 worlds,
    through the next-step autoreset of every world and a reset of two worlds alone (one per
    shard) mid-episode."""
    sc = load_scenario("practice").replace(duration_s=6)
    ref = vector_env(sc, mode="motion", num_envs=5)
    env = vector_env(sc, mode="motion", num_envs=5, processes=2)
    try:
        mine, theirs = ShardedPlanFollower(env, "greedy"), BatchPlanFollower(ref, "greedy")
        obs, want = env.reset(seed=3)[0], ref.reset(seed=3)[0]
        ended = 0
        for t in range(int(sc.n_ticks * 1.5)):
            act = mine.actions(obs)
            np.testing.assert_array_equal(act, theirs.actions(want), strict=True, err_msg=str(t))
            obs, _, _, truncs, _ = env.step(act)
            want, _, _, want_truncs, _ = ref.step(act)
            ended += int(truncs.all())
            np.testing.assert_array_equal(truncs, want_truncs)
            if t == sc.n_ticks + 10:
                mask = np.isin(np.arange(5), [1, 4])
                obs = env.reset(seed=[7, 8], options={"reset_mask": mask})[0]
                want = ref.reset(seed=[7, 8], options={"reset_mask": mask})[0]
        assert ended == 1
        np.testing.assert_array_equal(mine.replans, theirs.replans, strict=True)
        assert mine.replans.min() > 0
        routes = [dict(p.routes) if p else None for p in mine.plans]
        assert routes == [dict(p.routes) if p else None for p in theirs.plans]
        mine.reset([0, 3])
        assert mine.replans.tolist()[0] == 0 and mine.replans.tolist()[3] == 0
        mine.close()
        with pytest.raises(EnvError, match="closed"):
            mine.actions(obs)
    finally:
        env.close()


@pytest.mark.parametrize("per_world", [False, True])
def test_task_expert_equals_the_one_process_expert(per_world):
    """5 task-level worlds in 3 processes: each step's expert actions, fallback flags and the
    mapping counts (one for all worlds, or one per world) equal VectorTaskEnv.expert_actions on
    one batched env, with one greedy instance for every world or one per world, through an
    episode end and its autoreset."""
    sc = load_scenario("practice").replace(duration_s=4)
    ref = vector_env(sc, mode="task", num_envs=5, k=4)
    env = vector_env(sc, mode="task", num_envs=5, processes=3, k=4)
    try:

        def scheds():
            return (
                [make_scheduler("greedy") for _ in range(5)]
                if per_world
                else make_scheduler("greedy")
            )

        expert = ShardedTaskExpert(env, scheds())
        ref_scheds = scheds()
        env.reset(seed=0)
        ref.reset(seed=0)
        ended = 0
        for t in range(12):
            c_mine = [MappingCounts() for _ in range(5)] if per_world else MappingCounts()
            c_ref = [MappingCounts() for _ in range(5)] if per_world else MappingCounts()
            act, fb = expert.actions(counts=c_mine)
            want, want_fb = ref.expert_actions(ref_scheds, counts=c_ref)
            np.testing.assert_array_equal(act, want, strict=True, err_msg=str(t))
            np.testing.assert_array_equal(fb, want_fb, strict=True)
            assert c_mine == c_ref and sum((c_mine if per_world else [c_mine])[0].values()) > 0
            truncs = env.step(act)[3]
            np.testing.assert_array_equal(truncs, ref.step(act)[3])
            ended += int(truncs.all())
        assert ended >= 1
        act, _ = expert.actions()  # (no counts)
        np.testing.assert_array_equal(act, ref.expert_actions(ref_scheds)[0])
    finally:
        env.close()


def test_bad_input_is_refused_and_the_env_goes_on():
    """A one-process env, the wrong level, a per-world list of the wrong length, and a shared
    instance without plan_batch (refused by every shard's follower) raise an EnvError naming
    the problem; the env still steps afterwards, and closing an expert twice is harmless."""
    sc = load_scenario("practice").replace(duration_s=3)
    env = vector_env(sc, mode="motion", num_envs=4, processes=2)
    try:
        with pytest.raises(EnvError, match="ShardedVectorEnv"):
            ShardedPlanFollower(vector_env(sc, mode="motion", num_envs=2), "greedy")
        with pytest.raises(EnvError, match="task-level env"):
            ShardedTaskExpert(env, make_scheduler("greedy"))
        with pytest.raises(EnvError, match="need 4, one per world"):
            ShardedPlanFollower(env, [make_scheduler("greedy")] * 3)
        with pytest.raises(EnvError, match="plan_batch"):
            ShardedPlanFollower(env, make_scheduler("routing"))
        obs = env.reset(seed=0)[0]
        expert = ShardedPlanFollower(env, "greedy")
        env.step(expert.actions(obs))
        expert.close()
        expert.close()
        assert env.local._started
    finally:
        env.close()


def _keys(env, kept):
    """The keys a shard keeps (run in every shard)."""
    return sorted(kept)


def test_an_expert_lives_in_the_shards_as_long_as_its_object():
    """Every shard keeps an expert while its object lives; close() or the object's collection
    drops it from every shard, and closing twice, or after the env, is harmless."""
    import gc

    sc = load_scenario("practice").replace(duration_s=3)
    env = vector_env(sc, mode="motion", num_envs=4, processes=2)
    try:
        a, b = ShardedPlanFollower(env, "greedy"), ShardedPlanFollower(env, "greedy")
        assert env.apply_shards(_keys, [()] * 2) == [sorted([a.key, b.key])] * 2
        a.close()
        a.close()
        assert env.apply_shards(_keys, [()] * 2) == [[b.key]] * 2
        del b
        gc.collect()
        assert env.apply_shards(_keys, [()] * 2) == [[]] * 2
        c = ShardedPlanFollower(env, "greedy")
    finally:
        env.close()
    c.close()
