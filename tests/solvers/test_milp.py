"""Tests for the route model (solvers.milp_model) and its two backends (milp, milp-cvxpy)."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fcplan.plan import Plan, validate_plan
from fcplan.taskgraph import TaskGraph, TaskKind, synthetic_task_graph
from fcplan.team import Mode
from solvers.milp import MilpScheduler, solve_cpsat
from solvers.milp_cvxpy import MilpCvxpyScheduler, solve_cvxpy
from solvers.milp_model import (
    COVER,
    DUMP,
    FREEZE,
    ROUTE,
    SEARCH,
    WATCH,
    MilpParams,
    brute_force_optimum,
    build_milp_model,
    decode_plan,
    plan_objective,
)
from solvers.milp_model.routes import agent_roles
from solvers.milp_model.sensing import best_search_altitude, detection_probability, segment_coverage
from tests.solvers.graphs import SCENARIOS
from tests.solvers.graphs import episode_graphs as _episode_graphs

TICKS = (0, 100, 300, 600)
BACKENDS = (solve_cpsat, solve_cvxpy)
SCHEDULERS = (MilpScheduler, MilpCvxpyScheduler)
#: candidate counts small enough for the brute force
TINY = dict(fire_candidates=3, search_candidates=3, watch_candidates=2)


def episode_graphs(name) -> tuple[TaskGraph, ...]:
    """Task graphs at :data:`TICKS` of a greedy episode."""
    return _episode_graphs(name, TICKS)


def milp_plan(g: TaskGraph, backend=MilpScheduler, **settings) -> Plan:
    return backend(**settings).plan(g, time_limit=None, rng=np.random.default_rng(0))


def random_graph(seed: int, n_agents: int, n_tasks: int, **kw) -> TaskGraph:
    return synthetic_task_graph(n_agents, n_tasks, np.random.default_rng(seed), **kw)


def check_plan(g: TaskGraph, plan: Plan, params: MilpParams | None = None) -> None:
    """validate_plan plus the model's own rules (roles, one dump per fire task, one watcher per
    connected fire, tank, route lengths, the whole route flyable)."""
    p = params or MilpParams()
    validate_plan(plan, g)
    roles = agent_roles(g)
    dumped: set[str] = set()
    watched: set[int] = set()
    heading: set[str] = set()
    for a, route in plan.routes.items():
        i = g.agent_index[a]
        assert 0 < len(route) <= max(p.slots, p.search_slots)
        assert len(set(route)) == len(route), f"{a} visits a task twice"
        kinds = {g.task_kind[g.task_index[t]] for t in route}
        assert len(kinds) == 1, f"{a} mixes fires and search blocks"
        if kinds == {TaskKind.SEARCH}:
            assert g.agent_can_sense[i] and len(route) <= p.search_slots
            assert route[0] not in heading, f"two searchers head for {route[0]}"
            heading.add(route[0])
            t_first = g.start_task_distance[i, g.task_index[route[0]]] / g.agent_speed[i]
            assert t_first <= agent_roles(g).t0[i] + p.search_reach_s + 1e-9
        elif roles.dumper[i]:
            assert len(route) <= min(p.slots, roles.tank[i])
            assert not dumped & set(route), f"{a} dumps where another agent dumps"
            dumped |= set(route)
        else:
            assert g.agent_can_sense[i] and len(route) == 1, f"{a} watches more than one fire"
            cl = int(g.task_cluster[g.task_index[route[0]]])
            assert cl not in watched, f"connected fire {cl} watched twice"
            watched.add(cl)
        need, have = g.route_length_px(i, route), g.agent_budget_px[i]
        assert g.route_ok(i, route), f"{a}: route + way home {need:.1f} px > {have:.1f} px"


# ---------------------------------------------------------------------------------------- optimum
@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_agents=st.integers(2, 3),
    n_tasks=st.integers(1, 6),
    fire_share=st.sampled_from([0.0, 0.5, 0.8, 1.0]),
    slots=st.integers(1, 2),
    search_slots=st.integers(1, 2),
    growth=st.sampled_from([0.0, 2.0, 20.0]),
)
def test_backends_match_brute_force(
    seed, n_agents, n_tasks, fire_share, slots, search_slots, growth
):
    """On small random task graphs (up to 3 agents x 6 tasks; with and without the growth
    term) CP-SAT and cvxpy/HiGHS both reach the brute-force optimum of the same model (to
    1e-6), their solutions are feasible, their bounds are proven, and the decoded plans pass
    validate_plan and the model's rules."""
    g = random_graph(seed, n_agents, n_tasks, fire_share=fire_share)
    params = MilpParams(slots=slots, search_slots=search_slots, growth_cells_s=growth, **TINY)
    model = build_milp_model(g, params)
    _, best = brute_force_optimum(model)
    for backend in BACKENDS:
        x, stats = backend(model)
        assert model.is_feasible(x)
        assert stats.status == "optimal"
        assert model.objective(x) == pytest.approx(best, abs=1e-6, rel=1e-9)
        assert stats.objective == pytest.approx(best, abs=1e-6, rel=1e-9)
        # CP-SAT scales real objective coefficients: its bound may be loose by its precision
        assert best - 1e-6 <= stats.bound <= best + 1e-4 * max(1.0, abs(best))
        check_plan(g, decode_plan(model, x, g), params)


