"""Tests for the assignment MILP (solvers.milp_model) and its two backends (milp, milp-cvxpy)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import fcplan
from fcplan.plan import Plan, validate_plan
from fcplan.scheduling import STATUSES, make_scheduler, solve
from fcplan.taskgraph import TaskGraph, TaskKind, synthetic_task_graph
from fcplan.team import Mode
from solvers.milp import MilpScheduler, solve_cpsat
from solvers.milp_cvxpy import MilpCvxpyScheduler, solve_cvxpy
from solvers.milp_model import (
    AUX,
    DUMP,
    SEARCH,
    WATCH,
    MilpParams,
    brute_force_optimum,
    build_milp_model,
    decode_plan,
)
from tests.solvers.graphs import SCENARIOS
from tests.solvers.graphs import episode_graphs as _episode_graphs

TICKS = (0, 100, 300, 600)
BACKENDS = (solve_cpsat, solve_cvxpy)


def episode_graphs(name) -> tuple[TaskGraph, ...]:
    """Task graphs at :data:`TICKS` of a greedy episode."""
    return _episode_graphs(name, TICKS)


def milp_plan(g: TaskGraph, backend=MilpScheduler, **settings) -> Plan:
    return backend(**settings).plan(g, time_limit=10.0, rng=np.random.default_rng(0))


def check_plan(g: TaskGraph, plan: Plan, params: MilpParams | None = None) -> None:
    """validate_plan plus the model's own rules (roles, once per kind, tank, whole route fits)."""
    p = params or MilpParams()
    validate_plan(plan, g)
    dumped: set[str] = set()
    watched: set[str] = set()
    searched: set[str] = set()
    for a, route in plan.routes.items():
        i = g.agent_index[a]
        assert g.agent_mode[i] != Mode.HOMING, f"{a} is homing but routed"
        assert 0 < len(route) <= p.slots
        assert len(set(route)) == len(route), f"{a} visits a task twice"
        kinds = [g.task_kind[g.task_index[t]] for t in route]
        tank = g.agent_tank_capacity[i] if g.agent_mode[i] == Mode.RETURNING else g.agent_tank[i]
        dumps = g.agent_can_act[i] and tank > 0
        n_fire = 0
        for t, k in zip(route, kinds, strict=True):
            if k == TaskKind.SEARCH:
                assert g.agent_can_sense[i]
                assert t not in searched
                searched.add(t)
            elif dumps:
                assert t not in dumped, f"{t} dumped twice"
                dumped.add(t)
                n_fire += 1
            else:
                assert g.agent_can_sense[i], f"{a} can neither dump nor watch {t}"
                assert t not in watched, f"{t} watched twice"
                watched.add(t)
        assert n_fire <= tank, f"{a}: {n_fire} fires for tank {tank}"
        need, have = g.route_length_px(i, route), g.agent_budget_px[i]
        assert g.route_ok(i, route), f"{a}: route + way home {need:.1f} px > {have:.1f} px"


def random_graph(seed: int, n_agents: int, n_tasks: int, **kw) -> TaskGraph:
    return synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(seed), **kw)


# ---------------------------------------------------------------------------------------- optimum
@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 3),
    n_tasks=st.integers(1, 6),
    fire_share=st.sampled_from([0.0, 0.5, 0.8, 1.0]),
    slots=st.integers(1, 2),
    fresh_s=st.sampled_from([1.0, 5.0, 10.0]),
    support=st.sampled_from([0.0, 3.0]),
)
def test_backends_match_brute_force(seed, n_agents, n_tasks, fire_share, slots, fresh_s, support):
    """On small random task graphs (up to 3 agents x 6 tasks; fires stale or fresh, with and
    without the support bonus) CP-SAT and cvxpy/HiGHS both reach the brute-force optimum of the
    same model (to 1e-6), their solutions are feasible, they agree with each other, and the decoded
    plans pass validate_plan and the model's rules."""
    g = random_graph(seed, n_agents, n_tasks, fire_share=fire_share)
    params = MilpParams(slots=slots, fresh_s=fresh_s, support_weight=support)
    model = build_milp_model(g, params)
    _, best = brute_force_optimum(model)
    objs = []
    for backend in BACKENDS:
        x, stats = backend(model, time_limit=10.0)
        assert model.is_feasible(x)
        assert stats.status == "optimal"
        assert model.objective(x) == pytest.approx(best, abs=1e-6, rel=1e-9)
        assert stats.objective == pytest.approx(best, abs=1e-6, rel=1e-9)
        # a proven bound: CP-SAT scales real objective coefficients, so its bound may be loose
        # by its working precision (relative 1e-4 at most here)
        assert best - 1e-6 <= stats.bound <= best + 1e-4 * max(1.0, abs(best))
        objs.append(model.objective(x))
        check_plan(g, decode_plan(model, x, g), params)
    assert objs[0] == pytest.approx(objs[1], abs=1e-6)


