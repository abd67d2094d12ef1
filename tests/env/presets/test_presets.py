"""Reference MARL presets base / cmplx1 / cmplx2 (fcplan.env.presets): rules, rewards, API."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.env import EnvError
from fcplan.env.motion import parallel_env
from fcplan.env.presets.base import STATIONARY_FIRE, BaseEnv
from fcplan.env.presets.cmplx import CmplxEnv
from fcplan.env.presets.core import rf1_penalty_small, rf1_structure_penalty
from fcplan.fire import BURNING, PRUNED

pettingzoo_test = pytest.importorskip("pettingzoo.test")
from pettingzoo.utils import parallel_to_aec  # noqa: E402

P0, P1, A0, A1 = "perception_0", "perception_1", "action_0", "action_1"


@pytest.mark.parametrize("preset", ["base", "cmplx1", "cmplx2"])
def test_pettingzoo_api(preset):
    """Each preset passes parallel_api_test, api_test on its AEC conversion and
    parallel_seed_test."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pettingzoo_test.parallel_api_test(parallel_env(preset=preset), num_cycles=250)
        pettingzoo_test.api_test(parallel_to_aec(parallel_env(preset=preset)), num_cycles=250)
        pettingzoo_test.parallel_seed_test(lambda: parallel_env(preset=preset))


@pytest.mark.parametrize("preset", ["base", "cmplx1", "cmplx2"])
def test_multi_step_determinism(preset):
    """Same seed and actions reproduce a preset's rollout over many steps; seeds differ."""

    def roll(seed):
        env = parallel_env(preset=preset)
        obs, _ = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        out = []
        for _ in range(150):
            if not env.agents:
                obs, _ = env.reset()
            acts = {a: int(rng.integers(env.action_space(a).n)) for a in env.agents}
            obs, rew, *_ = env.step(acts)
            out.append((env.state().tobytes(), tuple(rew.values()), obs[P0]["fov"].tobytes()))
        return out

    assert roll(5) == roll(5)
    assert roll(5) != roll(6)


def test_base_spaces_and_start():
    """base: P Discrete(5) (4 without no-op), A Discrete(6); FOV (4 + 2P + A, 2v+1, 2v+1);
    state (1 + P + A, W, W); random starts with all x and all y distinct; centre start."""
    env = BaseEnv()
    obs, _ = env.reset(seed=0)
    assert [int(env.action_space(a).n) for a in env.agents] == [5, 5, 6, 6]
    assert int(BaseEnv(no_op=False).action_space(P0).n) == 4
    assert obs[A1]["fov"].shape == (10, 3, 3)
    assert BaseEnv(vision=2).observation_space(P0)["fov"].shape == (10, 5, 5)
    assert BaseEnv(n_perception=3, n_action=1).observation_space(A0)["fov"].shape == (11, 3, 3)
    assert env.state().shape == (5, 10, 10)
    vals = env._pos.ravel()
    assert len(set(vals.tolist())) == 8
    assert int(env.fire.sum()) == 5
    env = BaseEnv(center_init=True, stationary_fire=True)
    env.reset(seed=0)
    assert env._pos.tolist() == [[5, 5]] * 4
    assert sorted(np.flatnonzero(env.fire.ravel()).tolist()) == sorted(STATIONARY_FIRE)
    with pytest.raises(EnvError, match="world_size"):
        BaseEnv(world_size=6)
    with pytest.raises(EnvError, match="vision"):
        BaseEnv(vision=3)


def _base_case(**kwargs):
    """A base env with fire at (0, 1), (1, 1), (5, 5); P0 (0, 0), P1 (9, 9), A0 (1, 1),
    A1 (9, 0)."""
    env = BaseEnv(**kwargs)
    env.reset(seed=0)
    env.fire[:] = False
    env.fire[[0, 1, 5], [1, 1, 5]] = True
    env.n_fires = 3
    env._pos = np.array([[0, 0], [9, 9], [1, 1], [9, 0]])
    return env


