"""Tests for fcplan.env.reward: the one step reward both environments use, and its injection."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan import World, compute_all, load_scenario
from fcplan.env.motion import MotionEnv
from fcplan.env.reward import PenaltyReward
from fcplan.env.task import TaskEnv
from fcplan.metrics import negative_reward_rate

SHORT = load_scenario(24).replace(duration_s=20)


def test_one_tick_path_equals_the_window_path():
    """The per-tick path (current counts, cached facility sum) gives exactly the reward the
    trace-window path gives for a one-tick window, and windows add up to the manual rate."""
    world = World().reset(SHORT, seed=1)
    fast, window = PenaltyReward(), PenaltyReward()
    fast.reset(world)
    window.reset(world)
    for _ in range(SHORT.n_ticks):
        world.step()
        t = world.tick
        active = int(world.trace_sum("active", t - 1, t))
        fac = world.trace_sum("facility_burning", t - 1, t) @ world.facility_penalties
        assert fast(world, t - 1) == -(SHORT.scoring.propagation_weight * active + fac) / 10
    rate = negative_reward_rate(world.trace())
    assert window(world, 0) == pytest.approx(-rate.sum() / SHORT.ticks_per_second, rel=1e-12)


@pytest.mark.parametrize(
    "make", [lambda **kw: TaskEnv(SHORT, **kw), lambda **kw: MotionEnv(SHORT, **kw)]
)
def test_unshaped_return_is_minus_the_manual_negative_reward(make):
    """Over an unshaped episode of either env the rewards sum to minus the manual total
    negative reward of the episode's trace."""
    env = make()
    env.reset(seed=0)
    total = 0.0
    while env.agents:
        _, rew, *_ = env.step({})
        total += rew[env.possible_agents[0]]
    manual = compute_all(env.world.trace())["manual"]
    assert total == pytest.approx(-manual.total_negative_reward, rel=1e-9)


class _Ticks:
    """A reward function counting the ticks of each step (a stand-in for a user's)."""

    def reset(self, world: World) -> None:
        self.world = world

    def __call__(self, world: World, start: int) -> float:
        assert world is self.world
        return float(world.tick - start)


@pytest.mark.parametrize(("cls", "per_step"), [(TaskEnv, 10.0), (MotionEnv, 1.0)])
def test_an_injected_reward_function_replaces_the_penalty(cls, per_step):
    """An env given ``reward_fn`` rewards each step with it (reset with the env's world), plus
    the shaping terms, which are off by default."""
    env = cls(SHORT, reward_fn=_Ticks())
    env.reset(seed=3)
    rewards = [env.step({})[1][env.possible_agents[0]] for _ in range(3)]
    assert rewards == [per_step] * 3
    assert np.isfinite(rewards).all()