def test_model_arrays_are_consistent():
    """The model is a plain array problem: one column per variable, every variable binary with a
    role-compatible (agent, task, slot), integral rows, and all-zero is feasible."""
    g = random_graph(3, 3, 6)
    m = build_milp_model(g)
    assert m.A_ub.shape == (m.n_rows, m.n_vars) == (len(m.row_kind), m.c.size)
    assert np.all(m.integrality == 1)
    assert np.all(m.A_ub.data == np.round(m.A_ub.data)) and np.all(m.b_ub == np.round(m.b_ub))
    assert m.is_feasible(np.zeros(m.n_vars))
    prim = m.var_kind != AUX
    a, k = m.var_agent[prim], m.var_task[prim]
    kind = m.var_kind[prim]
    fire = g.task_kind[k] == TaskKind.FIRE
    assert np.all(g.agent_can_sense[a[kind == SEARCH]]) and not fire[kind == SEARCH].any()
    assert np.all(g.agent_can_act[a[kind == DUMP]]) and fire[kind == DUMP].all()
    assert np.all(g.agent_can_sense[a[kind == WATCH]]) and fire[kind == WATCH].all()
    assert np.all((m.var_slot >= 0) & (m.var_slot < m.params.slots))
    assert m.size["variables"] == m.n_vars and m.size["constraints"] == m.n_rows


# ---------------------------------------------------------------------------------------- coupling
def hand_graph(
    *, stale: bool, watcher: Mode = Mode.ACTIVE, n_fires: int = 1, n_search: int = 0
) -> TaskGraph:
    """P1 (perception) and A2 (action) near ``n_fires`` fire tasks of one connected fire at
    (600, 600), plus ``n_search`` search blocks; ``watcher`` is P1's mode (HOMING: unavailable)."""
    n = n_fires + n_search
    g = synthetic_task_graph(2, n, np.random.default_rng(0), fire_share=n_fires / n)
    fire = np.arange(n) < n_fires
    pos = np.array([[600.0 + 40.0 * i, 600.0 if f else 400.0] for i, f in enumerate(fire)])
    return dataclasses.replace(
        g,
        agent_pos=np.array([[500.0, 500.0], [400.0, 600.0]]),
        agent_battery=np.full(2, 500.0),
        agent_mode=np.array([int(watcher), int(Mode.ACTIVE)], dtype=np.int8),
        task_pos=pos,
        task_value=np.where(fire, 40.0, 10.0),
        task_cells=np.where(fire, 40, 0).astype(np.int64),
        task_staleness=np.where(fire, 30.0 if stale else 0.0, 20.0),
        task_threat=np.zeros(n),
        task_cluster=np.where(fire, 0, -1).astype(np.int64),
    )


def test_stale_fire_without_watcher_is_worth_nothing():
    """A stale fire with no perception agent available is worth nothing to an action agent: the
    optimum is 0 and A2 is not sent; both backends agree."""
    g = hand_graph(stale=True, watcher=Mode.HOMING)
    m = build_milp_model(g)
    assert (m.var_kind == DUMP).any()
    dump_only = (m.var_kind == DUMP) & (m.var_slot == 0)
    x = dump_only.astype(np.float64)
    x[(m.var_kind == AUX) & (m.var_slot == 0)] = 1.0
    assert not m.is_feasible(x)  # z cannot be 1 without a watcher
    assert m.objective(dump_only.astype(float)) <= 0.0
    for backend in (MilpScheduler, MilpCvxpyScheduler):
        plan = milp_plan(g, backend)
        assert plan.stats.objective == pytest.approx(0.0, abs=1e-9)
        assert "A2" not in plan.routes


def test_fresh_fire_needs_no_watcher():
    """A freshly sensed fire is dumped on even when no perception agent is available."""
    g = hand_graph(stale=False, watcher=Mode.HOMING)
    for backend in (MilpScheduler, MilpCvxpyScheduler):
        plan = milp_plan(g, backend)
        assert plan.routes.get("A2") == (g.task_ids[0],)
        assert plan.stats.objective > 0