def test_model_arrays_are_consistent():
    """The model is a plain array problem: one column per variable (routes, then covers, then
    freezes), integral rows and bounds, role-compatible routes, and all-zero is feasible."""
    g = random_graph(3, 3, 8)
    m = build_milp_model(g)
    assert m.A_ub.shape == (m.n_rows, m.n_vars) == (len(m.row_kind), m.c.size)
    assert np.all(m.A_ub.data == np.round(m.A_ub.data)) and np.all(m.b_ub == np.round(m.b_ub))
    assert np.all(m.ub == np.round(m.ub)) and m.is_feasible(np.zeros(m.n_vars))
    kinds = m.var_kind
    assert np.all(np.diff(kinds) >= 0), "routes, then covers, then freezes"
    assert (kinds == ROUTE).sum() == m.n_routes
    assert np.all(m.ub[kinds == COVER] == m.params.cover_levels)
    assert np.all(m.ub[kinds != COVER] == 1)
    roles = agent_roles(g)
    for r in range(m.n_routes):
        a, tasks = m.route_agent[r], m.route_tasks[r][m.route_tasks[r] >= 0]
        fire = g.task_kind[tasks] == TaskKind.FIRE
        if m.route_kind[r] == SEARCH:
            assert g.agent_can_sense[a] and not fire.any()
        elif m.route_kind[r] == DUMP:
            assert roles.dumper[a] and fire.all()
        else:
            assert m.route_kind[r] == WATCH and g.agent_can_sense[a] and fire.all()
            assert not roles.dumper[a] and tasks.size == 1
    assert m.size["variables"] == m.n_vars and m.size["constraints"] == m.n_rows


# ---------------------------------------------------------------------------------------- routes
@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), low=st.floats(0.05, 1.0), returning=st.booleans())
def test_routes_have_exact_arrivals_and_fit_the_battery(seed, low, returning):
    """Every enumerated route starts at the agent's start (its depot slot after a forced return,
    reached first), has arrival times equal to the flown distance over the agent's own speed and
    a length equal to TaskGraph.route_length_px, fits the battery (route_ok), holds no task
    twice and no more dumps than the tank."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(3, 7, rng)
    mode = np.where(rng.random(3) < 0.5 * returning, Mode.RETURNING, Mode.ACTIVE).astype(np.int8)
    g = dataclasses.replace(
        g,
        agent_battery=g.agent_battery * low,
        agent_mode=mode,
        agent_speed=rng.uniform(100.0, 300.0, 3),
        agent_tank=np.minimum(g.agent_tank, 2),
    )
    m = build_milp_model(g)
    roles = agent_roles(g)
    for r in range(m.n_routes):
        a = int(m.route_agent[r])
        tasks = m.route_tasks[r][m.route_tasks[r] >= 0].tolist()
        assert len(set(tasks)) == len(tasks)
        pts = np.vstack([g.agent_start_pos[a], g.task_pos[tasks]])
        away = np.hypot(*(g.agent_pos[a] - g.agent_start_pos[a]))
        want = (away + np.cumsum(np.hypot(*np.diff(pts, axis=0).T))) / g.agent_speed[a]
        assert m.route_arrival[r][: len(tasks)] == pytest.approx(want, rel=1e-12)
        assert m.route_length[r] == pytest.approx(g.route_length_px(a, tasks), rel=1e-12)
        assert g.route_ok(a, tasks)
        if m.route_kind[r] == DUMP:
            assert len(tasks) <= roles.tank[a]


def test_every_flyable_sequence_of_candidates_is_a_route():
    """With every task a candidate, the dump routes of an action agent are exactly the sequences
    of its fire tasks (up to the slot count and its tank) that fit its battery: none is missing,
    none is extra."""
    g = random_graph(7, 3, 5, fire_share=1.0, perception_share=0.0)
    g = dataclasses.replace(g, agent_battery=g.agent_battery * 0.4, agent_tank=np.array([0, 2, 3]))
    p = MilpParams(slots=3, fire_candidates=5)
    m = build_milp_model(g, p)
    roles = agent_roles(g)
    assert roles.dumper.tolist() == [False, True, True]
    for a in (1, 2):
        ks = [k for k in range(g.n_tasks) if roles.ok1[a, k]]
        want = {
            seq
            for n in range(1, min(3, roles.tank[a]) + 1)
            for seq in itertools.permutations(ks, n)
            if g.route_length_px(a, seq) <= g.agent_budget_px[a]
        }
        got = {
            tuple(t[t >= 0].tolist())
            for t, who in zip(m.route_tasks, m.route_agent, strict=True)
            if who == a
        }
        assert got == want


# ---------------------------------------------------------------------------------------- values
def hand_graph(*, watcher: Mode = Mode.ACTIVE, n_fires: int = 1, n_search: int = 0) -> TaskGraph:
    """P1 (perception) and A2 (action) near ``n_fires`` fire tasks of one connected fire at
    (600, 600), plus ``n_search`` search blocks; ``watcher`` is P1's mode."""
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
        task_staleness=np.where(fire, 30.0, 20.0),
        task_threat=np.zeros(n),
        task_cluster=np.where(fire, 0, -1).astype(np.int64),
        threat_time_s=np.full((n, 1), np.inf),
    )


