"""Tests for fcplan.env.task_batch: the batched candidates and feature tables are, graph for
graph, those of fcplan.env.task_candidates (the specification)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.env.task_batch import batch_observe
from fcplan.env.task_candidates import agent_features, rank_candidates, task_features
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.scenario import load_scenario
from fcplan.taskgraph import synthetic_task_graph
from fcplan.team import Mode


def _bits(a):
    a = np.asarray(a)
    return a.dtype, a.shape, a.tobytes()


def _check(graphs, k, goal, frac):
    """batch_observe equals the per-graph functions on every graph, bit for bit."""
    obs = batch_observe(graphs, k, goal, frac)
    cands, tasks, agents = obs.candidates, obs.tasks, obs.agents
    for b, g in enumerate(graphs):
        ref = rank_candidates(g, k)
        got = cands[b]
        for name in ("rows", "valid", "start_distance", "priority", "freshness", "legal"):
            assert _bits(getattr(got, name)) == _bits(getattr(ref, name)), (b, name)
        assert _bits(tasks[b]) == _bits(task_features(g, ref, goal[b])), b
        assert _bits(agents[b]) == _bits(agent_features(g, ref, float(frac[b]))), b
        assert _bits(obs.rows[b]) == _bits(ref.rows) and _bits(obs.valid[b]) == _bits(ref.valid)
        for i, slot in zip(*np.nonzero(ref.valid), strict=True):
            t = ref.rows[i, slot]
            assert _bits(obs.slot_pos[b, i, slot]) == _bits(g.task_pos[t])
            assert obs.slot_fire[b, i, slot] == (g.task_kind[t] == 0)
            eta = ref.start_distance[[i], [t]] / g.agent_speed[[i]]  # (decode_actions' arrival)
            assert _bits(obs.slot_eta[b, i, slot]) == _bits(eta[0])


def _goals(rng, n, a):
    """Goals: some agents without one (NaN), some worlds with none at all."""
    goal = rng.uniform(0, 1200, (n, a, 2))
    goal[rng.random((n, a)) < 0.4] = np.nan
    goal[: max(n // 3, 1)] = np.nan
    return goal


@settings(max_examples=30, deadline=None)
@given(
    n_graphs=st.integers(1, 6),
    n_agents=st.integers(2, 5),
    k=st.integers(1, 12),
    seed=st.integers(0, 2**31 - 1),
)
def test_synthetic_graphs(n_graphs, n_agents, k, seed):
    """Property: on synthetic graphs of ragged task counts (0 to 40, k above and below them),
    random agent modes (forced returns included) and batteries, the batched candidates (rows,
    mask, distances, priorities, freshness, legality), task features and agent features equal
    rank_candidates, task_features and agent_features of each graph."""
    rng = np.random.default_rng(seed)
    graphs = []
    for _ in range(n_graphs):
        g = synthetic_task_graph(
            n_agents, int(rng.integers(0, 41)), rng, battery=float(rng.uniform(60, 600))
        )
        mode = rng.choice([int(m) for m in Mode], size=n_agents).astype(np.int8)
        object.__setattr__(g, "agent_mode", mode)
        graphs.append(g)
    _check(graphs, k, _goals(rng, n_graphs, n_agents), rng.random(n_graphs))


def test_environment_graphs():
    """Property: on the graphs the batched task env builds along episodes of #1 and #24 (fire
    and fire-free graphs, shared read-only arrays), the batched tables equal the per-graph
    ones."""
    rng = np.random.default_rng(3)
    for name in ("1", "24"):
        env = VectorTaskEnv(load_scenario(name).replace(duration_s=60), num_envs=5, k=6)
        obs, _ = env.reset(seed=7)
        for step in range(7):
            m = obs["action_mask"]
            obs, *_ = env.step((rng.random(m.shape) * m).argmax(axis=2))
            if step % 2:
                _check(env.graphs, 6, _goals(rng, 5, m.shape[1]), rng.random(5))
        assert any(g.fire_tasks.size for g in env.graphs)


def test_batched_decoding_equals_per_world_command():
    """Property: VectorTaskEnv._commands (all worlds at once, conflicts resolved as arrays)
    leaves every world as the per-world decoding VectorTaskEnv._command does: the same illegal
    and conflict flags, goals, team arrays and next observations, on actions that often send
    two agents of one role to the same slot, pick masked slots, the no-op or out-of-range
    values."""
    sc = load_scenario("1").replace(duration_s=60)
    fast, slow = (VectorTaskEnv(sc, num_envs=6, k=4) for _ in range(2))

    def per_world(worlds, act, illegal, conflict):
        for b in worlds.tolist():
            slow._command(b, act[b], illegal, conflict)

    slow._commands = per_world  # type: ignore[method-assign]
    obs_f, _ = fast.reset(seed=5)
    obs_s, _ = slow.reset(seed=5)
    rng = np.random.default_rng(1)
    conflicts = 0
    for _ in range(12):
        act = rng.integers(-1, 6, (6, 4))
        act[:, 0] = np.where(rng.random(6) < 0.6, 0, act[:, 0])
        act[:, 1] = np.where(rng.random(6) < 0.6, 0, act[:, 1])
        act[:, 2] = np.where(rng.random(6) < 0.6, act[:, 3], act[:, 2])
        obs_f, _, _, _, inf_f = fast.step(act)
        obs_s, _, _, _, inf_s = slow.step(act)
        for name in ("illegal", "conflict", "tick"):
            assert _bits(inf_f[name]) == _bits(inf_s[name]), name
        for name in obs_f:
            assert _bits(obs_f[name]) == _bits(obs_s[name]), name
        assert _bits(fast._goal) == _bits(slow._goal)
        for name in ("pos", "z_target", "goal", "has_goal", "mode", "routes", "route_len"):
            u, v = getattr(fast.batch.team, name), getattr(slow.batch.team, name)
            assert _bits(u) == _bits(v), name
        conflicts += int(inf_f["conflict"].sum())
    assert conflicts > 0
