"""Tests for fcplan.taskgraph.build: dump-sized fire tiles, search blocks, edges, the per-episode
builder and its shared constants."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario, make_scheduler
from fcplan.belief import Belief
from fcplan.plan import plan_commands
from fcplan.scenario.grid import cell_name
from fcplan.taskgraph import (
    TaskGraphBuilder,
    TaskGraphParams,
    TaskKind,
    build_task_graph,
    grid_block_name,
)
from fcplan.team import fov_half_extent
from tests.taskgraph.worlds import (
    block_cells,
    centres,
    fire_far_away,
    fire_near_house,
    fire_tile_of_cells,
    graph_of,
    hover_world,
    offsets,
    rect_distance,
)

SETTINGS = settings(max_examples=30, deadline=None)


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


@pytest.mark.parametrize("nb", [1, 2, 5, 12])
def test_neighbour_table_is_the_3x3_box_sum(nb):
    """Counting each fire block's cells in its 3 x 3 neighbourhood through the neighbour table
    equals the padded 3 x 3 box sum of the per-block counts."""
    from fcplan.taskgraph.build import _neighbours

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


# ---------------------------------------------------------------------- the builder
def test_builder_graphs_share_read_only_constants():
    """Two graphs of one builder share their per-agent and facility constants as read-only
    arrays, and their belief-dependent arrays are their own (writing to them does not touch the
    other graph)."""
    world = World().reset(load_scenario(1), seed=0)
    belief = Belief(world.scenario)
    builder = TaskGraphBuilder(world.scenario)
    belief.update(world.step())
    a = builder.build(world.team, belief)
    belief.update(world.step())
    b = builder.build(world.team, belief)
    for name in ("agent_home", "agent_speed", "agent_role", "agent_can_sense", "facility_pos"):
        assert getattr(a, name) is getattr(b, name)
        assert not getattr(a, name).flags.writeable
    for name in ("agent_pos", "agent_battery", "task_value", "task_staleness"):
        assert getattr(a, name) is not getattr(b, name)
        assert getattr(a, name).flags.writeable
    assert np.array_equal(a.agent_home, world.team.home)
    assert a.shared_memo is b.shared_memo is not None


def assert_same_graph(a, b) -> None:
    """Every field and every filled-in distance view of two graphs is equal, bit for bit."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape, f.name
            assert x.tobytes() == y.tobytes(), f.name
        else:
            assert x == y, f.name
    for name in ("agent_task_distance", "task_home_distance", "can_do"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name


@pytest.mark.parametrize("name", ["practice", "12", "open_world_example"])
def test_builder_reused_over_an_episode_equals_fresh_builds(name):
    """A builder reused over a greedy episode (its constants computed once, its cluster labels
    remembered) gives, at every replan, the graph a fresh builder gives, with and without
    known fire; after a reset the builder follows the new team."""
    sc = load_scenario(name)
    builder = TaskGraphBuilder(sc)
    greedy = make_scheduler("greedy")
    seen_fire = False
    for seed in (0, 1):
        world = World().reset(sc, seed=seed)
        belief = Belief(sc)
        commands = None
        for tick in range(1, 401):
            belief.update(world.step(commands))
            commands = None
            if tick % 10:
                continue
            g = builder.build(world.team, belief)
            assert_same_graph(g, build_task_graph(sc, world.team, belief))
            seen_fire |= g.fire_tasks.size > 0
            commands = plan_commands(greedy.plan(g, rng=world.controller_rng), g)
    assert seen_fire


def test_builder_with_params_equals_build_task_graph():
    """A builder with other settings (tile, block size) builds what build_task_graph builds with
    them."""
    world, belief = fire_near_house()
    params = TaskGraphParams(tile_px=(17.5, 12.0), search_block_px=150, threat_radius_px=400.0)
    builder = TaskGraphBuilder(world.scenario, params)
    assert builder.params is params
    assert_same_graph(builder.build(world.team, belief), graph_of(world, belief, params))


@settings(max_examples=60, deadline=None)
@given(
    st.integers(0, 12),
    st.integers(0, 6),
    st.integers(0, 2**32 - 1),
)
def test_penalty_weighted_adds_the_facilities_in_order(n, f, seed):
    """The threat ``penalty_weighted(close, pen)`` is, bit for bit, the plain left-to-right sum
    ``0 + close[i, 0] pen[0] + close[i, 1] pen[1] + ...`` of Python floats (no BLAS, so the same
    on every machine), and agrees with the matrix product to rounding."""
    from fcplan.taskgraph.build import penalty_weighted

    rng = np.random.default_rng(seed)
    close = rng.random((n, f))
    pen = rng.choice([0.0, 1.0, 2.5, 10.0], f) * rng.random(f)
    got = penalty_weighted(close, pen)
    want = []
    for row in close.tolist():
        total = 0.0
        for c, w in zip(row, pen.tolist(), strict=True):
            total += c * w
        want.append(total)
    assert got.dtype == np.float64 and got.shape == (n,)
    assert got.tolist() == want
    np.testing.assert_allclose(got, close @ pen, rtol=1e-12, atol=1e-12)