def test_dump_value_is_cells_times_rate_times_time_left():
    """A one-task dump route is worth q n_k (0.1 + threat) (H - t) with t the exact arrival
    time; a threatened facility raises the rate by its penalty times the share of the horizon
    left after the fire reaches it."""
    g = hand_graph()
    p = MilpParams(horizon_s=30.0, growth_cells_s=0.0)
    m = build_milp_model(g, p)
    one = np.flatnonzero((m.route_kind == DUMP) & (m.route_tasks[:, 1] < 0))[0]
    t = 200.0 / g.agent_speed[1]  # A2 at (400, 600), the fire at (600, 600)
    assert m.route_arrival[one, 0] == pytest.approx(t)
    assert m.route_value[one] == pytest.approx(0.9 * 40 * 0.1 * (30.0 - t))
    threatened = dataclasses.replace(g, threat_time_s=np.array([[6.0]]))
    m2 = build_milp_model(threatened, p)
    pc = float(g.facility_penalty[0])
    want = 0.9 * 40 * (0.1 + pc * (1.0 - 6.0 / 30.0)) * (30.0 - t)
    assert m2.route_value[one] == pytest.approx(want)


def test_growth_is_stopped_only_when_watched_and_dumped():
    """The freeze variable of a connected fire can be 1 only with a dump route on it and a
    route watching it; with both, the optimum sends P1 to watch (low) while A2 dumps."""
    g = hand_graph(n_fires=2)
    m = build_milp_model(g, MilpParams(growth_cells_s=5.0))
    freeze = np.flatnonzero(m.var_kind == FREEZE)
    assert freeze.size == 1
    dump = np.flatnonzero(m.route_kind == DUMP)[0]
    watch = np.flatnonzero(m.route_kind == WATCH)[0]
    for chosen, ok in (((), False), ((dump,), False), ((watch,), False), ((dump, watch), True)):
        x = np.zeros(m.n_vars)
        x[list(chosen)] = 1.0
        x[freeze] = 1.0
        assert m.is_feasible(x) == ok, chosen
    for backend in SCHEDULERS:
        plan = milp_plan(g, backend, growth_cells_s=5.0)
        check_plan(g, plan)
        assert plan.routes["P1"][0] in g.task_ids[:2]
        assert plan.altitudes["P1"] == pytest.approx(MilpParams().watch_altitude)
        assert set(plan.routes["A2"]) <= set(g.task_ids[:2])


def test_without_a_watcher_the_fire_is_still_dumped_on():
    """Known cells are sensed, so they can be put out without a watcher: with P1 away (sent
    home, and too far to come back) A2 still dumps on the fire."""
    g = hand_graph()
    g = dataclasses.replace(g, agent_battery=np.array([1.0, 500.0]))
    for backend in SCHEDULERS:
        plan = milp_plan(g, backend)
        assert plan.routes.get("A2") == (g.task_ids[0],)
        assert "P1" not in plan.routes


