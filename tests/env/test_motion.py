"""Motion-level environment on fcplan scenarios (fcplan.env.motion)."""

from __future__ import annotations

import hashlib
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fcplan.env import EnvError
from fcplan.env.motion import MotionEnv, parallel_env
from fcplan.fire import PRUNED
from fcplan.metrics import negative_reward_rate
from tests.conftest import scenario_with

pettingzoo_test = pytest.importorskip("pettingzoo.test")
from pettingzoo.utils import parallel_to_aec  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _short(base=1, seconds=6.0, **overrides):
    return scenario_with(base, duration_s=seconds, **overrides)


def _legal_random(env, obs, rng):
    """One random legal action per live agent."""
    acts = {}
    for a in env.agents:
        legal = np.flatnonzero(obs[a]["action_mask"])
        acts[a] = int(legal[rng.integers(legal.size)])
    return acts


def _digest(make, seed: int, steps: int, action_seed: int = 7) -> str:
    """SHA-256 of a rollout: observations, rewards, flags and state at every step."""
    env = make()
    h = hashlib.sha256()
    rng = np.random.default_rng(action_seed)
    obs, _ = env.reset(seed=seed)
    for _ in range(steps):
        if not env.agents:
            obs, _ = env.reset()
        acts = _legal_random(env, obs, rng)
        obs, rew, term, trunc, _ = env.step(acts)
        for a in sorted(obs):
            for key in sorted(obs[a]):
                h.update(np.ascontiguousarray(obs[a][key]).tobytes())
            h.update(repr((rew[a], term[a], trunc[a])).encode())
        h.update(np.ascontiguousarray(env.state()).tobytes())
    return h.hexdigest()


def _make(name: str):
    """Named env factories shared with the subprocess check."""
    return {
        "practice": lambda: MotionEnv(_short("practice", 4.0)),
        "24": lambda: MotionEnv(_short(24, 4.0)),
        "base": lambda: parallel_env(preset="base", max_steps=60),
        "cmplx2": lambda: parallel_env(preset="cmplx2", max_steps=40),
    }[name]


