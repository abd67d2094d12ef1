"""Tests for fcplan.env.task_candidates and task_actions: masks match validate_plan, ranking,
features, plan <-> action mapping."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.env.task_actions import MappingCounts, actions_plan, decode_actions, plan_to_actions
from fcplan.env.task_candidates import (
    FEATURE_BOUND,
    TASK_FEATURES,
    agent_features,
    legal_tasks,
    rank_candidates,
    task_features,
)
from fcplan.errors import PlanError
from fcplan.plan import Plan, validate_plan
from fcplan.taskgraph import TaskKind, synthetic_task_graph
from fcplan.team import Mode


@settings(max_examples=40, deadline=None)
@given(
    n_agents=st.integers(2, 7),
    n_tasks=st.integers(0, 40),
    k=st.integers(1, 12),
    seed=st.integers(0, 2**31 - 1),
    battery=st.floats(60.0, 600.0),
)
def test_mask_is_exactly_validate_plan(n_agents, n_tasks, k, seed, battery):
    """Every legal (agent, task) pair passes validate_plan as a one-task route and every
    illegal one fails; candidates are legal, distinct, role-appropriate and fill k slots when
    enough tasks are legal; the no-op is always legal; features are finite and bounded."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, n_tasks, rng, battery=battery)
    mode = rng.choice([int(m) for m in Mode], size=n_agents).astype(np.int8)
    object.__setattr__(g, "agent_mode", mode)
    legal = legal_tasks(g)
    for i, a in enumerate(g.agent_ids):
        for t in range(g.n_tasks):
            try:
                validate_plan(Plan(routes={a: (g.task_ids[t],)}), g)
                ok = True
            except PlanError:
                ok = False
            assert ok == legal[i, t]
    c = rank_candidates(g, k)
    mask = c.action_mask()
    assert mask.shape == (n_agents, k + 1) and (mask[:, -1] == 1).all()
    for i in range(n_agents):
        rows = c.rows[i][c.valid[i]]
        assert (c.rows[i][~c.valid[i]] == -1).all()
        assert len(set(rows.tolist())) == rows.size
        assert legal[i, rows].all()
        assert rows.size == min(k, int(legal[i].sum()))
        if not g.agent_can_sense[i]:
            assert (g.task_kind[rows] == TaskKind.FIRE).all()
        # valid slots come first
        assert not (np.diff(c.valid[i].astype(int)) > 0).any()
    f = task_features(g, c, np.full((n_agents, 2), np.nan))
    s = agent_features(g, c, 0.5)
    assert f.shape == (n_agents, k, len(TASK_FEATURES)) and f.dtype == np.float32
    for x in (f, s):
        assert np.isfinite(x).all() and (np.abs(x) <= FEATURE_BOUND).all()
    assert (f[~c.valid] == 0).all()


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 6), k=st.integers(1, 8))
def test_any_masked_choice_is_a_valid_plan(seed, n_agents, k):
    """Any choice of legal actions gives a plan validate_plan accepts, with at most one agent
    per (task, role), and mapping that plan back gives the surviving actions."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, 20, rng)
    c = rank_candidates(g, k)
    mask = c.action_mask()
    act = np.array([rng.choice(np.flatnonzero(m)) for m in mask])
    rows, illegal, conflict = decode_actions(g, c, act)
    assert not illegal.any()
    plan = actions_plan(g, rows)
    validate_plan(plan, g)
    chosen = rows >= 0
    pairs = list(zip(rows[chosen].tolist(), g.agent_role[chosen].tolist(), strict=True))
    assert len(pairs) == len(set(pairs))
    counts = MappingCounts()
    back = plan_to_actions(plan, g, c, counts)
    assert np.array_equal(back, np.where(conflict, k, act))
    assert counts["outside_top_k"] == 0


def test_ranking_is_deterministic_and_prefers_value_per_time():
    """Equal inputs rank equally; a more valuable task at the same distance ranks first."""
    g = synthetic_task_graph(4, 30, np.random.default_rng(1))
    a, b = rank_candidates(g, 6), rank_candidates(g, 6)
    assert np.array_equal(a.rows, b.rows)
    for i in range(4):
        p = a.priority[i, a.rows[i][a.valid[i]]]
        fire = g.task_kind[a.rows[i][a.valid[i]]] == TaskKind.FIRE
        for kind in (fire, ~fire):
            assert (np.diff(p[kind]) <= 0).all()


def test_outside_top_k_maps_to_nearest_candidate_of_its_kind():
    """A plan task outside the candidates maps to the nearest legal candidate of the same kind
    and is counted."""
    g = synthetic_task_graph(3, 30, np.random.default_rng(2))
    c = rank_candidates(g, 2)
    i = int(np.flatnonzero(g.agent_can_act)[0])
    outside = [t for t in np.flatnonzero(legal_tasks(g)[i]) if t not in c.rows[i]]
    t = int(outside[0])
    counts = MappingCounts()
    act = plan_to_actions(Plan(routes={g.agent_ids[i]: (g.task_ids[t],)}), g, c, counts)
    assert counts["outside_top_k"] == 1 and counts["noop"] == g.n_agents - 1
    slot = int(act[i])
    assert g.task_kind[c.rows[i, slot]] == g.task_kind[t]
    d = np.hypot(*(g.task_pos[c.rows[i][c.valid[i]]] - g.task_pos[t]).T)
    assert d[slot] == d.min()


# ---------------------------------------------------------------- fast paths (issue 4, speed)
# The env's per-step code and the modules under it have vectorised / deferred fast paths; each
# is checked here against the plain definition it replaces.


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 8), k=st.integers(1, 6))
def test_actions_commands_equal_plan_commands(seed, n_agents, k):
    """actions_commands gives exactly plan_commands(actions_plan(...)): same agents, order,
    routes and altitudes, for any rows and altitude settings."""
    from fcplan.env.task_actions import actions_commands
    from fcplan.plan import plan_commands

    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, 25, rng)
    rows = np.where(rng.random(n_agents) < 0.3, -1, rng.integers(0, g.n_tasks, n_agents))
    za, zs = rng.uniform(0.0, 200.0, 2)
    fast = actions_commands(g, rows, watch_altitude=za, search_altitude=zs)
    slow = plan_commands(actions_plan(g, rows, watch_altitude=za, search_altitude=zs), g)
    assert list(fast.items()) == list(slow.items())


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 8),
    dump=st.sampled_from(["watch", None, 20.0, 90.0, 500.0]),
)
def test_hybrids_sent_to_fires_fly_at_the_dump_altitude(seed, n_agents, dump):
    """The env's altitude rule: a hybrid with water sent to a fire flies at
    ``graph.dump_altitude(i, d)`` (``d`` = ``watch_altitude`` for ``"watch"``, v0's rule); a
    camera agent sent to a block at ``search_altitude``, one without water sent to a fire at
    ``watch_altitude`` (all clipped); action-only agents get no altitude; and actions_commands
    equals plan_commands(actions_plan(...)) under every rule."""
    import dataclasses

    from fcplan.env.task_actions import actions_commands
    from fcplan.plan import plan_commands

    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, 25, rng)
    hybrid = g.agent_can_sense & (rng.random(n_agents) < 0.6)
    tank = np.where(hybrid, rng.integers(0, 3, n_agents), g.agent_tank)
    g = dataclasses.replace(g, agent_can_act=g.agent_can_act | hybrid, agent_tank=tank)
    rows = np.where(rng.random(n_agents) < 0.2, -1, rng.integers(0, g.n_tasks, n_agents))
    za, zs = 35.0, 70.0
    cmds = actions_commands(g, rows, watch_altitude=za, search_altitude=zs, dump_altitude=dump)
    plan = actions_plan(g, rows, watch_altitude=za, search_altitude=zs, dump_altitude=dump)
    assert list(cmds.items()) == list(plan_commands(plan, g).items())
    for i, t in enumerate(rows.tolist()):
        z = cmds[g.agent_ids[i]].altitude if t >= 0 else None
        if t < 0 or not g.agent_can_sense[i]:
            assert z is None
        elif g.task_kind[t] != TaskKind.FIRE:
            assert z == g.clip_altitude(i, zs)
        elif g.agent_can_act[i] and g.agent_tank[i] > 0:
            assert z == g.dump_altitude(i, za if dump == "watch" else dump)
        else:
            assert z == g.clip_altitude(i, za)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n_agents=st.integers(2, 6), n_tasks=st.integers(1, 30))
def test_validate_plan_fast_path_matches_checks(seed, n_agents, n_tasks):
    """validate_plan's vectorised pass accepts exactly the plans its one-by-one checks accept,
    and a rejected plan raises the same error message."""
    from fcplan.plan import _check_plan, _plan_ok

    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(n_agents, n_tasks, rng, battery=float(rng.uniform(60.0, 600.0)))
    object.__setattr__(g, "agent_mode", rng.integers(0, 4, n_agents).astype(np.int8))
    ids = list(g.agent_ids) + ["X9"]
    tids = list(g.task_ids) + ["fire:nowhere"]
    for _ in range(10):
        agents = rng.choice(ids, size=int(rng.integers(0, 4)), replace=False).tolist()
        routes = {a: tuple(rng.choice(tids, size=int(rng.integers(0, 4))).tolist()) for a in agents}
        alts = {a: float(rng.uniform(0.0, 120.0)) for a in agents if rng.random() < 0.5}
        home = frozenset(a for a in ids[:-1] if rng.random() < 0.1)
        plan = Plan(routes=routes, altitudes=alts, home=home)
        try:
            _check_plan(plan, g)
            slow = None
        except PlanError as e:
            slow = str(e)
        assert _plan_ok(plan, g) == (slow is None)
        try:
            validate_plan(plan, g)
            fast = None
        except PlanError as e:
            fast = str(e)
        assert fast == slow


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), backwards=st.booleans())
def test_deferred_coverage_equals_eager_writes(seed, backwards):
    """Belief's deferred coverage writes give the same coverage and block ages as writing every
    tick, including agents that hover (same field of view) and time going backwards."""
    from types import SimpleNamespace

    from fcplan import load_scenario
    from fcplan.belief import Belief, _coarse_box

    rng = np.random.default_rng(seed)
    sc = load_scenario("practice")
    belief = Belief(sc)
    n_a = len(sc.agents)
    w, c = sc.world_size, belief.coverage_px
    eager = np.full_like(belief.coverage, -1)
    fov = rng.uniform(0, w, (n_a, 4))
    empty = np.zeros(0, dtype=np.int64)
    tick = 0
    for step in range(60):
        moving = rng.random(n_a) < 0.4  # the others hover: the same rectangle as last tick
        centre = rng.uniform(-50, w + 50, (n_a, 2))
        half = rng.uniform(5, 80, (n_a, 2))
        new = np.stack(
            [
                centre[:, 0] - half[:, 0],
                centre[:, 0] + half[:, 0],
                centre[:, 1] - half[:, 1],
                centre[:, 1] + half[:, 1],
            ],
            axis=1,
        )
        fov = np.where(moving[:, None], new, fov)
        tick = tick - 7 if backwards and step == 30 else tick + 1
        belief.update(
            SimpleNamespace(tick=tick, sensed=empty, pruned=empty, fov_rects=fov.tolist())
        )
        for k in belief._sensing_rows:
            i0, i1, j0, j1 = _coarse_box(fov[k].tolist(), c, eager.shape[0])
            eager[i0:i1, j0:j1] = tick
        if step % 7 == 0:
            assert np.array_equal(belief.coverage, eager)
    assert np.array_equal(belief.coverage, eager)
    ref = Belief(sc)
    ref._coverage[...] = eager
    ref.tick = belief.tick
    assert np.array_equal(belief.coverage_age_s(100), ref.coverage_age_s(100))


def _writable_copy(g):
    """The same graph with every array field a fresh writable copy (no shared read-only arrays,
    no filled-in distance tables): the generic code paths."""
    import dataclasses

    fields = {
        f.name: (np.array(v) if isinstance(v := getattr(g, f.name), np.ndarray) else v)
        for f in dataclasses.fields(g)
    }
    return type(g)(**fields)


@settings(max_examples=10, deadline=None)
@given(name=st.sampled_from(["practice", "1", "24", "open_world_example"]), seed=st.integers(0, 9))
def test_shared_array_shortcuts_equal_the_generic_paths(name, seed):
    """On graphs of a TaskGraphBuilder (read-only per-team and fire-free task arrays, legality,
    task rows and capable-agent tables kept in their shared memo), candidates, masks and features
    are bit for bit those of the same graph with fresh writable arrays and no memo, with and
    without known fire."""
    from fcplan import World, load_scenario, make_scheduler
    from fcplan.belief import Belief
    from fcplan.plan import plan_commands
    from fcplan.taskgraph import TaskGraphBuilder

    world = World().reset(load_scenario(name), seed=seed)
    belief = Belief(world.scenario)
    builder = TaskGraphBuilder(world.scenario)
    sched = make_scheduler("greedy")
    goal = np.full((len(world.team.ids), 2), np.nan)
    goal[0] = (100.0, 200.0)
    commands = None
    for tick in range(1, 601):
        belief.update(world.step(commands))
        commands = None
        if tick % 10:
            continue
        g = builder.build(world.team, belief)
        commands = plan_commands(sched.plan(g, time_limit=None, rng=world.controller_rng), g)
        if tick % 50:
            continue
        for f in (g, builder.build(world.team, belief)):  # memo warm
            h = _writable_copy(f)
            assert f.shared_memo is not None and h.shared_memo is None
            a, b = rank_candidates(f, 6), rank_candidates(h, 6)
            for field in ("rows", "valid", "start_distance", "priority", "freshness", "legal"):
                assert np.array_equal(getattr(a, field), getattr(b, field)), field
            for x, y in (
                (task_features(f, a, goal), task_features(h, b, goal)),
                (agent_features(f, a, 0.3), agent_features(h, b, 0.3)),
            ):
                assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