def test_tank_limits_dumps():
    """With many fires, three slots and a tank of 1 or 2, no action agent gets more fire tasks
    than its tank, and each action agent gets at least one."""
    for tank in (1, 2):
        g = random_graph(5, 4, 8, fire_share=1.0, perception_share=0.25)
        g = dataclasses.replace(
            g,
            agent_tank=np.where(g.agent_can_act, tank, 0).astype(np.int64),
            agent_battery=np.full(g.n_agents, 500.0),
        )
        for backend in SCHEDULERS:
            plan = milp_plan(g, backend, slots=3)
            check_plan(g, plan, MilpParams(slots=3))
            for i, a in enumerate(g.agent_ids):
                if g.agent_can_act[i]:
                    assert 1 <= len(plan.routes.get(a, ())) <= tank


# ---------------------------------------------------------------------------------------- search
def test_search_altitude_maximises_the_detection_rate():
    """For the manual's perception agents (10..100 m, 200 px/s) the best search altitude is the
    highest: the swath grows with z faster than the confidence falls; with equal bounds it is
    that altitude. The detection probability is 1 - (1 - c) ** (draws in view)."""
    assert best_search_altitude(10.0, 100.0, 200.0) == 100.0
    assert best_search_altitude(40.0, 40.0, 200.0) == 40.0
    # along y the view is 2 tan(pi/6) z long: 5.77 draws at z = 100, confidence 0.4
    p = detection_probability(100.0, 10.0, 100.0, 200.0, np.array([0.0, 1.0]))
    assert p == pytest.approx(1.0 - 0.6 ** (2 * math.tan(math.pi / 6) * 100.0 / 20.0))


def test_segment_coverage_of_blocks():
    """A straight flight through a block's centre covers all of it (share = detection
    probability) unless it ends before the block; a block beyond the swath gets nothing; a
    block half in the swath gets half; the passing time is the distance along the track over
    the speed."""
    p = np.array([[0.0, 500.0]])
    q = np.array([[1000.0, 500.0]])
    centres = np.array([[500.0, 500.0], [500.0, 900.0], [500.0, 500.0 + 57.735]])
    share, when = segment_coverage(p, q, centres, 100.0, 100.0, 10.0, 100.0, 200.0)
    prob = detection_probability(100.0, 10.0, 100.0, 200.0, np.array([1.0, 0.0]))
    assert share[0] == pytest.approx([prob, 0.0, prob / 2], abs=1e-3)
    assert when[0, 0] == pytest.approx(2.5)


def test_overlapping_sweeps_count_once():
    """At the start of #12 (three perception agents at the depot, every block unexplored) the
    agents fly off toward three different blocks, and the team's value is below the sum of
    what each agent would find alone (a block found twice counts once)."""
    g = episode_graphs(12)[0]
    m = build_milp_model(g)
    x, stats = solve_cpsat(m)
    plan = decode_plan(m, x, g)
    sensors = [a for i, a in enumerate(g.agent_ids) if g.agent_can_sense[i]]
    assert len({plan.routes[a][0] for a in sensors}) == len(sensors) == 3
    alone = 0.0
    for a in sensors:
        others_away = np.array(
            [b not in (a,) and g.agent_can_sense[i] for i, b in enumerate(g.agent_ids)]
        )
        solo = dataclasses.replace(g, agent_battery=np.where(others_away, 0.0, g.agent_battery))
        alone += solve_cpsat(build_milp_model(solo))[1].objective
    assert stats.objective < alone


# ---------------------------------------------------------------------------------------- real graphs
@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), low=st.floats(0.02, 0.4))
@example(
    seed=140, low=0.125
)  # a model with no auxiliary: the warm start once indexed an empty array
def test_battery_keeps_whole_routes_flyable(seed, low):
    """With low batteries (some agents on a forced return), every planned route, flown in order
    from the agent's start and back home, fits its battery."""
    rng = np.random.default_rng(seed)
    g = synthetic_task_graph(3, 6, rng)
    mode = np.where(rng.random(3) < 0.3, Mode.RETURNING, Mode.ACTIVE).astype(np.int8)
    g = dataclasses.replace(g, agent_battery=g.agent_battery * low, agent_mode=mode)
    for backend in SCHEDULERS:
        check_plan(g, milp_plan(g, backend))


