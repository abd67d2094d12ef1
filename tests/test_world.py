"""Tests for fcplan.world: sensing, pruning and its gate, facility counts, conservation,
determinism."""

from __future__ import annotations

import hashlib
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.fire import BURNING, PRUNED
from fcplan.team import Command
from tests.conftest import scenario_with

QUIET = {"fire.delay_s": 1000.0}  # no natural fire during the test: only cells we ignite


def block(x0, y0, nx, ny):
    xs, ys = np.meshgrid(np.arange(x0, x0 + nx), np.arange(y0, y0 + ny), indexing="ij")
    return np.stack([xs.ravel(), ys.ravel()], axis=1)


def park(world, agent, x, y, z=None):
    team = world.team
    i = team.index(agent)
    team.pos[i] = (x, y)
    if z is not None:
        team.z[i] = team.z_target[i] = z
    team.mode[i] = 1  # ACTIVE, hovering


def test_world_runs_standalone_to_the_end():
    """reset/step without any scheduler runs the scenario's duration and records every tick."""
    world = World().reset(load_scenario(1), seed=3)
    while not world.done:
        world.step()
    tr = world.trace()
    assert tr.n_ticks == 1800 and tr.active[-1] > 0 and tr.pruned[-1] == 0


@pytest.mark.parametrize("z", [10.0, 55.0, 100.0])
def test_sensing_rate_matches_altitude_confidence(z):
    """A perception agent senses each burning cell in view with probability 1 - 0.6(z-lo)/(hi-lo)."""
    world = World().reset(scenario_with(1, **QUIET), seed=0)
    world.ignite(block(580, 580, 40, 22))
    park(world, "P1", 600.0, 591.0, z)
    info = world.step()
    hx = z
    hy = 0.57735 * z
    in_view = (np.abs(block(580, 580, 40, 22)[:, 0] - 600) <= hx) & (
        np.abs(block(580, 580, 40, 22)[:, 1] - 591) <= hy
    )
    expected = 1 - 0.6 * (z - 10) / 90
    got = info.sensed.size / in_view.sum()
    assert got == pytest.approx(expected, abs=0.08)
    # nothing outside the field of view is sensed
    sx, sy = info.sensed // 1200, info.sensed % 1200
    assert (np.abs(sx - 600) <= hx).all() and (np.abs(sy - 591) <= hy).all()


def test_pruning_rate_is_the_confidence_and_spares_unsensed_cells():
    """A dump prunes sensed burning cells in view with probability 0.9 and never unsensed ones."""
    world = World().reset(scenario_with(1, **QUIET), seed=1)
    cells = block(570, 583, 60, 34)
    world.ignite(cells)
    flat = cells[:, 0] * 1200 + cells[:, 1]
    sensed = flat[::2]  # half the cells are known
    world.sensed.reshape(-1)[sensed] = True
    world.n_sensed_active = world.n_sensed_ever = sensed.size
    park(world, "A1", 600.0, 600.0)
    world.team.armed[world.team.index("A1")] = True
    info = world.step()
    assert world.team.dumps[world.team.index("A1")] == 1
    assert set(info.pruned.tolist()) <= set(sensed.tolist())
    assert info.pruned.size / sensed.size == pytest.approx(0.9, abs=0.05)
    unsensed = flat[1::2]
    assert (world.fire.state.reshape(-1)[unsensed] == BURNING).all()
    # one dump per arrival: the agent is disarmed
    assert not world.team.armed[world.team.index("A1")]


def test_no_dump_without_sensed_fire_keeps_the_agent_armed():
    """With nothing sensed in view no water is spent and the dump stays armed (manual gate)."""
    world = World().reset(scenario_with(1, **QUIET), seed=2)
    world.ignite(block(590, 590, 20, 20))
    park(world, "A1", 600.0, 600.0)
    a = world.team.index("A1")
    world.team.armed[a] = True
    world.step()
    assert world.team.tank[a] == 10 and world.team.armed[a]
    assert world.fire.n_pruned == 0


def test_reference_gate_prunes_unsensed_cells_when_nothing_is_sensed():
    """action_gate = "reference" restores the 2020 rule: with nothing sensed, any cell can go."""
    world = World().reset(scenario_with(1, **QUIET, **{"fire.action_gate": "reference"}), seed=2)
    world.ignite(block(590, 590, 20, 20))
    park(world, "A1", 600.0, 600.0)
    world.team.armed[world.team.index("A1")] = True
    world.step()
    assert world.fire.n_pruned > 300


