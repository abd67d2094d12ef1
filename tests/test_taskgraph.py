"""Tests for fcplan.taskgraph: dump-sized fire tiles, search blocks, edges, numpy/networkx views."""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.scenario.grid import cell_name
from fcplan.taskgraph import (
    TaskGraph,
    TaskGraphParams,
    TaskKind,
    build_task_graph,
    grid_block_name,
)
from fcplan.team import Command, fov_half_extent

SETTINGS = settings(max_examples=30, deadline=None)


@lru_cache(maxsize=4)
def quiet_scenario(name: str | int = 1):
    """A shipped scenario whose own fire regions never ignite during the game."""
    sc = load_scenario(name)
    regions = tuple(dataclasses.replace(r, delay_s=10_000.0) for r in sc.regions)
    return sc.replace(regions=regions)


def hover_world(cells, at, *, z: float = 100.0, hover_ticks: int = 30, scenario=None):
    """Ignite ``cells`` by hand, fly P1 to ``at`` (or each agent of a dict ``{id: xy}`` to its
    point) at altitude ``z`` and hover there.

    Returns the world and the team's belief. At z = 100 the view is 200 x 115 px; each cell in it
    is sensed with probability 0.4 per tick, so after ~30 ticks almost every cell is known (the
    tests compare the graph with the belief, not with the ignited cells).
    """
    sc = scenario or quiet_scenario(1)
    world = World().reset(sc, seed=0)
    if len(cells):
        world.ignite(np.asarray(cells, dtype=np.int64).reshape(-1, 2))
    belief = Belief(sc)
    targets = at if isinstance(at, dict) else {"P1": at}
    team = world.team
    n = 0
    cmd = {}
    for agent, xy in targets.items():
        i = team.index(agent)
        travel = math.hypot(xy[0] - team.pos[i, 0], xy[1] - team.pos[i, 1])
        n = max(n, int(travel / team.speed[i]) + 2 + hover_ticks)
        cmd[agent] = Command(route=((float(xy[0]), float(xy[1])),), altitude=z)
    for _ in range(n):
        belief.update(world.step(cmd))
        cmd = None
    return world, belief


def graph_of(world, belief, params=None) -> TaskGraph:
    return build_task_graph(world.scenario, world.team, belief, params)


def block_cells(center, half=(40, 25), step=3):
    """A filled rectangle of cells (every ``step`` px) around ``center``."""
    cx, cy = center
    xs = np.arange(cx - half[0], cx + half[0] + 1, step)
    ys = np.arange(cy - half[1], cy + half[1] + 1, step)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    return np.stack([gx.ravel(), gy.ravel()], axis=1)


def rect_distance(p, rect) -> float:
    x0, x1, y0, y1 = rect
    dx = max(x0 - p[0], 0.0, p[0] - x1)
    dy = max(y0 - p[1], 0.0, p[1] - y1)
    return math.hypot(dx, dy)