@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
def test_pettingzoo_api(name):
    """The env passes PettingZoo's parallel_api_test, api_test on its AEC conversion and
    parallel_seed_test (open_world_example has hybrid agents, Discrete(8))."""
    sc = _short(name, 8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pettingzoo_test.parallel_api_test(MotionEnv(sc), num_cycles=100)
        pettingzoo_test.api_test(parallel_to_aec(MotionEnv(sc)), num_cycles=100)
        pettingzoo_test.parallel_seed_test(lambda: MotionEnv(sc))


def test_multi_step_determinism_and_seed_sensitivity():
    """Same seed and actions give identical rollouts over many steps (and resets); another
    seed gives a different one."""
    make = _make("practice")
    a = _digest(make, seed=3, steps=120)
    assert a == _digest(make, seed=3, steps=120)
    assert a != _digest(make, seed=4, steps=120)


def test_determinism_across_processes():
    """A fresh Python process reproduces the rollout digests of this one bit for bit."""
    names = ["practice", "24", "base", "cmplx2"]
    here = [_digest(_make(n), seed=11, steps=50) for n in names]
    code = (
        f"import sys; sys.path.insert(0, {str(ROOT)!r})\n"
        "from tests.env.test_motion import _digest, _make\n"
        f"print(' '.join(_digest(_make(n), seed=11, steps=50) for n in {names!r}))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    )
    assert out.stdout.split() == here


def test_reward_is_manual_negative_reward_and_final_metrics_in_infos():
    """Rewards are minus the manual penalty per tick; they sum to minus the total negative
    reward reported in the last step's infos; truncation comes at the scenario's duration."""
    env = MotionEnv(_short(1, 5.0))
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    total, steps = 0.0, 0
    while env.agents:
        obs, rew, term, trunc, infos = env.step(_legal_random(env, obs, rng))
        total += rew["P1"]
        steps += 1
        assert len(set(rew.values())) == 1 and not any(term.values())
    assert steps == env.scenario.n_ticks and all(trunc.values())
    trace = env.world.trace()
    per_tick = -negative_reward_rate(trace) / env.scenario.ticks_per_second
    manual = infos["P1"]["metrics"]["manual"]
    assert total == pytest.approx(per_tick.sum(), rel=1e-12, abs=1e-12)
    assert total == pytest.approx(-manual["total_negative_reward"], rel=1e-9, abs=1e-12)
    assert set(infos["A1"]["metrics"]) == {"manual", "reference2020"}


def test_action_table_moves_altitude_and_masks():
    """A move covers the agent's speed in its direction; climb/descend change the altitude
    target by one tick's climb within the range; masked or missing actions mean stay; an
    out-of-range action raises EnvError."""
    env = MotionEnv("practice")
    obs, _ = env.reset(seed=0)
    team = env.world.team
    p1, a1 = team.index("P1"), team.index("A1")
    start = team.pos.copy()
    obs, *_ = env.step({"P1": 2, "A1": 4})  # P1 east, A1 south
    assert team.pos[p1].tolist() == [start[p1, 0] + team.speed[p1], start[p1, 1]]
    assert team.pos[a1].tolist() == [start[a1, 0], start[a1, 1] + team.speed[a1]]
    assert team.pos[team.index("P2")].tolist() == start[team.index("P2")].tolist()
    z0 = team.z[p1]
    env.step({"P1": 5})
    assert team.z[p1] == pytest.approx(min(z0 + 5.0, team.alt_hi[p1]))
    # drive P1 to its floor: descend becomes illegal there and a masked descend is a stay
    for _ in range(40):
        obs, *_ = env.step({"P1": 6})
    assert team.z[p1] == team.alt_lo[p1] and obs["P1"]["action_mask"][6] == 0
    pos = team.pos[p1].copy()
    env.step({"P1": 6})
    assert team.z[p1] == team.alt_lo[p1] and team.pos[p1].tolist() == pos.tolist()
    with pytest.raises(EnvError, match="action of A1"):
        env.step({"A1": 6})
    with pytest.raises(EnvError, match="action of P1"):
        env.step({"P1": -1})


def test_moves_off_the_map_are_masked():
    """A move that would leave the map is illegal, and taking it anyway keeps the agent inside."""
    env = MotionEnv("practice")
    obs, _ = env.reset(seed=0)
    team = env.world.team
    i = team.index("P2")
    for _ in range(200):
        if obs["P2"]["action_mask"][1] == 0:
            break
        obs, *_ = env.step({"P2": 1})  # west until the edge
    assert obs["P2"]["action_mask"][1] == 0
    x = team.pos[i, 0]
    assert 0.0 <= x < team.speed[i]
    env.step({"P2": 1})
    assert team.pos[i, 0] == x


def test_dump_spends_tank_only_when_it_prunes_and_empty_tank_masks_dump():
    """A dump with nothing sensed in view costs nothing; an empty tank masks dump and sends
    the agent home, where it refills."""
    sc = _short("practice", 30.0, **{"team.action.tank": 1})
    env = MotionEnv(sc)
    obs, _ = env.reset(seed=0)
    team, world = env.world.team, env.world
    a1 = team.index("A1")
    obs, *_ = env.step({"A1": 5})
    assert team.tank[a1] == 1  # nothing sensed there: no dump
    # put A1 over a sensed burning cell and dump
    world.ignite([[int(team.pos[a1, 0]), int(team.pos[a1, 1])]])
    world.sensed[int(team.pos[a1, 0]), int(team.pos[a1, 1])] = True
    obs, *_ = env.step({"A1": 5})
    assert team.tank[a1] == 0 and obs["A1"]["action_mask"][5] == 0
    assert obs["A1"]["action_mask"].tolist() == [1, 0, 0, 0, 0, 0]  # forced home: stay only
    while team.tank[a1] == 0:
        obs, *_ = env.step({})
    assert team.tank[a1] == 1 and obs["A1"]["action_mask"][5] == 1


def test_observation_channels_match_the_world():
    """The fov crops' known-fire, pruned and agent channels and the state's burning and known
    channels agree with a direct computation from the world; later steps do not mutate earlier
    observations."""
    env = MotionEnv(_short(1, 60.0), cell_px=20, view=15)
    obs, _ = env.reset(seed=1)
    rng = np.random.default_rng(1)
    kept = None
    for t in range(250):
        obs, *_ = env.step(_legal_random(env, obs, rng))
        if t == 100:
            kept = {a: {k: v.copy() for k, v in o.items()} for a, o in obs.items()}
            held = obs
    for a in kept:
        for k in kept[a]:
            np.testing.assert_array_equal(kept[a][k], held[a][k])
    world, team = env.world, env.world.team
    w, c, v = world.world_size, 20, 15
    nc = -(-w // c)
    known = np.zeros((nc * c, nc * c))
    known[:w, :w] = world.sensed & (world.fire.state == 1)
    pruned = np.zeros((nc * c, nc * c))
    pruned[:w, :w] = world.fire.state == PRUNED
    kc = known.reshape(nc, c, nc, c).sum(axis=(1, 3))
    pc = pruned.reshape(nc, c, nc, c).sum(axis=(1, 3))
    r = v // 2
    for i, a in enumerate(env.possible_agents):
        cx, cy = (team.pos[i] // c).astype(int)
        ref_k = np.zeros((v, v))
        ref_p = np.zeros((v, v))
        x0, x1, y0, y1 = max(cx - r, 0), min(cx + r + 1, nc), max(cy - r, 0), min(cy + r + 1, nc)
        ref_k[x0 - cx + r : x1 - cx + r, y0 - cy + r : y1 - cy + r] = kc[x0:x1, y0:y1]
        ref_p[x0 - cx + r : x1 - cx + r, y0 - cy + r : y1 - cy + r] = pc[x0:x1, y0:y1]
        fov = obs[a]["fov"]
        np.testing.assert_allclose(fov[0], np.minimum(ref_k / c, 1.0), atol=1e-6)
        np.testing.assert_allclose(fov[1], np.minimum(ref_p / c, 1.0), atol=1e-6)
        others = np.zeros((v, v))
        for j in range(team.n):
            ox, oy = (team.pos[j] // c).astype(int) - (cx, cy) + r
            if j != i and 0 <= ox < v and 0 <= oy < v:
                others[ox, oy] = 1.0
        np.testing.assert_array_equal(fov[3], others)
        assert obs[a]["fov"] in env.observation_space(a)["fov"]
    state = env.state()
    assert state in env.state_space
    burning = np.zeros((nc * c, nc * c))
    burning[:w, :w] = world.fire.state == 1
    bc = burning.reshape(nc, c, nc, c).sum(axis=(1, 3))
    np.testing.assert_allclose(state[0], np.minimum(bc / c, 1.0), atol=1e-6)
    np.testing.assert_allclose(state[1], np.minimum(kc / c, 1.0), atol=1e-6)


def test_parallel_env_dispatch_and_bad_arguments():
    """parallel_env takes a scenario, a preset name or preset=; bad arguments raise EnvError
    naming the argument."""
    assert parallel_env("base").metadata["name"] == "fcplan_base_v0"
    assert parallel_env(preset="cmplx1").variant == "cmplx1"
    assert isinstance(parallel_env("practice"), MotionEnv)
    with pytest.raises(EnvError, match="preset"):
        parallel_env("practice", preset="base")
    with pytest.raises(EnvError, match="preset"):
        parallel_env(preset="hard")
    with pytest.raises(EnvError, match="view"):
        MotionEnv("practice", view=4)
    with pytest.raises(EnvError, match="render_mode"):
        MotionEnv("practice", render_mode="human")
    env = MotionEnv(_short("practice", 0.2))
    env.reset(seed=0)
    while env.agents:
        env.step({})
    with pytest.raises(EnvError, match="reset"):
        env.step({})


def test_render_rgb_array():
    """render_mode="rgb_array" returns an (H, W, 3) uint8 image from the shared renderer."""
    pytest.importorskip("fcplan.render")
    env = MotionEnv("practice", render_mode="rgb_array", render_size=128)
    env.reset(seed=0)
    env.step({"P1": 2})
    img = env.render()
    assert img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**16),
    choices=st.lists(st.integers(0, 7), min_size=4, max_size=4),
    stay=st.floats(0.0, 0.6),
)
def test_invariants_under_random_play(seed, choices, stay):
    """Whatever the agents do: battery and tank never go negative, agents stay on the map,
    pruned cells never burn again, and observations stay inside their spaces."""
    sc = _short(
        1,
        5.0,
        **{"team.perception.battery": 30, "team.action.battery": 30, "team.action.tank": 1},
    )
    env = MotionEnv(sc)
    obs, _ = env.reset(seed=seed)
    world, team = env.world, env.world.team
    rng = np.random.default_rng(seed)
    w = world.world_size
    pruned_before = np.zeros((w, w), dtype=bool)
    step = 0
    while env.agents:
        acts = {}
        for k, a in enumerate(env.agents):
            legal = np.flatnonzero(obs[a]["action_mask"])
            pick = choices[k % 4] if rng.random() > stay else 0
            acts[a] = int(legal[pick % legal.size])
        obs, *_ = env.step(acts)
        step += 1
        assert (team.battery >= 0).all() and (team.tank >= 0).all()
        assert (team.pos >= 0).all() and (team.pos <= w - 1).all()
        pruned_now = world.fire.state == PRUNED
        assert not (pruned_before & ~pruned_now).any()
        pruned_before = pruned_now
        if step % 10 == 0:
            for a in obs:
                assert obs[a] in env.observation_space(a)


def test_hybrid_action_table():
    """Hybrids get both sets: climb 5, descend 6, dump 7."""
    env = MotionEnv(_short("open_world_example", 2.0))
    env.reset(seed=0)
    hybrids = [a for a in env.possible_agents if a.startswith("H")]
    assert hybrids and all(int(env.action_space(h).n) == 8 for h in hybrids)
    team = env.world.team
    i = team.index(hybrids[0])
    z0 = team.z_target[i]
    env.step({hybrids[0]: 6 if z0 > team.alt_lo[i] else 5})
    assert team.z_target[i] != z0


def test_small_team_python_path_equals_numpy_path(monkeypatch):
    """Agent vectors and action masks are identical whether built by the small-team Python loop
    or by the numpy code used for large teams."""
    import fcplan.env.motion_obs as motion_obs

    env = MotionEnv(_short("open_world_example", 20.0))
    obs, _ = env.reset(seed=2)
    rng = np.random.default_rng(2)
    while env.agents:
        obs, *_ = env.step(_legal_random(env, obs, rng))
        if env.world.tick % 25 == 0:
            vec, mask, cx, cy = env.observations.agent_arrays()
            monkeypatch.setattr(motion_obs, "_PY_AGENTS", 0)
            vec_np, mask_np, cx_np, cy_np = env.observations.agent_arrays()
            monkeypatch.setattr(motion_obs, "_PY_AGENTS", 16)
            assert len(mask) == len(mask_np) == len(env.possible_agents)
            for m, m_np in zip(mask, mask_np, strict=True):
                assert m.dtype == m_np.dtype == np.int8
                np.testing.assert_array_equal(m, m_np)
            np.testing.assert_array_equal(vec, vec_np)
            assert (cx, cy) == (cx_np, cy_np)


def test_staleness_channel():
    """Staleness is 0 where a camera looks now, grows by 1 / (stale_s * tps) per tick after,
    and is 1 where no camera ever looked."""
    env = MotionEnv("practice", stale_s=2.0)
    obs, _ = env.reset(seed=0)
    team = env.world.team
    p1 = team.index("P1")
    c = env.cell_px
    cx, cy = (int(v) for v in team.pos[p1] // c)
    env.step({"P1": 0})
    state = env.state()
    assert state[3, cx, cy] == 0.0 and state[3, -1, -1] == 1.0
    assert obs["P1"]["fov"][2].max() <= 1.0
    # leave: the cell stops being covered; 5 ticks later its staleness is 5 / 20 higher
    for _ in range(12):
        env.step({"P1": 2})
    x0, x1, y0, y1 = env._last_info.fov[p1]
    covered = x0 <= (cx + 1) * c - 1e-9 and cx * c <= x1 and y0 <= (cy + 1) * c and cy * c <= y1
    assert not covered
    before = env.state()[3, cx, cy]
    for _ in range(5):
        env.step({"P1": 2})
    assert env.state()[3, cx, cy] == pytest.approx(min(1.0, before + 5 / 20), abs=1e-6)
    assert 0.0 < before < 1.0


def test_coarse_maps_observe_equals_direct_crops():
    """CoarseMaps.observe gives, per agent, the padded window of its cell with staleness
    min(1, seen + tick * seen_scale) and, on the agents channel, the *other* agents only (a
    shared cell shows at the centre); the crops are a fresh C-contiguous array, and
    staleness(tick) equals the map part of the stale layer."""
    from fcplan import load_scenario
    from fcplan.env.motion_grid import AGENTS, LAST_SEEN, CoarseMaps

    sc = load_scenario("practice")
    maps = CoarseMaps(sc, cell_px=20, view=7, seen_scale=0.01)
    rng = np.random.default_rng(5)
    nc, r = maps.nc, maps.radius
    for tick in (0, 3, 40, 250):
        seen = -np.float32(0.01) * rng.integers(0, tick + 1, size=(nc, nc)).astype(np.float32)
        seen[rng.random((nc, nc)) < 0.3] = np.inf
        maps.seen[r : r + nc, r : r + nc] = seen
        cx = rng.integers(0, nc, size=5).tolist()
        cy = rng.integers(0, nc, size=5).tolist()
        cx[1], cy[1] = cx[0], cy[0]  # two agents in one cell
        out = maps.observe(cx, cy, tick, 7)
        assert out.flags.c_contiguous and out.dtype == np.float32 and out.shape == (5, 7, 7, 7)
        stale = np.ones((nc + 2 * r, nc + 2 * r), np.float32)
        stale[r : r + nc, r : r + nc] = np.minimum(seen + np.float32(tick * 0.01), 1.0)
        np.testing.assert_array_equal(maps.staleness(tick), stale[r : r + nc, r : r + nc])
        occupied = np.zeros_like(stale)
        for x, y in zip(cx, cy, strict=True):
            occupied[x + r, y + r] += 1.0
        for i, (x, y) in enumerate(zip(cx, cy, strict=True)):
            np.testing.assert_array_equal(out[i, LAST_SEEN], stale[x : x + 7, y : y + 7])
            others = occupied[x : x + 7, y : y + 7].copy()
            others[r, r] -= 1.0
            np.testing.assert_array_equal(out[i, AGENTS], np.minimum(others, 1.0))
            for k in (0, 1, 4, 5, 6):
                np.testing.assert_array_equal(out[i, k], maps.grid[k, x : x + 7, y : y + 7])
        assert out[0, AGENTS, r, r] == out[1, AGENTS, r, r] == 1.0
