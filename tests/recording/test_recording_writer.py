"""Tests of fcplan.recording.writer: the Recorder observer, the in-memory Recording, its
re-simulation and replay frames, and `run_episode(record=...)`."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.belief import Belief
from fcplan.cli import main
from fcplan.recording import (
    FORMAT_VERSION,
    WORLD_ENTRIES,
    Recorder,
    Recording,
    RecordingError,
    load_recording,
)
from fcplan.render import snapshot
from fcplan.team import Command


def _human_game(seed: int = 5, ticks: int = 400, picks=None) -> tuple[World, Recorder]:
    """A scripted 'human' game on practice: routes, a patrol loop, altitude, home, int keys."""
    sc = load_scenario("practice")
    world = World().reset(sc, seed)
    rec = Recorder(sc, seed, source="human", settings={"pace": "real-time"})
    script = (
        picks
        if picks is not None
        else {
            0: {"P1": Command(route=((350.0, 350.0), (450.0, 350.0)), patrol=True, altitude=40.0)},
            5: {"A1": Command(route=((350.0, 350.0),)), 1: Command(altitude=80.0)},
            60: {"A2": Command(route=((300.0, 400.0), (360.0, 330.0)))},
            150: {"P1": Command(altitude=25.0), "A1": Command(home=True)},
            200: {"P2": Command(route=())},
        }
    )
    for t in range(ticks):
        cmds = script.get(t)
        if cmds:
            rec.on_input(t, {"type": "script", "agents": [str(k) for k in cmds]})
        rec.on_commands(t, cmds)
        rec.on_step(world, world.step(cmds))
    return world, rec


def test_recorded_metrics_equal_the_episode(recorded):
    """The recording alone reproduces every metric of both definitions exactly."""
    result, path = recorded
    rec = load_recording(path)
    got = rec.metrics()
    assert set(got) == set(result.metrics)
    for name, m in result.metrics.items():
        assert got[name].as_dict() == m.as_dict()
    for name, arr in result.trace.arrays().items():
        assert np.array_equal(rec.arrays[name], arr), name


def test_resimulation_is_identical(recorded):
    """Re-simulating a scheduler run from its header and commands reproduces every world array."""
    _, path = recorded
    rec = load_recording(path)
    again = rec.resimulate()
    assert again.mismatches(rec) == []
    assert again.metrics()["manual"].as_dict() == rec.metrics()["manual"].as_dict()


def test_header_and_replans(recorded):
    """The header names scenario, seed, scheduler, settings and versions; plans and replan ticks
    are kept, one per scheduler call."""
    result, path = recorded
    rec = load_recording(path)
    assert rec.header["format_version"] == FORMAT_VERSION
    assert rec.seed == 1 and rec.source == "greedy"
    assert rec.scenario == load_scenario(24)
    assert rec.settings["replan_period"] == 1.0
    assert {"fcplan", "numpy", "python"} <= set(rec.header["versions"])
    assert np.array_equal(rec.arrays["replan_tick"], result.replan_ticks)
    assert len(rec.replans) == len(result.solves)
    assert rec.replans[0]["stats"]["status"] == result.solves[0].status
    assert os.path.getsize(path) <= 5_000_000  # the budget for a 180-s episode of #24


def test_fire_events_add_up_to_the_trace(recorded):
    """Cumulative ignitions minus prunes equal the active count each tick; prunes equal P."""
    _, path = recorded
    a = load_recording(path).arrays
    ign, pr = np.cumsum(a["ignited_count"]), np.cumsum(a["pruned_count"])
    assert np.array_equal(ign - pr, a["active"])
    assert np.array_equal(pr, a["pruned"])
    assert np.array_equal(np.cumsum(a["sensed_count"]), a["sensed_ever"])


def test_human_game_resimulates_and_replays():
    """A scripted human game (patrol, altitude, home, stop, int keys) re-simulates identically,
    keeps its inputs, and its frames equal live snapshots of the world (fire, belief, agents,
    routes ahead)."""
    sc = load_scenario("practice")
    checkpoints = {1, 7, 61, 149, 151, 230, 400}
    world = World().reset(sc, 5)
    belief = Belief(sc)
    rec = Recorder(sc, 5, source="human", settings={})
    live = {}
    script = {
        0: {"P1": Command(route=((350.0, 350.0), (450.0, 350.0)), patrol=True, altitude=40.0)},
        5: {"A1": Command(route=((350.0, 350.0),)), 1: Command(altitude=80.0)},
        60: {"A2": Command(route=((300.0, 400.0), (360.0, 330.0)))},
        150: {"P1": Command(altitude=25.0), "A1": Command(home=True)},
        200: {"P2": Command(route=())},
    }
    for t in range(400):
        cmds = script.get(t)
        rec.on_commands(t, cmds)
        info = world.step(cmds)
        belief.update(info)
        rec.on_step(world, info)
        if world.tick in checkpoints:
            live[world.tick] = snapshot(world, belief)
    recording = rec.recording()
    assert recording.resimulate().mismatches(recording) == []
    frames = {f.tick: f for f in recording.frames(1, 400) if f.tick in checkpoints}
    assert set(frames) == checkpoints
    for t, want in live.items():
        got = frames[t]
        for name in (
            "fire",
            "known",
            "pruned",
            "agent_pos",
            "agent_z",
            "agent_battery",
            "agent_tank",
            "agent_mode",
        ):
            assert np.array_equal(getattr(got, name), getattr(want, name)), (t, name)
        for i, (r_got, r_want) in enumerate(zip(got.routes, want.routes, strict=True)):
            assert np.array_equal(r_got, r_want), (t, i)


def test_inputs_round_trip(tmp_path):
    """Human inputs are saved in order with their ticks and come back as the same dicts."""
    _, rec = _human_game(ticks=100)
    path = tmp_path / "human.npz"
    rec.save(path)
    back = load_recording(path)
    assert back.source == "human"
    assert back.inputs == [
        {"type": "script", "agents": ["P1"]},
        {"type": "script", "agents": ["A1", "1"]},
        {"type": "script", "agents": ["A2"]},
    ]
    assert back.arrays["input_tick"].tolist() == [0, 5, 60]
    assert back.resimulate().mismatches(back) == []


def test_bad_hook_input_is_refused():
    """Non-JSON input events and commands for unknown agents raise RecordingError."""
    rec = Recorder(load_scenario("practice"), 0, source="human")
    with pytest.raises(RecordingError, match="JSON"):
        rec.on_input(0, {"obj": object()})
    with pytest.raises(RecordingError, match="unknown agent"):
        rec.on_commands(0, {"Z9": Command(altitude=20.0)})


def test_unseeded_recording_cannot_resimulate():
    """A recording without an integer seed says so instead of re-simulating something else."""
    sc = load_scenario("practice")
    world = World().reset(sc, None)
    rec = Recorder(sc, None, source="human")
    rec.on_step(world, world.step())
    with pytest.raises(RecordingError, match="seed"):
        rec.recording().resimulate()


def test_cli_run_record(tmp_path, capsys):
    """`fcplan run --record` writes a recording whose metrics are the run's."""
    path = tmp_path / "p.npz"
    assert main(["run", "practice", "--seed", "2", "--record", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    rec = load_recording(path)
    assert rec.metrics()["manual"].as_dict() == out["metrics"]["manual"]


@settings(max_examples=8, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.integers(0, 59),
            st.sampled_from(["P1", "P2", "A1", "A2", 0, 3]),
            st.lists(st.tuples(st.floats(0, 1199), st.floats(0, 1199)), max_size=3),
            st.booleans(),
            st.one_of(st.none(), st.floats(0, 150)),
            st.booleans(),
        ),
        max_size=12,
    ),
    st.integers(0, 2**31),
)
def test_any_command_sequence_resimulates(cmds, seed):
    """Whatever commands a player gives (any routes, patrols, altitudes, home), the saved
    recording re-simulates to identical world arrays."""
    script: dict[int, dict] = {}
    for t, agent, route, patrol, alt, home in cmds:
        script.setdefault(t, {})[agent] = Command(
            route=None if home else tuple(route), patrol=patrol, altitude=alt, home=home
        )
    _, rec = _human_game(seed=seed % 1000, ticks=60, picks=script)
    recording = rec.recording()
    assert recording.resimulate().mismatches(recording) == []
    assert set(WORLD_ENTRIES) <= set(recording.arrays)
    assert isinstance(recording, Recording)