@pytest.mark.parametrize("stale", [True, False])
def test_available_perception_agent_watches_the_fire_being_dumped(stale):
    """With a perception agent available, the optimum sends it to watch the fire (low altitude,
    in a slot no later than the dump) while the action agent dumps."""
    g = hand_graph(stale=stale)
    for backend in (MilpScheduler, MilpCvxpyScheduler):
        plan = milp_plan(g, backend)
        check_plan(g, plan)
        fire = g.task_ids[0]
        assert plan.routes.get("A2") == (fire,)
        assert plan.routes.get("P1", ())[:1] == (fire,)
        assert plan.altitudes["P1"] == pytest.approx(MilpParams().watch_altitude)


def test_watch_counts_on_same_cluster_and_earlier_slots_only():
    """A stale fire's dump may earn its value (z = 1) with a watcher on another fire task of the
    same connected fire in the same or an earlier slot, not with one in a later slot, on another
    connected fire, or with none."""
    g = hand_graph(stale=True, n_fires=2, n_search=1)
    m = build_milp_model(g)

    def vector(*picks):
        x = np.zeros(m.n_vars)
        for kind, agent, task, slot in picks:
            hit = (m.var_kind == kind) & (m.var_task == task) & (m.var_slot == slot)
            if kind != AUX:
                hit &= m.var_agent == agent
            assert hit.sum() == 1, (kind, agent, task, slot)
            x[hit] = 1.0
        return x

    P1, A2 = 0, 1
    same_slot = vector((WATCH, P1, 1, 0), (DUMP, A2, 0, 0), (AUX, -1, 0, 0))
    assert m.is_feasible(same_slot)
    earlier = vector((WATCH, P1, 1, 0), (DUMP, A2, 1, 0), (DUMP, A2, 0, 1), (AUX, -1, 0, 1))
    assert m.is_feasible(earlier)
    later = vector((SEARCH, P1, 2, 0), (WATCH, P1, 1, 1), (DUMP, A2, 0, 0), (AUX, -1, 0, 0))
    assert not m.is_feasible(later)
    assert m.is_feasible(later - vector((AUX, -1, 0, 0)))
    assert not m.is_feasible(vector((DUMP, A2, 0, 0), (AUX, -1, 0, 0)))
    # the same watcher on another connected fire does not count
    g2 = dataclasses.replace(g, task_cluster=np.array([0, 1, -1], dtype=np.int64))
    m = build_milp_model(g2)
    assert not m.is_feasible(vector((WATCH, P1, 1, 0), (DUMP, A2, 0, 0), (AUX, -1, 0, 0)))