def test_base_rf1_hand_computed():
    """RF1: change of 2|sensed| + 20|pruned| (2 sensed, 1 pruned: 24) minus 1 per lonely agent
    (P1, A1) and 3 per agent without a P-A neighbour pair (P1, A1): 24 - 8 = 16; mixed 50/50
    with the local rewards."""
    env = _base_case(reward="rf1")
    assert rf1_structure_penalty(env._pos, env.is_perception, 5) == 8.0
    _, rew, term, trunc, infos = env.step({P0: 4, P1: 4, A0: 4, A1: 5})
    assert rew[P0] == pytest.approx(0.5 * (-0.1 + 0.1 * 2) + 0.5 * 16)
    assert rew[A0] == pytest.approx(0.5 * (-0.1 + 0.1 * 1 - 0.05) + 0.5 * 16)
    assert rew[P1] == pytest.approx(0.5 * -0.1 + 0.5 * 16)
    assert rew[A1] == pytest.approx(0.5 * -0.1 + 0.5 * 16)
    assert infos[P0]["action_complete"] == pytest.approx(1 / 3)
    _, rew, *_ = env.step({P0: 4, P1: 4, A0: 5, A1: 5})  # nothing new: only the penalty
    assert rew[P1] == pytest.approx(0.5 * -0.1 + 0.5 * -8)
    assert not any(term.values()) and not any(trunc.values())


def test_base_rf3_and_rf2_hand_computed():
    """RF3 = -0.1 * unpruned - 0.05 per dumping action agent; RF2 = -1 while fire remains."""
    env = _base_case(reward="rf3")
    _, rew, *_ = env.step({P0: 4, P1: 4, A0: 5, A1: 4})  # only A1 dumps (on no fire)
    glob = -0.1 * 3 - 0.05
    assert rew[P1] == pytest.approx(0.5 * -0.1 + 0.5 * glob)
    assert rew[A1] == pytest.approx(0.5 * (-0.1 - 0.05) + 0.5 * glob)
    assert rew[P0] == pytest.approx(0.5 * (-0.1 + 0.2) + 0.5 * glob)
    env = _base_case(reward="rf2", local_reward_ratio=0.0)
    _, rew, *_ = env.step({P0: 4, P1: 4, A0: 4, A1: 5})
    assert set(rew.values()) == {-1.0}


def test_base_done_rules_and_termination_reward():
    """Pruning every fire terminates with success (+10 n_fires each with termination_reward);
    reaching max_steps truncates (-10 per unpruned fire each)."""
    env = _base_case(reward="rf2", local_reward_ratio=0.0, termination_reward=True)
    env.fire[:] = False
    env.fire[1, 1] = True
    env.n_fires = 1
    _, rew, term, trunc, infos = env.step({P0: 4, P1: 4, A0: 4, A1: 5})
    assert all(term.values()) and not any(trunc.values()) and infos[A0]["success"]
    assert rew[P1] == pytest.approx(0.0 + 10.0)
    assert env.agents == []
    env = _base_case(reward="rf2", local_reward_ratio=0.0, termination_reward=True, max_steps=2)
    env.step({})
    _, rew, term, trunc, infos = env.step({})
    assert all(trunc.values()) and not any(term.values()) and not infos[P0]["success"]
    assert rew[P0] == pytest.approx(-1.0 - 10.0 * 3)


def test_cmplx_spaces_start_and_variants():
    """cmplx: P Discrete(6), A Discrete(4) (cmplx1) or Discrete(5) (cmplx2); everyone starts at
    (W-10, W/10) at altitude 10; FOV (6, 31, 31); state (W, W); 2 regions of 5..14 fronts."""
    for variant, a_n in (("cmplx1", 4), ("cmplx2", 5)):
        env = CmplxEnv(variant=variant)
        obs, _ = env.reset(seed=3)
        assert [int(env.action_space(a).n) for a in env.agents] == [6, 6, a_n, a_n]
        assert env._pos.tolist() == [[90, 10]] * 4 and env._z.tolist() == [10] * 4
        assert obs[P1]["fov"].shape == (6, 31, 31) and env.state().shape == (100, 100)
        assert len(env.regions) == 2
        for r in env.regions:
            assert 5 <= r.fronts <= 14 and 20 <= r.center[0] <= 79 and 20 <= r.center[1] <= 79
            assert r.wind_dir_deg in (0, 45, 90, 135, 180)
    env = CmplxEnv()
    env.reset(seed=0)
    env.step({P0: 1, P1: 4, A0: 3, A1: 0})
    assert env._pos.tolist() == [[95, 10], [90, 10], [90, 15], [85, 10]]
    assert env._z.tolist() == [10, 12, 10, 10]
    for _ in range(5):
        env.step({P0: 1, P1: 4})
    assert env._pos[0].tolist() == [99, 10] and env._z[1] == 15  # clipped