@pytest.mark.parametrize("name", SCENARIOS)
def test_plans_on_shipped_scenarios_are_valid(name):
    """On graphs from every shipped scenario both backends' plans validate and keep the model's
    rules, with status optimal and the same objective."""
    for g in episode_graphs(name):
        plans = [milp_plan(g, b) for b in SCHEDULERS]
        for plan in plans:
            check_plan(g, plan)
            assert plan.stats.status == "optimal"
        assert plans[0].stats.objective == pytest.approx(plans[1].stats.objective, abs=1e-6)


def test_decoded_routes_follow_route_order_and_altitudes():
    """A chosen route becomes its agent's route in visiting order; camera agents fly the
    route's altitude (watch altitude on fires, the search altitude on blocks), clipped to their
    bounds; agents without a chosen route are not mentioned."""
    g = random_graph(11, 3, 6)
    m = build_milp_model(g, MilpParams(**TINY))
    x, _ = brute_force_optimum(m)
    plan = decode_plan(m, x, g)
    chosen = np.flatnonzero(x[: m.n_routes] > 0.5)
    assert set(plan.routes) == {g.agent_ids[a] for a in m.route_agent[chosen]}
    for r in chosen:
        a = g.agent_ids[m.route_agent[r]]
        tasks = m.route_tasks[r]
        assert plan.routes[a] == tuple(g.task_ids[k] for k in tasks[tasks >= 0])
        i = g.agent_index[a]
        if g.agent_can_sense[i]:
            want = MilpParams().watch_altitude if m.route_kind[r] != SEARCH else 100.0
            assert plan.altitudes[a] == pytest.approx(g.clip_altitude(i, want))


def test_hybrids_dump_from_the_top_of_their_bounds():
    """A hybrid with water flies its dump routes at the top of its altitude bounds (a dump puts
    out every sensed burning cell in view, and the view grows with the altitude), or at
    ``dump_altitude`` when set; with an empty tank its fire routes are watches, at the watch
    altitude. Perception agents watch at the watch altitude either way."""
    g = next(g for g in episode_graphs("open_world_example") if g.fire_tasks.size)
    hybrids = np.flatnonzero(g.agent_can_act & g.agent_can_sense & (g.agent_tank > 0))
    assert hybrids.size
    for dump_z in (None, 40.0):
        m = build_milp_model(g, MilpParams(dump_altitude=dump_z))
        for a in hybrids.tolist():
            want = g.agent_alt_range[a][1] if dump_z is None else g.clip_altitude(a, dump_z)
            dumps = (m.route_agent == a) & (m.route_kind == DUMP)
            assert dumps.any() and np.allclose(m.altitude[dumps], want)
        watchers = (m.route_kind == WATCH) & ~g.agent_can_act[m.route_agent]
        z = np.array([g.clip_altitude(a, 35.0) for a in m.route_agent[watchers].tolist()])
        assert np.allclose(m.altitude[watchers], z)
    dry = dataclasses.replace(g, agent_tank=np.where(g.agent_can_sense, 0, g.agent_tank))
    m = build_milp_model(dry, MilpParams())
    for a in hybrids.tolist():
        fire_routes = (m.route_agent == a) & (m.route_kind != SEARCH)
        assert not ((m.route_agent == a) & (m.route_kind == DUMP)).any()
        assert np.allclose(m.altitude[fire_routes], g.clip_altitude(a, 35.0))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_plan_objective_scores_other_schedulers_below_the_optimum(seed):
    """plan_objective gives the MILP's own optimal plan its objective, and no feasible plan of
    another scheduler scores above the MILP optimum when every task is a candidate."""
    from fcplan.scheduling import make_scheduler

    g = synthetic_task_graph(3, 8, np.random.default_rng(seed))
    full = dict(fire_candidates=8, search_candidates=8, watch_candidates=8)
    best = make_scheduler("milp", **full).plan(g, time_limit=None, rng=None)
    params = MilpParams(**full)
    obj, ok = plan_objective(g, best, params)
    assert ok and obj == pytest.approx(best.stats.objective, rel=1e-9, abs=1e-9)
    for name in ("greedy", "random", "cbba"):
        other = make_scheduler(name).plan(g, time_limit=None, rng=np.random.default_rng(seed))
        o, feasible = plan_objective(g, other, params)
        if feasible:
            assert o <= obj + 1e-6 * max(1.0, abs(obj))