def fire_tile_of_cells(graph: TaskGraph, xy: np.ndarray) -> np.ndarray:
    """(k,) row of the fire task whose tile holds each cell (-1 when none)."""
    tw, th = graph.tile_px
    fires = graph.fire_tasks
    tiles = {
        (int(graph.task_pos[k, 0] // tw), int(graph.task_pos[k, 1] // th)): int(k) for k in fires
    }
    assert len(tiles) == fires.size, "two fire tasks share a tile"
    return np.array([tiles.get((int(x // tw), int(y // th)), -1) for x, y in xy], dtype=np.int64)


# strategies: a few clumps of cells inside one 200 x 115 px view centred on a random point
centres = st.tuples(st.integers(150, 1050), st.integers(150, 1050))
offsets = st.lists(
    st.tuples(st.integers(-95, 95), st.integers(-55, 55)), min_size=1, max_size=60, unique=True
)


@lru_cache(maxsize=1)
def fire_near_house():
    """Known fire just north of the house at I-02 (footprint x 840..960, y 125..275)."""
    cells = block_cells((900, 100), half=(20, 10), step=2)
    return hover_world(cells, (900, 100))


@lru_cache(maxsize=1)
def fire_far_away():
    """Known fire at (520, 500): more than 250 px from every facility footprint of #1."""
    cells = block_cells((520, 500), half=(30, 20), step=2)
    return hover_world(cells, (520, 500))


# ---------------------------------------------------------------------- fire tiles
@SETTINGS
@given(centre=centres, offs=offsets)
def test_fire_tasks_are_dump_sized(centre, offs):
    """Every known cell of a fire task lies inside the task's tile and inside an action agent's
    field of view (fov_half_extent(30)) centred on the task position."""
    cells = np.array(centre) + np.array(offs)
    world, belief = hover_world(cells, centre)
    g = graph_of(world, belief)
    xy = belief.known_xy()
    assert xy.shape[0] > 0
    owner = fire_tile_of_cells(g, xy)
    assert (owner >= 0).all(), "a known cell is in no fire task's tile"
    tw, th = g.tile_px
    hx, hy = fov_half_extent(30.0)
    pos = g.task_pos[owner]
    # inside the tile of its task
    assert np.all(xy[:, 0] // tw == pos[:, 0] // tw)
    assert np.all(xy[:, 1] // th == pos[:, 1] // th)
    # inside a 30 m dump's view centred on the task (inclusive, as the world's FOV test)
    assert np.all(np.abs(xy[:, 0] - pos[:, 0]) <= hx + 1e-9)
    assert np.all(np.abs(xy[:, 1] - pos[:, 1]) <= hy + 1e-9)
    # and the tile itself fits in that view
    assert tw <= 2 * hx and th <= 2 * hy


@SETTINGS
@given(
    centre=centres,
    offs=offsets,
    tile=st.tuples(st.integers(5, 120), st.integers(5, 120)),
)
def test_known_cells_are_partitioned_among_fire_tasks(centre, offs, tile):
    """For any tile size, the fire tasks' cell counts add up to the number of known cells and
    each task counts exactly the known cells of its tile; positions lie in their tile."""
    cells = np.array(centre) + np.array(offs)
    world, belief = hover_world(cells, centre)
    g = graph_of(world, belief, TaskGraphParams(tile_px=(float(tile[0]), float(tile[1]))))
    xy = belief.known_xy()
    fires = g.fire_tasks
    assert int(g.task_cells[fires].sum()) == len(xy) == g.known_cells
    assert np.all(g.task_cells[fires] > 0)
    owner = fire_tile_of_cells(g, xy)
    assert (owner >= 0).all()
    np.testing.assert_array_equal(
        np.bincount(owner, minlength=g.n_tasks)[fires], g.task_cells[fires]
    )
    assert np.all(g.task_cells[g.search_tasks] == 0)
    # fire tasks come first, then search blocks
    assert np.all(np.diff(g.task_kind.astype(int)) >= 0)


def test_fire_task_position_is_centre_of_its_cells():
    """A fire task sits at the centre of its cells' bounding box, its id is ``fire:x:y``, and a
    freshly sensed fire has (near) zero staleness."""
    world, belief = fire_far_away()
    g = graph_of(world, belief)
    xy = belief.known_xy()
    owner = fire_tile_of_cells(g, xy)
    for k in g.fire_tasks:
        mine = xy[owner == k]
        centre = (mine.min(axis=0) + mine.max(axis=0)) / 2.0
        np.testing.assert_allclose(g.task_pos[k], centre)
        assert g.task_ids[k].split("#")[0] == f"fire:{int(centre[0])}:{int(centre[1])}"
        assert 0.0 <= g.task_staleness[k] <= 1.0
    assert len(set(g.task_ids)) == g.n_tasks


def test_one_connected_fire_is_one_cluster():
    """Tiles of one contiguous patch of fire share a cluster id; a distant patch gets another."""
    a = block_cells((520, 500), half=(60, 30), step=1)
    b = block_cells((560, 680), half=(5, 5), step=1)
    world, belief = hover_world(np.r_[a, b], {"P1": (520, 500), "P2": (560, 680)})
    g = graph_of(world, belief)
    xy = belief.known_xy()
    owner = fire_tile_of_cells(g, xy)
    in_a = np.abs(xy[:, 1] - 500) <= 30
    clusters_a = set(g.task_cluster[owner[in_a]].tolist())
    clusters_b = set(g.task_cluster[owner[~in_a]].tolist())
    assert len(clusters_a) == 1
    assert clusters_b and clusters_a.isdisjoint(clusters_b)
    assert np.all(g.task_cluster[g.search_tasks] == -1)


# ---------------------------------------------------------------------- search blocks
@pytest.mark.parametrize("name", [1, "open_world_example"])
def test_search_tasks_cover_the_map_in_chess_named_blocks(name):
    """One search task per 100-px block: ``search:<chess name>`` at the block centre, the names
    agreeing with fcplan.scenario.grid.cell_name, every cell of the map in exactly one block."""
    sc = load_scenario(name)
    world = World().reset(sc, seed=0)
    g = build_task_graph(sc, world.team, Belief(sc))
    w = sc.world_size
    nb = -(-w // 100)
    s = g.search_tasks
    assert s.size == nb * nb
    seen = np.zeros((nb, nb), dtype=int)
    for k in s:
        x, y = g.task_pos[k]
        bx, by = int(x // 100), int(y // 100)
        seen[bx, by] += 1
        assert g.task_ids[k] == f"search:{cell_name(x, y)}" == f"search:{grid_block_name(bx, by)}"
        np.testing.assert_allclose(g.task_pos[k], [bx * 100 + 50, by * 100 + 50])
        assert g.task_kind[k] == TaskKind.SEARCH
    assert np.all(seen == 1)
    k = g.task_index["search:D-05"]
    np.testing.assert_allclose(g.task_pos[k], [350.0, 450.0])


@pytest.mark.parametrize(
    "block",
    [100, 200, 120, 150, 50, 10],
)
def test_search_blocks_for_other_block_sizes(block):
    """With TaskGraphParams(search_block_px=b), the map is covered by ceil(W / b)^2 search
    tasks at the block centres, each with a finite staleness."""
    sc = load_scenario(1)
    world = World().reset(sc, seed=0)
    belief = Belief(sc)
    for _ in range(5):
        belief.update(world.step())
    g = build_task_graph(sc, world.team, belief, TaskGraphParams(search_block_px=block))
    nb = -(-sc.world_size // block)
    s = g.search_tasks
    assert s.size == nb * nb
    assert np.all(np.isfinite(g.task_staleness[s])) and np.all(g.task_staleness[s] >= 0)
    blocks = {(int(x // block), int(y // block)) for x, y in g.task_pos[s]}
    assert blocks == {(bx, by) for bx in range(nb) for by in range(nb)}


def test_grid_block_name_examples():
    """grid_block_name uses letters for columns (A.., Z, AA..) and 2-digit 1-based rows."""
    assert grid_block_name(3, 4) == "D-05"
    assert grid_block_name(0, 0) == "A-01"
    assert grid_block_name(25, 11) == "Z-12"
    assert grid_block_name(26, 0) == "AA-01"


def test_unexplored_blocks_are_stalest():
    """Search blocks the team has just covered are less stale than blocks nobody has seen."""
    world, belief = fire_far_away()
    g = graph_of(world, belief)
    near = g.task_index["search:F-05"]  # (550, 450): under P1's camera
    far = g.task_index["search:L-12"]
    assert g.task_staleness[near] < g.task_staleness[far]


# ---------------------------------------------------------------------- edges
def test_requires_edges_go_from_fire_to_its_search_block():
    """Each fire task has exactly one ``requires`` edge, to the search block holding its
    position; task_block says the same."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    G = g.graph
    assert g.fire_tasks.size > 0
    for k in g.fire_tasks:
        t = g.task_ids[k]
        req = [v for _, v, d in G.out_edges(t, data=True) if d["kind"] == "requires"]
        x, y = g.task_pos[k]
        assert req == [f"search:{cell_name(x, y)}"]
        assert g.task_ids[g.task_block[k]] == req[0]
        assert G.nodes[req[0]]["kind"] == "search"
    n_req = sum(d["kind"] == "requires" for *_, d in G.edges(data=True))
    assert n_req == g.fire_tasks.size


def test_threatens_edges_for_fire_next_to_a_house():
    """Fire beside a house gets a ``threatens`` edge to it with a finite, non-negative time; the
    edges go exactly to facilities within the threat radius, nearer ones sooner."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    G = g.graph
    radius = TaskGraphParams().threat_radius_px
    house = "facility:0:house"
    assert G.nodes[house]["pos"] == (900.0, 200.0)
    assert g.fire_tasks.size > 0
    for k in g.fire_tasks:
        t = g.task_ids[k]
        edges = {
            v: d["time_s"] for _, v, d in G.out_edges(t, data=True) if d["kind"] == "threatens"
        }
        assert house in edges
        expected = set()
        dist = {}
        for f, fid in enumerate(g.node_ids[g.n_agents + 1 + g.n_tasks :]):
            d = rect_distance(g.task_pos[k], g.facility_rect[f])
            dist[fid] = d
            if d < radius:
                expected.add(fid)
        assert set(edges) == expected
        for t_s in edges.values():
            assert math.isfinite(t_s) and t_s >= 0.0
        ordered = sorted(edges, key=dist.get)
        times = [edges[f] for f in ordered]
        assert times == sorted(times)
        assert g.task_threat[k] > 0.0
        assert g.task_value[k] > g.task_cells[k]  # threat raises the value


def test_no_threatens_edges_for_far_fire():
    """Fire more than the threat radius from every facility has no ``threatens`` edge, zero
    threat and infinite threat times."""
    world, belief = fire_far_away()
    g = graph_of(world, belief)
    assert g.fire_tasks.size > 0
    kinds = [d["kind"] for *_, d in g.graph.edges(data=True)]
    assert "threatens" not in kinds
    assert np.all(np.isinf(g.threat_time_s))
    assert np.all(g.task_threat == 0.0)
    np.testing.assert_allclose(g.task_value[g.fire_tasks], g.task_cells[g.fire_tasks])


# ---------------------------------------------------------------------- views
def test_numpy_and_networkx_views_agree():
    """The networkx view has one node per entry of node_ids (agents, depot, tasks, facilities)
    at the same positions and with the same kinds as the numpy arrays; ``can_do`` edges match
    the can_do matrix."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    G = g.graph
    n_fac = len(g.facility_kinds)
    assert G.number_of_nodes() == len(g.node_ids) == g.n_agents + 1 + g.n_tasks + n_fac
    assert g.positions.shape == (len(g.node_ids), 2)
    for row, nid in enumerate(g.node_ids):
        np.testing.assert_allclose(G.nodes[nid]["pos"], g.positions[row])
    kinds = [G.nodes[n]["kind"] for n in g.node_ids]
    assert kinds == (
        ["agent"] * g.n_agents
        + ["depot"]
        + ["fire" if k == TaskKind.FIRE else "search" for k in g.task_kind]
        + ["facility"] * n_fac
    )
    for k, t in enumerate(g.task_ids):
        assert G.nodes[t]["cells"] == g.task_cells[k]
    np.testing.assert_allclose(G.nodes["depot"]["pos"], world.scenario.depot.center)
    can = [(a, t) for a, t, d in G.edges(data=True) if d["kind"] == "can_do"]
    assert len(can) == int(g.can_do.sum())
    for a, t in can:
        assert g.can_do[g.agent_index[a], g.task_index[t]]
    for a, t, d in G.edges(data=True):
        if d["kind"] == "can_do":
            i, k = g.agent_index[a], g.task_index[t]
            assert d["time_s"] == pytest.approx(g.agent_task_distance[i, k] / g.agent_speed[i])


points = st.lists(
    st.tuples(st.floats(0, 1199, allow_nan=False), st.floats(0, 1199, allow_nan=False)),
    min_size=1,
    max_size=8,
)


@lru_cache(maxsize=1)
def base_graph() -> TaskGraph:
    world, belief = fire_far_away()
    return graph_of(world, belief)


@SETTINGS
@given(agents=points, tasks=points)
def test_distances_are_straight_lines(agents, tasks):
    """agent_task_distance[i, k] is the Euclidean distance between agent i and task k;
    task_distance is the symmetric Euclidean matrix with a zero diagonal."""
    g0 = base_graph()
    a = np.array(agents, dtype=np.float64)
    t = np.array(tasks, dtype=np.float64)
    n_a, n_t = len(a), len(t)
    g = dataclasses.replace(
        g0,
        agent_ids=tuple(f"X{i}" for i in range(n_a)),
        agent_pos=a,
        agent_home=np.zeros((n_a, 2)),
        agent_speed=np.full(n_a, 200.0),
        agent_can_sense=np.ones(n_a, bool),
        task_ids=tuple(f"t{k}" for k in range(n_t)),
        task_pos=t,
        task_kind=np.full(n_t, TaskKind.SEARCH, np.int8),
    )
    d = g.agent_task_distance
    assert d.shape == (n_a, n_t)
    for i in range(n_a):
        for k in range(n_t):
            assert d[i, k] == pytest.approx(math.dist(a[i], t[k]), abs=1e-9)
            assert g.task_home_distance[i, k] == pytest.approx(math.hypot(*t[k]), abs=1e-9)
    td = g.task_distance
    np.testing.assert_allclose(td, td.T)
    np.testing.assert_allclose(np.diag(td), 0.0, atol=1e-9)
    np.testing.assert_allclose(g.agent_task_time, d / 200.0)


def test_agent_task_distance_from_the_real_team():
    """On a built graph, agent_task_distance equals the distance from the team's positions."""
    world, belief = fire_near_house()
    g = graph_of(world, belief)
    exp = np.hypot(
        world.team.pos[:, None, 0] - g.task_pos[None, :, 0],
        world.team.pos[:, None, 1] - g.task_pos[None, :, 1],
    )
    np.testing.assert_allclose(g.agent_task_distance, exp, atol=1e-9)
    np.testing.assert_allclose(g.agent_pos, world.team.pos)


@pytest.mark.parametrize("name", [1, "open_world_example"])
def test_can_do_forbids_search_for_action_only_agents(name):
    """Action-only agents can do fire tasks only; perception and hybrid agents can do
    everything."""
    if name == 1:
        world, belief = fire_near_house()
    else:
        sc = quiet_scenario(name)
        world, belief = hover_world(block_cells((500, 500)), (500, 500), scenario=sc)
    g = graph_of(world, belief)
    from fcplan.scenario import Role

    fire = g.task_kind == TaskKind.FIRE
    assert fire.any() and (~fire).any()
    for i in range(g.n_agents):
        role = Role(int(g.agent_role[i]))
        if role is Role.ACTION:
            assert not g.can_do[i, ~fire].any()
            assert g.can_do[i, fire].all()
            assert not g.agent_can_sense[i]
        else:
            assert g.can_do[i].all()


# ---------------------------------------------------------------------- no fire
@pytest.mark.parametrize("name", ["practice", 1, 24, "open_world_example"])
def test_graph_builds_with_no_known_fire(name):
    """With nothing sensed the graph has only search tasks, zero known cells, (0, F) threat
    times, and a networkx view without fire nodes or requires/threatens edges."""
    sc = load_scenario(name)
    world = World().reset(sc, seed=0)
    g = build_task_graph(sc, world.team, Belief(sc))
    assert g.fire_tasks.size == 0
    assert g.known_cells == 0
    assert g.n_tasks == g.search_tasks.size > 0
    assert g.threat_time_s.shape == (0, len(sc.scored_facilities))
    assert g.n_agents == len(sc.agents)
    kinds = {d["kind"] for _, d in g.graph.nodes(data=True)}
    assert kinds == {"agent", "depot", "search", "facility"}
    edge_kinds = {d["kind"] for *_, d in g.graph.edges(data=True)}
    assert edge_kinds <= {"can_do"}
    assert g.agent_task_distance.shape == (g.n_agents, g.n_tasks)


def test_graph_reports_team_state():
    """Agent arrays come from the team: full range is battery / 0.1 px, tanks and homes match
    the scenario, speeds are px per second."""
    sc = load_scenario(1)
    world = World().reset(sc, seed=0)
    g = build_task_graph(sc, world.team, Belief(sc))
    for i, a in enumerate(sc.agents):
        assert g.agent_ids[i] == a.id
        assert g.agent_full_range[i] == pytest.approx(a.battery / 0.1)
        assert g.agent_tank[i] == a.tank
        np.testing.assert_allclose(g.agent_home[i], a.start)
        assert g.agent_speed[i] == pytest.approx(a.speed * 10.0)
        np.testing.assert_allclose(g.agent_alt_range[i], a.altitude)


@settings(max_examples=80, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    nx=st.integers(2, 30),
    ny=st.integers(2, 30),
    most=st.sampled_from([40, 200]),
)
def test_small_fire_clusters_match_scipy_label_also_when_repeated(seed, nx, ny, most):
    """Up to a few dozen tiles (the closure path) and up to 200 (the numpy labelling), cluster
    labels equal scipy.ndimage.label (8-connected, numbered by first tile in raster order), and
    asking again for the same tiles (the memo) gives the same labels."""
    from scipy.ndimage import label

    from fcplan.taskgraph import _EIGHT, _clusters

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, min(nx * ny, most) + 1))
    flat = np.sort(rng.choice(nx * ny, size=n, replace=False))
    tx, ty = np.divmod(flat, ny)
    grid = np.zeros((nx + 1, ny + 1), dtype=bool)
    grid[tx, ty] = True
    labels, _ = label(grid, structure=_EIGHT)
    want = labels[tx, ty].astype(np.int64) - 1
    assert np.array_equal(_clusters(tx, ty, nx, ny), want)
    assert np.array_equal(_clusters(tx.copy(), ty.copy(), nx, ny), want)


@pytest.mark.parametrize("nb", [1, 2, 5, 12])
def test_neighbour_table_is_the_3x3_box_sum(nb):
    """Counting each fire block's cells in its 3 x 3 neighbourhood through the neighbour table
    equals the padded 3 x 3 box sum of the per-block counts."""
    from fcplan.taskgraph import _neighbours

    rng = np.random.default_rng(nb)
    fb = rng.integers(0, nb * nb, 20)
    counts = rng.integers(1, 50, 20)
    near = np.bincount(fb, weights=counts, minlength=nb * nb).reshape(nb, nb)
    padded = np.zeros((nb + 2, nb + 2))
    padded[1:-1, 1:-1] = near
    box = sum(padded[i : i + nb, j : j + nb] for i in range(3) for j in range(3)).ravel()
    got = np.bincount(
        _neighbours(nb)[fb].ravel(), weights=np.repeat(counts, 9), minlength=nb * nb + 1
    )
    assert np.array_equal(got[: nb * nb], box)


def test_graph_shares_read_only_constants_between_builds():
    """Two graphs of one team share their per-agent constants as read-only arrays, and their
    belief-dependent arrays are their own (writing to them does not touch the other graph)."""
    world = World().reset(load_scenario(1), seed=0)
    belief = Belief(world.scenario)
    belief.update(world.step())
    a = build_task_graph(world.scenario, world.team, belief)
    belief.update(world.step())
    b = build_task_graph(world.scenario, world.team, belief)
    for name in ("agent_home", "agent_speed", "agent_role", "agent_can_sense", "facility_pos"):
        assert getattr(a, name) is getattr(b, name)
        assert not getattr(a, name).flags.writeable
    for name in ("agent_pos", "agent_battery", "task_value", "task_staleness"):
        assert getattr(a, name) is not getattr(b, name)
        assert getattr(a, name).flags.writeable
    assert np.array_equal(a.agent_home, world.team.home)