def test_cmplx_rewards_hand_computed():
    """RF1 (cumulative) = 2|sensed| + 20|pruned| - structure penalty; the 'change' mode uses
    the per-step change; RF2 = -1 while fire burns; RF3 = -0.1 |burning|; one shared value."""
    env = CmplxEnv(reward="rf1")
    env.reset(seed=2)
    for _ in range(3):
        _, rew, *_ = env.step({A0: 1})
    want = 2.0 * env.sensed.sum() + 20.0 * env.fire.n_pruned
    want -= rf1_structure_penalty(env._pos, env.is_perception, 30.0)
    assert len(set(rew.values())) == 1 and rew[P0] == pytest.approx(want)
    env = CmplxEnv(reward="rf1", rf1_mode="change")
    env.reset(seed=2)
    total = 0.0
    for _ in range(3):
        _, rew, *_ = env.step({A0: 1})
        total += rew[P0] + rf1_structure_penalty(env._pos, env.is_perception, 30.0)
    assert total == pytest.approx(2.0 * env.sensed.sum() + 20.0 * env.fire.n_pruned)
    env = CmplxEnv(reward="rf3")
    env.reset(seed=2)
    _, rew, *_ = env.step({})
    assert rew[A1] == pytest.approx(-0.1 * env.fire.n_burning)
    env = CmplxEnv(reward="rf2")
    env.reset(seed=2)
    _, rew, *_ = env.step({})
    assert rew[A1] == (-1.0 if env.fire.n_burning else 0.0)


def test_cmplx_low_altitude_senses_everything_instead_of_crashing():
    """Below z = 10 the reference confidence exceeds 1 and crashed; here it is clipped to 1:
    every burning cell in the box is sensed."""
    env = CmplxEnv()
    env.reset(seed=4)
    cx, cy = (int(v) for v in env.regions[0].center)
    env._pos[0] = [cx, cy]
    for _ in range(3):
        env.step({P0: 5})  # descend to 5 (clipped)
    assert env._z[0] == 5
    x0, x1, y0, y1 = env._box(0)
    burning = env.fire.state[x0:x1, y0:y1] == BURNING
    assert burning.any() and env.sensed[x0:x1, y0:y1][burning].all()


def test_cmplx_pruning_gate_and_variant_difference():
    """Action agents prune only where a sampled cell is sensed; cmplx1 prunes every step,
    cmplx2 only on dump (action 4)."""
    for variant, act, expect in (("cmplx1", 0, True), ("cmplx2", 0, False), ("cmplx2", 4, True)):
        env = CmplxEnv(variant=variant, prune_confidence=1.0)
        env.reset(seed=4)
        cx, cy = (int(v) for v in env.regions[0].center)
        env._pos[:] = [cx, cy]
        env.step({P0: 4, P1: 4, A0: 1, A1: 1})
        env._pos[:] = [cx, cy]
        pruned_before = env.fire.n_pruned
        env.step({P0: 5, P1: 5, A0: act, A1: act})
        env._pos[2:] = [cx, cy]
        env.step({P0: 5, P1: 5, A0: act, A1: act})
        assert (env.fire.n_pruned > pruned_before) == expect, variant
    env = CmplxEnv(prune_confidence=1.0)
    env.reset(seed=4)
    env._pos[2:] = [int(v) for v in env.regions[0].center]  # action agents alone: no sensing
    env._pos[:2] = [0, 99]
    for _ in range(3):
        env.step({A0: 1, A1: 0})
        env._pos[2:] = [int(v) for v in env.regions[0].center]
    assert env.fire.n_pruned == 0 and (env.fire.state != PRUNED).all()