# ---------------------------------------------------------------------------------------- tank, battery
@pytest.mark.parametrize("tank", [1, 2])
def test_tank_limits_dumps(tank):
    """With many fresh fires, three slots and small tanks, no action agent gets more fire tasks
    than its tank; with tank 1 each action agent still gets one fire."""
    g = random_graph(5, 4, 8, fire_share=1.0, perception_share=0.25)
    g = dataclasses.replace(
        g,
        agent_tank=np.where(g.agent_can_act, tank, 0).astype(np.int64),
        task_staleness=np.zeros(g.n_tasks),
        agent_battery=np.full(g.n_agents, 500.0),
    )
    params = MilpParams(slots=3)
    for backend in (MilpScheduler, MilpCvxpyScheduler):
        plan = milp_plan(g, backend, slots=3)
        check_plan(g, plan, params)
        fires = {g.task_ids[k] for k in g.fire_tasks}
        for i, a in enumerate(g.agent_ids):
            if g.agent_can_act[i]:
                n = len(set(plan.routes.get(a, ())) & fires)
                assert 1 <= n <= tank


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), low=st.floats(0.02, 0.4))
def test_battery_keeps_whole_routes_flyable(seed, low):
    """With low batteries (some agents on a forced return), every planned route, flown in order
    from the agent's start and back home, fits its battery (the triangle-inequality bound)."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(3, 6, rng)
    mode = np.where(rng.random(3) < 0.3, Mode.RETURNING, Mode.ACTIVE).astype(np.int8)
    g = dataclasses.replace(g, agent_battery=g.agent_battery * low, agent_mode=mode)
    for backend in (MilpScheduler, MilpCvxpyScheduler):
        check_plan(g, milp_plan(g, backend, slots=2))


# ---------------------------------------------------------------------------------------- real graphs
@pytest.mark.parametrize("name", SCENARIOS)
def test_plans_on_shipped_scenarios_are_valid(name):
    """On graphs from every shipped scenario both backends' plans validate and keep the model's
    rules (roles, tank, whole-route battery), with status optimal and the same objective."""
    for g in episode_graphs(name):
        plans = [milp_plan(g, b) for b in (MilpScheduler, MilpCvxpyScheduler)]
        for plan in plans:
            check_plan(g, plan)
            assert plan.stats.status == "optimal"
        assert plans[0].stats.objective == pytest.approx(plans[1].stats.objective, abs=1e-6)


@pytest.mark.parametrize("name", [1, 12, 24, "open_world_example"])
def test_deterministic(name):
    """The same graph gives the same plan (routes and altitudes), whatever the generator, for
    both backends (single thread, fixed solver seed)."""
    for g in episode_graphs(name):
        for backend in (MilpScheduler, MilpCvxpyScheduler):
            # a generous limit: the solvers are deterministic when they finish (one thread,
            # fixed seed); only a wall-clock limit hit under load could change the answer
            a = backend().plan(g, time_limit=10.0, rng=np.random.default_rng(1))
            b = backend().plan(g, time_limit=10.0, rng=np.random.default_rng(2))
            assert dict(a.routes) == dict(b.routes)
            assert dict(a.altitudes) == dict(b.altitudes)


def test_decoded_routes_follow_slots_and_altitudes():
    """Routes list tasks in slot order; camera agents fly low when their route starts at a fire
    and high when it starts at a search block; agents without a task are not mentioned."""
    g = random_graph(11, 3, 6)
    m = build_milp_model(g)
    x, _ = brute_force_optimum(m)
    plan = decode_plan(m, x, g)
    chosen = np.flatnonzero((x > 0.5) & (m.var_kind != AUX))
    for a, route in plan.routes.items():
        i = g.agent_index[a]
        rows = chosen[m.var_agent[chosen] == i]
        assert route == tuple(g.task_ids[k] for k in m.var_task[rows[np.argsort(m.var_slot[rows])]])
        if g.agent_can_sense[i]:
            first = g.task_kind[g.task_index[route[0]]]
            want = m.params.watch_altitude if first == TaskKind.FIRE else m.params.search_altitude
            lo, hi = g.agent_alt_range[i]
            assert plan.altitudes[a] == pytest.approx(min(max(want, lo), hi))
    assert set(plan.routes) == {g.agent_ids[i] for i in np.unique(m.var_agent[chosen])}


# ---------------------------------------------------------------------------------------- limits, episodes
@pytest.mark.parametrize("name", ["milp", "milp-cvxpy"])
def test_tiny_time_limit_gives_valid_plan_or_recorded_fallback(name):
    """With a 1 ms limit, fcplan.scheduling.solve returns a valid plan: the solver's own (any
    status) or greedy's with status 'fallback' and the reason recorded."""
    sched = make_scheduler(name)
    for g in episode_graphs(24) + episode_graphs("open_world_example"):
        plan = solve(sched, g, time_limit=0.001, rng=np.random.default_rng(0))
        validate_plan(plan, g)
        assert plan.stats.status in STATUSES
        if plan.stats.status == "fallback":
            assert plan.stats.message


@pytest.mark.parametrize("name", ["milp", "milp-cvxpy"])
def test_episode_completes_and_prunes_fire(name):
    """A whole episode of scenario #1 runs with the scheduler, and the team puts fire out."""
    result = fcplan.run_episode(1, name, seed=0)
    assert result.ticks == load_ticks(1)
    assert len(result.solves) > 0
    assert result.trace.pruned[-1] > 0
    assert result.metrics["manual"].overall_firefighting > 0
    assert any(s.status == "optimal" for s in result.solves)


def load_ticks(name) -> int:
    return fcplan.load_scenario(name).n_ticks


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_plan_objective_scores_other_schedulers_below_the_optimum(seed):
    """plan_objective gives the MILP's own optimal plan its objective, and no feasible plan of
    another scheduler scores above the MILP optimum."""
    from fcplan.scheduling import make_scheduler
    from solvers.milp_model import plan_objective

    g = synthetic_task_graph(3, 8, np.random.default_rng(seed))
    best = make_scheduler("milp", fire_candidates=g.n_tasks, search_candidates=g.n_tasks).plan(
        g, time_limit=10.0, rng=None
    )
    obj, ok = plan_objective(g, best)
    assert ok and obj == pytest.approx(best.stats.objective, rel=1e-5, abs=1e-6)
    for name in ("greedy", "random", "cbba"):
        other = make_scheduler(name).plan(g, time_limit=None, rng=np.random.default_rng(seed))
        o, feasible = plan_objective(g, other)
        if feasible:
            assert o <= obj + 1e-6 * max(1.0, abs(obj))