def test_facility_counts_follow_ignition_and_pruning():
    """Burning cells inside a footprint (strict bounds) are counted; pruning moves them to the
    facility's pruned count."""
    sc = scenario_with(1, **QUIET)
    world = World().reset(sc, seed=0)
    house = sc.scored_facilities[0]
    x0, x1, y0, y1 = house.footprint
    inside = block(int(x0) + 1, int(y0) + 1, 5, 4)
    edge = np.array([[int(x0), int(y0) + 10]])  # on the open boundary: not inside
    world.ignite(np.concatenate([inside, edge]))
    assert world.facility_burning[0] == 20 and world.facility_burning.sum() == 20
    # a dump over the house moves its cells from burning to pruned
    world2 = World().reset(sc, seed=0)
    world2.ignite(inside)
    world2.sensed.reshape(-1)[inside[:, 0] * 1200 + inside[:, 1]] = True
    park(world2, "A1", float(inside[:, 0].mean()), float(inside[:, 1].mean()))
    world2.team.armed[world2.team.index("A1")] = True
    info = world2.step()
    assert world2.facility_burning[0] + world2.facility_pruned[0] == 20
    assert world2.facility_pruned[0] == info.pruned.size > 0


@settings(max_examples=10, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    events=st.lists(
        st.tuples(st.integers(0, 59), st.sampled_from(["ignite", "dump", "trace", "sum"])),
        max_size=12,
    ),
)
def test_facility_trace_rows_are_the_counts_after_every_tick(seed, events):
    """The trace's facility rows (written lazily, from the last change of the counts on) hold,
    for every tick, facility_burning and facility_pruned as they were after that tick: through
    hand ignitions inside footprints between ticks, dumps over a facility during ticks, and the
    trace read (trace(), trace_sum) at any tick in between."""
    sc = scenario_with(1, **QUIET)
    world = World().reset(sc, seed=seed)
    rng = np.random.default_rng(seed)
    fac = [f.footprint for f in sc.scored_facilities[:3]]
    burning, pruned = [], []
    for t in range(60):
        for when, what in events:
            if when != t:
                continue
            x0, x1, y0, y1 = fac[int(rng.integers(len(fac)))]
            cx, cy = (
                int(rng.integers(int(x0) + 1, int(x1))),
                int(rng.integers(int(y0) + 1, int(y1))),
            )
            if what == "ignite":
                world.ignite(block(cx, cy, 3, 2))
            elif what == "dump" and world.fire.n_burning:
                cells = np.flatnonzero(world.fire.state.reshape(-1) == BURNING)
                world.sensed.reshape(-1)[cells] = True
                world.n_sensed_active = world.n_sensed_ever = int(cells.size)
                c = int(cells[rng.integers(cells.size)])
                park(world, "A1", float(c // 1200), float(c % 1200))
                world.team.armed[world.team.index("A1")] = True
            elif what == "trace" and world.tick:
                tr = world.trace()
                np.testing.assert_array_equal(tr.facility_burning, np.array(burning))
                np.testing.assert_array_equal(tr.facility_pruned, np.array(pruned))
            elif what == "sum" and world.tick:
                np.testing.assert_array_equal(
                    world.trace_sum("facility_burning", 0, world.tick), np.sum(burning, axis=0)
                )
        world.step()
        burning.append(world.facility_burning.copy())
        pruned.append(world.facility_pruned.copy())
    tr = world.trace()
    np.testing.assert_array_equal(tr.facility_burning, np.array(burning))
    np.testing.assert_array_equal(tr.facility_pruned, np.array(pruned))
    k = int(rng.integers(0, 60))
    np.testing.assert_array_equal(
        world.trace_sum("facility_pruned", k, 60), np.sum(pruned[k:], axis=0)
    )


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    moves=st.lists(
        st.tuples(
            st.sampled_from(["P1", "P2", "A1", "A2"]),
            st.tuples(st.floats(150, 600), st.floats(150, 600)),
        ),
        max_size=8,
    ),
)
def test_counts_are_conserved(seed, moves):
    """Every tick: active + pruned = ever ignited, sensed_active <= active, sensed_ever <=
    active + pruned, facility counts match the grid, and pruned cells never burn again."""
    world = World().reset(load_scenario(1), seed=seed)
    ever_pruned = np.zeros((1200, 1200), dtype=bool)
    for t in range(300):
        cmd = None
        if moves and t % 30 == 0:
            agent, pt = moves[(t // 30) % len(moves)]
            cmd = {agent: Command(route=(pt,), altitude=30.0)}
        world.step(cmd)
        f = world.fire
        assert f.n_burning + f.n_pruned == f.n_ignited
        assert world.n_sensed_active <= f.n_burning
        assert world.n_sensed_ever <= f.n_burning + f.n_pruned
        if t % 50 == 0:
            assert not np.any((f.state == BURNING) & ever_pruned)
            ever_pruned |= f.state == PRUNED
            assert f.n_burning == int((f.state == BURNING).sum())
            assert world.n_sensed_active == int(((f.state == BURNING) & world.sensed).sum())


def _trace_digest(seed: int) -> str:
    from fcplan import run_episode

    tr = run_episode(1, "greedy", seed=seed).trace
    h = hashlib.sha256()
    for name, arr in sorted(tr.arrays().items()):
        h.update(name.encode())
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()


def test_same_seed_gives_byte_identical_traces_across_processes():
    """The same scenario, scheduler and seed give byte-identical trace arrays in two processes;
    another seed differs."""
    code = "from tests.test_world import _trace_digest; print(_trace_digest(7))"
    out = [
        subprocess.run(
            [sys.executable, "-c", code],
            capture_output=True,
            text=True,
            check=True,
            cwd=str(__import__("pathlib").Path(__file__).parents[1]),
        ).stdout.strip()
        for _ in range(2)
    ]
    assert out[0] == out[1] == _trace_digest(7)
    assert _trace_digest(8) != out[0]


def test_fire_does_not_depend_on_the_team_until_it_prunes():
    """With the same seed the fire evolves identically whatever the agents do if nothing is
    pruned (common random numbers across schedulers)."""
    a = World().reset(load_scenario(2), seed=5)
    b = World().reset(load_scenario(2), seed=5)
    b.step({"P1": Command(route=((900.0, 900.0),), altitude=100.0)})
    a.step()
    for _ in range(400):
        a.step()
        b.step()
    np.testing.assert_array_equal(a.fire.state, b.fire.state)


@pytest.mark.parametrize("bad", [-1, True, np.bool_(False), 1.5, "3", [1, 2]])
def test_bad_seeds_are_one_line_seed_errors(bad):
    """A seed that is not an integer >= 0, a SeedSequence, a Generator or None is refused with
    one SeedError line naming the allowed values, at every door: World.reset, run_episode, the
    task env and the batched streams (numpy alone raises TypeError or ValueError without the
    argument's name, and takes True as 1)."""
    from fcplan import run_episode
    from fcplan.batch.streams import spawn_streams
    from fcplan.env.task import TaskEnv
    from fcplan.errors import FcplanError, SeedError

    sc = load_scenario("practice")
    for call in (lambda: World(sc, seed=bad), lambda: run_episode(sc, "idle", seed=bad),
                 lambda: TaskEnv(sc, max_steps=1).reset(seed=bad),
                 lambda: spawn_streams(bad)):  # fmt: skip
        with pytest.raises(SeedError, match=r"^seed: must be an integer >= 0, a SeedSequence"):
            call()
    assert issubclass(SeedError, FcplanError) and issubclass(SeedError, ValueError)


def test_good_seeds_are_taken():
    """Integers >= 0 (numpy's too), SeedSequences, Generators and None start a world; the same
    int and its SeedSequence give the same fire."""
    sc = load_scenario("practice")
    for seed in (0, np.int64(7), 2**70, np.random.SeedSequence(3), np.random.default_rng(1), None):
        World(sc, seed=seed)
    a, b = World(sc, seed=5), World(sc, seed=np.random.SeedSequence(5))
    for _ in range(30):
        a.step({}), b.step({})
    assert np.array_equal(a.fire.burning_cells(), b.fire.burning_cells())


@given(st.lists(st.integers(0, 2**40), max_size=8))
def test_seed_list_keeps_the_first_of_each_seed_in_order(seeds):
    """seed_list returns each integer seed once, in the order of its first appearance, as
    plain ints, for lists, tuples and numpy arrays alike."""
    from fcplan.world import seed_list

    want = list(dict.fromkeys(seeds))
    assert seed_list(seeds) == want
    assert seed_list(tuple(seeds)) == want
    got = seed_list(np.array(seeds, dtype=np.int64))
    assert got == want and all(type(s) is int for s in got)


@pytest.mark.parametrize("bad", [[-1], [1.0], [True], ["3"], "0-4", 1.5, None, True, {0: 1}])
def test_seed_list_refuses_what_is_not_a_list_of_seeds(bad):
    """A negative, float, bool or string seed, and a lone value that is not an integer >= 0,
    is a one-line SeedError naming the argument; a lone integer is a list of one."""
    from fcplan.errors import SeedError
    from fcplan.world import seed_list

    with pytest.raises(SeedError, match=r"^sweep\.toml: seeds: must be .*\(got "):
        seed_list(bad, name="sweep.toml: seeds")
    assert seed_list(7) == [7] and seed_list(np.int64(7)) == [7] and seed_list([]) == []