def test_cmplx_done_rules():
    """The unreachable default threshold ends episodes by truncation at max_steps; a reachable
    one terminates with the success bonus."""
    env = CmplxEnv(max_steps=5)
    env.reset(seed=0)
    for _ in range(5):
        _, rew, term, trunc, infos = env.step({})
    assert all(trunc.values()) and not any(term.values()) and env.agents == []
    env = CmplxEnv(a_c_threshold=0.0, reward="rf3")
    env.reset(seed=0)
    _, rew, term, trunc, infos = env.step({})
    assert all(term.values()) and infos[P0]["success"]
    assert rew[P0] == pytest.approx(-0.1 * env.fire.n_burning + 1000.0)


@pytest.mark.parametrize("preset", ["base", "cmplx2"])
def test_preset_render(preset):
    """render_mode="rgb_array" gives an (H, W, 3) uint8 image of the grid."""
    env = parallel_env(preset=preset, render_mode="rgb_array")
    env.reset(seed=0)
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**16), variant=st.sampled_from(["cmplx1", "cmplx2"]))
def test_cmplx_invariants(seed, variant):
    """Agents stay on the grid and inside the altitude range; pruned cells never burn again;
    sensed cells stay sensed; observations stay inside their spaces."""
    env = CmplxEnv(variant=variant, max_steps=60)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    pruned = np.zeros((100, 100), dtype=bool)
    sensed = env.sensed.copy()
    while env.agents:
        obs, *_ = env.step({a: int(rng.integers(env.action_space(a).n)) for a in env.agents})
        assert ((env._pos >= 0) & (env._pos <= 99)).all()
        assert ((env._z >= 5) & (env._z <= 15)).all()
        now = env.fire.state == PRUNED
        assert not (pruned & ~now).any() and not (sensed & ~env.sensed).any()
        pruned, sensed = now, env.sensed.copy()
        for a in obs:
            assert obs[a] in env.observation_space(a)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(1, 8),
    st.integers(0, 2**32 - 1),
    st.sampled_from([0.0, 1.0, 2.5, 5.0, 30.0]),
)
def test_rf1_penalty_small_equals_numpy(n, seed, comm_range):
    """The Python-list RF1 structure penalty used by small teams equals the numpy one for any
    positions, roles and range (ties at the range included)."""
    rng = np.random.default_rng(seed)
    pos = rng.integers(0, 8, size=(n, 2))
    is_p = rng.random(n) < 0.5
    want = rf1_structure_penalty(pos, is_p, comm_range)
    got = rf1_penalty_small(pos.tolist(), is_p.tolist(), comm_range)
    assert got == want and type(got) is float


@pytest.mark.parametrize("variant", ["cmplx1", "cmplx2"])
def test_cmplx_incremental_layers_equal_the_fire(variant):
    """The cmplx env's padded known-fire and pruned layers, kept up to date from each step's
    sensed and pruned cells, equal a direct computation from the fire state and the sensed
    grid at every step (also with agents moved by hand between steps)."""
    env = CmplxEnv(variant=variant, max_steps=120)
    env.reset(seed=3)
    rng = np.random.default_rng(3)
    w, r = env.world_size, env.max_alt
    for t in range(120):
        if t % 30 == 10:  # put the team on a fire region: pruning happens
            env._pos[:] = [int(v) for v in env.regions[t % len(env.regions)].center]
        env.step({a: int(rng.integers(env.action_space(a).n)) for a in env.agents})
        inner = env._grid[:, r : r + w, r : r + w]
        known = (env.fire.state == BURNING) & env.sensed
        np.testing.assert_array_equal(inner[2], known.astype(np.float32))
        np.testing.assert_array_equal(inner[3], (env.fire.state == PRUNED).astype(np.float32))
    assert env.fire.n_pruned > 0
