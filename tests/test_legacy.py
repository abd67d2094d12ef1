"""Tests of the restricted unpickler and the import of FireCommander 2020 GUI recordings."""

from __future__ import annotations

import math
import os
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan import World, load_scenario, make_scheduler
from fcplan.belief import Belief
from fcplan.cli import main
from fcplan.legacy import LEGACY_FILES, LegacyError, import_legacy, restricted_loads
from fcplan.plan import plan_commands
from fcplan.recording import load_recording
from fcplan.scheduling import solve
from fcplan.taskgraph import build_task_graph
from fcplan.team import Mode

_FLAG = {int(Mode.IDLE): 1, int(Mode.ACTIVE): 1, int(Mode.RETURNING): 0, int(Mode.HOMING): 2}


def _dump(folder, name, obj):
    with open(os.path.join(folder, name), "wb") as f:
        pickle.dump(obj, f, protocol=2)


def write_legacy_folder(folder, scenario_name="practice", seed=0):
    """Play ``scenario_name`` with greedy in fcplan and write it as the 13 files of the 2020 GUI
    (FIRECOMMANDER.md section 7 layout; one frame per 100 ms). Returns the world."""
    sc = load_scenario(scenario_name)
    world, belief = World().reset(sc, seed), Belief(sc)
    sched = make_scheduler("greedy")
    w = sc.world_size
    n = len(sc.agents)
    roles = [int(a.role) for a in sc.agents]
    index_in_role = [int(a.id[1:]) for a in sc.agents]
    actors = [i for i in range(n) if sc.agents[i].role.can_act]
    sensors = [i for i in range(n) if sc.agents[i].role.can_sense]
    states = [[] for _ in range(n)]
    fire_rows = []
    sensed = [[] for _ in sensors]
    pruned = [[] for _ in actors]
    base = []
    user = [[] for _ in range(n)]
    on_fire = [[0] for _ in sc.scored_facilities]
    pruned_so_far = []
    while not world.done:
        cmds = None
        if world.tick % 10 == 0:
            g = build_task_graph(sc, world.team, belief)
            cmds = plan_commands(solve(sched, g, time_limit=None, rng=world.controller_rng), g)
            for aid, c in cmds.items():
                if c.route:
                    i = sc.agent_ids.index(aid)
                    user[i].append([c.route[0][0], c.route[0][1], world.tick, 0, 0])
        info = world.step(cmds)
        belief.update(info)
        ms = world.tick * 100
        team = world.team
        for i in range(n):
            dist = (team.battery_capacity[i] - team.battery[i]) / 0.1
            row = [
                *team.pos[i],
                team.z[i],
                0,
                0,
                0,
                0,
                ms,
                roles[i],
                index_in_role[i],
                dist,
                0,
                team.tank[i],
                _FLAG[int(team.mode[i])],
                0,
                0,
            ]
            states[i].extend(row)
            if world.tick == 77:  # the agent-switch bug: an extra 16-tuple for every agent
                states[i].extend(row)
        for c in info.ignited:
            fire_rows.append([c // w, c % w, 1.0, ms])
        for k in range(len(sensors)):
            cells = info.newly_sensed if k == 0 else np.zeros(0, np.int64)
            if k == 0 and world.tick % 50 == 0 and pruned_so_far:  # the GUI re-sensed old cells
                cells = np.concatenate([cells, pruned_so_far[:5]])
            sensed[k].append(
                np.stack([cells // w, cells % w, np.ones(cells.size), np.zeros(cells.size)], 1)
                if cells.size
                else []
            )
        if info.pruned.size:
            who = actors.index(info.dumped[0])
            pruned[who].append(
                [[[c // w, c % w, 1.0] for c in info.pruned], [*team.pos[info.dumped[0]], ms]]
            )
            pruned_so_far.extend(info.pruned.tolist())
        for k in range(len(actors)):
            if not (info.pruned.size and k == actors.index(info.dumped[0])):
                pruned[k].append([])
        base.append([*sc.depot.center, *sc.depot.size, 9, 1, world.tick])
        for f in range(len(on_fire)):
            on_fire[f].append(int(world.facility_burning[f]))
    regions = sc.regions
    fire_setting = [
        [r.fronts for r in regions],
        [r.delay_s for r in regions],
        [r.fuel for r in regions],
        [r.wind_speed for r in regions],
        [r.wind_dir_deg for r in regions],
        sc.scoring.temporal_exponent,
        sc.scoring.propagation_weight,
        90,
        80,
        1,
    ]
    kinds = {
        k: [list(f.center) for f in sc.facilities if f.kind == k]
        for k in ("house", "hospital", "power_station")
    }
    team_counts = sc.team_counts
    adv = [
        [list(sc.agents[0].altitude)],
        [[10, 100]],
        [[500]],
        [[500]],
        [[500]],
        [[20]],
        [[20]],
        [[20]],
        [[10]],
        [[10]],
    ]
    background = [
        [w, sc.duration_s, len(regions), *(len(v) for v in kinds.values()), len(sc.lakes)],
        [team_counts["perception"], team_counts["action"], team_counts.get("hybrid", 0), 0],
        [
            [list(r.center) for r in regions],
            fire_setting,
            [list(sc.depot.center), 1 if sc.depot.orientation == "vertical" else 0],
            kinds["house"],
            kinds["hospital"],
            kinds["power_station"],
            [list(lk.center) for lk in sc.lakes],
        ],
        adv,
        8,
        [math.pi / 4, math.pi / 6],
        16,
    ]
    os.makedirs(folder, exist_ok=True)
    files = {
        "Background_Info.pkl": background,
        "Battery_Info.pkl": [[a.battery, 0.1, 0.05] for a in sc.agents],
        "User_Data.pkl": user,
        "Target_Loci.pkl": [[[*f.center, *f.size, 0, 1, 0]] for f in sc.facilities],
        "Agent_Base_Loci.pkl": [base],
        "Lake_info.pkl": [[[*lk.center, 100, 0]] for lk in sc.lakes],
        "Fire_States.pkl": [fire_rows] + [[] for _ in regions[1:]],
        "Fire_Map.pkl": np.zeros((w, w)),
        "Sensing_Data_CoM.pkl": [[[] for _ in base] for _ in sensors],
        "Sensed_Fire_Map.pkl": sensed,
        "Pruned_Fire_Map.pkl": pruned,
        "target_onFire_List.pkl": on_fire,
        "Agent_States.pkl": states,
    }
    assert set(files) == set(LEGACY_FILES)
    for name, obj in files.items():
        _dump(folder, name, obj)
    return world


@pytest.fixture(scope="module")
def legacy(tmp_path_factory):
    """A synthetic legacy folder made from a practice episode, and the world that made it."""
    folder = tmp_path_factory.mktemp("legacy") / "Tim"
    world = write_legacy_folder(str(folder))
    return folder, world


def test_synthetic_folder_converts_with_the_same_counts(legacy):
    """A folder built to the documented structure converts; the fire, sensing, pruning and
    facility counts per tick equal the episode that produced it, so the metrics do too."""
    folder, world = legacy
    rec = import_legacy(folder)
    trace = world.trace()
    for name in (
        "active",
        "pruned",
        "sensed_active",
        "sensed_ever",
        "facility_burning",
        "facility_pruned",
    ):
        assert np.array_equal(rec.arrays[name], getattr(trace, name)), name
    assert rec.source == "legacy" and rec.seed is None
    from fcplan.metrics import compute_all

    want = compute_all(trace)
    got = rec.metrics()
    assert got["manual"].as_dict() == want["manual"].as_dict()
    assert 0 < got["manual"].overall_firefighting <= 100


def test_agents_and_scenario_are_recovered(legacy):
    """Agent positions, altitudes, tanks and battery follow the recorded states despite the extra
    agent-switch tuples, and the scenario has the recorded map, team and fire."""
    folder, world = legacy
    rec = import_legacy(folder)
    tr = world.trace().agents
    assert np.array_equal(rec.arrays["agent_xyz"], tr.xyz)
    assert np.array_equal(rec.arrays["agent_tank"], tr.tank)
    assert np.allclose(rec.arrays["agent_battery"], tr.battery, atol=1e-9)
    sc, orig = rec.scenario, world.scenario
    assert [a.id for a in sc.agents] == [a.id for a in orig.agents]
    assert [f.center for f in sc.scored_facilities] == [f.center for f in orig.scored_facilities]
    assert [(r.center, r.fronts, r.fuel) for r in sc.regions] == [
        (r.center, r.fronts, r.fuel) for r in orig.regions
    ]
    assert rec.inputs and rec.inputs[0]["action"] == "click"


def test_import_cli_and_replay(legacy, tmp_path, capsys):
    """`fcplan import-legacy` writes a recording that loads and replays to a GIF."""
    folder, _ = legacy
    out = tmp_path / "old.npz"
    assert main(["import-legacy", str(folder), "--out", str(out)]) == 0
    assert "cells burned" in capsys.readouterr().out
    rec = load_recording(out)
    assert rec.source == "legacy"
    gif = tmp_path / "old.gif"
    assert main(["replay", str(out), "--video", str(gif), "--size", "96", "--speed", "60"]) == 0
    with pytest.raises(Exception, match="seed"):
        rec.resimulate()


class _Call:
    """Pickles as a call of ``func(*args)``: what an attacker would put in a .pkl file."""

    def __init__(self, func, *args):
        self.func, self.args = func, args

    def __reduce__(self):
        return (self.func, self.args)


def _payloads(marker):
    import builtins
    import subprocess

    return {
        "os.system": _Call(os.system, f"touch {marker}"),
        "builtins.eval": _Call(builtins.eval, f"open({str(marker)!r}, 'w')"),
        "builtins.open": _Call(builtins.open, str(marker), "w"),
        "subprocess.Popen": _Call(subprocess.Popen, ["touch", str(marker)]),
        "in an object array": np.array([_Call(os.system, f"touch {marker}")], dtype=object),
        "numpy.load": _Call(np.load, str(marker)),
    }


@pytest.mark.parametrize("kind", list(_payloads("x")))
def test_malicious_pickles_are_refused(legacy, tmp_path, kind):
    """A legacy file that tries to call a function is refused with a LegacyError naming the file
    and the global, and the call never happens."""
    folder, _ = legacy
    bad = tmp_path / "bad"
    bad.mkdir()
    for name in LEGACY_FILES:
        (bad / name).write_bytes((folder / name).read_bytes())
    marker = tmp_path / "pwned"
    _dump(bad, "Lake_info.pkl", [[1, 2], _payloads(marker)[kind]])
    with pytest.raises(LegacyError, match="refused to load") as err:
        import_legacy(bad)
    assert "Lake_info.pkl" in str(err.value)
    assert not marker.exists()


def test_unknown_globals_are_refused_without_import():
    """A global naming a module that does not exist is refused as such (it is never imported)."""
    data = b"\x80\x02cno_such_module\nsomething\nq\x00)\x81q\x01."
    with pytest.raises(LegacyError, match="no_such_module.something"):
        restricted_loads(data)


@given(
    st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(),
        lambda inner: (
            st.lists(inner, max_size=4)
            | st.tuples(inner, inner)
            | st.dictionaries(st.text(max_size=5), inner, max_size=3)
        ),
        max_leaves=20,
    )
)
def test_plain_data_round_trips(value):
    """Lists, tuples, dicts, numbers and strings load exactly as pickle would load them."""
    for protocol in (2, 4):
        assert restricted_loads(pickle.dumps(value, protocol=protocol)) == value


def test_numpy_arrays_and_scalars_load():
    """numpy arrays of every plain dtype and numpy scalars load (protocols 2 and 4)."""
    value = [
        np.arange(6.0).reshape(2, 3),
        np.array([1, 2], np.int16),
        np.float64(2.5),
        np.int64(7),
        np.array(["ab", "c"]),
        np.zeros((0, 4)),
    ]
    for protocol in (2, 4):
        got = restricted_loads(pickle.dumps(value, protocol=protocol))
        for g, v in zip(got, value, strict=True):
            assert np.array_equal(g, v) and np.asarray(g).dtype == np.asarray(v).dtype


def test_malformed_folders(tmp_path, legacy):
    """A missing folder, a folder without the required files, a truncated pickle and a wrong
    layout each raise LegacyError naming the problem."""
    with pytest.raises(LegacyError, match="not a folder"):
        import_legacy(tmp_path / "nope")
    (tmp_path / "empty").mkdir()
    with pytest.raises(LegacyError, match="missing Background_Info.pkl"):
        import_legacy(tmp_path / "empty")
    folder, _ = legacy
    for name, content, match in [
        ("Fire_States.pkl", (folder / "Fire_States.pkl").read_bytes()[:50], "not a readable"),
        ("Background_Info.pkl", pickle.dumps([1, 2]), "Background_Info.pkl"),
        ("Agent_States.pkl", pickle.dumps([[1.0] * 15]), "Agent_States.pkl"),
    ]:
        bad = tmp_path / f"bad_{name}"
        bad.mkdir()
        for f in LEGACY_FILES:
            (bad / f).write_bytes((folder / f).read_bytes())
        (bad / name).write_bytes(content)
        with pytest.raises(LegacyError, match=match):
            import_legacy(bad)
