"""Tests of fcplan.legacy.convert: import_legacy of synthetic 2020 GUI folders (counts, agents,
scenario, malformed folders)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from fcplan.legacy import LEGACY_FILES, LegacyError, import_legacy
from tests.legacy.folders import write_legacy_folder


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
