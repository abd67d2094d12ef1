"""The frozen benchmark suites (fcplan-bench-v1, fcplan-bench-v2): their files are what their
recorded calls draw, every file is a valid scenario that plays, and the wheel ships them."""

from __future__ import annotations

import fnmatch
import hashlib
import json
import tomllib
from pathlib import Path

import pytest

from fcplan import make_scheduler
from fcplan.mission import Mission
from fcplan.scenario import GeneratorConfig, load_scenario, recipe_of
from fcplan.scenario.generate import GENERATOR_VERSION
from fcplan.scenario.suite import SUITE_VERSION, load_suite, suite_versions
from tests.missions import play_until

ROOT = Path(__file__).resolve().parents[2]
SUITE = load_suite()
SUITES = [load_suite(v) for v in suite_versions()]
#: every shipped suite's scenarios, by qualified name ("fcplan-bench-v2/hard-01")
ENTRIES = {f"{s.version}/{e.name}": e for s in SUITES for e in s.entries}
FOLDER = {f"{s.version}/{e.name}": s.folder for s in SUITES for e in s.entries}


def test_suite_has_the_tiers_the_issue_asks_for():
    """fcplan-bench-v1 holds hard-01..hard-12 and scale-01..scale-06, in that order, drawn by
    this generator version."""
    assert SUITE.version == SUITE_VERSION == "fcplan-bench-v1"
    assert [e.name for e in SUITE.entries] == [f"hard-{k:02d}" for k in range(1, 13)] + [
        f"scale-{k:02d}" for k in range(1, 7)
    ]
    assert {t: len(es) for t, es in SUITE.tiers().items()} == {"hard": 12, "scale": 6}
    assert SUITE.generator_version == GENERATOR_VERSION
    assert SUITE.description.startswith("fcplan-bench-v1")


def test_v2_holds_a_hard_tier_of_contested_scenarios():
    """fcplan-bench-v2 holds hard-01..hard-12 of the 'hard' preset on 1,100-1,400 px maps with 5-7
    fire regions; v1 stays the current suite (short names resolve in it), v2 loads by its
    qualified names; both are listed, oldest first."""
    v2 = load_suite("fcplan-bench-v2")
    assert suite_versions() == ["fcplan-bench-v1", "fcplan-bench-v2"]
    assert [e.name for e in v2.entries] == [f"hard-{k:02d}" for k in range(1, 13)]
    assert {e.preset for e in v2.entries} == {"hard"}
    for e in v2.entries:
        s = load_scenario(e.qualified_name)
        assert s.name == f"fcplan-bench-v2/{e.name}"
        assert 1100 <= s.world_size <= 1400 and 5 <= len(s.regions) <= 7
        assert len(s.agents) <= 9 and s.duration_s == 300
    assert load_scenario("hard-01").name == "fcplan-bench-v1/hard-01"


@pytest.mark.parametrize("name", list(ENTRIES))
def test_frozen_file_equals_regenerating_it_from_its_recorded_call(name):
    """The file's bytes are exactly the TOML of the scenario drawn again from the manifest's
    call (seed and every knob), and their SHA-256 is the manifest's."""
    entry = ENTRIES[name]
    data = (FOLDER[name] / entry.file).read_bytes()
    assert data.decode("utf-8") == entry.text()
    assert hashlib.sha256(data).hexdigest() == entry.sha256


@pytest.mark.parametrize("name", list(ENTRIES))
def test_manifest_call_is_the_recipe_the_file_records(name):
    """The scenario's own recipe note and the manifest record the same generator call, and the
    manifest's knobs are the preset's with the recorded overrides applied."""
    entry = ENTRIES[name]
    s = load_scenario(entry.qualified_name)
    recipe = recipe_of(s)
    assert recipe.pop("seed") == entry.seed
    assert recipe == GeneratorConfig(**entry.knobs).as_dict()
    assert s.wind_model == entry.wind_model
    preset = GeneratorConfig.preset(entry.preset, **entry.config().as_dict())
    assert preset == entry.config()
    changed = {k for k, v in entry.config().as_dict().items() if v != GeneratorConfig.preset(entry.preset).as_dict()[k]}  # fmt: skip
    assert changed == set(entry.overrides)


@pytest.mark.parametrize("name", list(ENTRIES))
def test_every_file_validates_and_plays_a_few_ticks(name):
    """Each file loads (validation included) and a greedy team plays 30 ticks on it: time
    advances, the fire burns and no replan falls back."""
    s = load_scenario(name)
    assert s.name == name
    mission = play_until(Mission(s, seed=0), make_scheduler("greedy"), 30)
    trace = mission.world.trace()
    assert mission.world.tick == 30
    assert trace.active[-1] + trace.pruned[-1] > 0
    assert all(st.status != "fallback" for st in mission.solves)


def test_tier_scenarios_meet_the_tiers_description():
    """Hard scenarios are manual-sized (800-1200 px, at most 9 agents, 300 s, late regions);
    scale scenarios are big (3,000 px or more, 18 agents or more, 10 regions or more)."""
    for entry in SUITE.entries:
        s = load_scenario(entry.qualified_name)
        if entry.tier == "hard":
            assert 800 <= s.world_size <= 1200 and len(s.agents) <= 9 and s.duration_s == 300
            assert any(r.delay_s > 0 for r in s.regions)
        else:
            assert s.world_size >= 3000 and len(s.agents) >= 18 and len(s.regions) >= 10


def test_package_data_ships_every_suite_file():
    """pyproject's package-data globs for fcplan match every file of fcplan/data/suites, so an
    installed wheel has the suites."""
    doc = tomllib.loads((ROOT / "pyproject.toml").read_text())
    globs = doc["tool"]["setuptools"]["package-data"]["fcplan"]
    files = [p.relative_to(ROOT / "fcplan").as_posix() for p in (ROOT / "fcplan" / "data").rglob("*") if p.is_file()]  # fmt: skip
    assert files
    unmatched = [f for f in files if not any(fnmatch.fnmatch(f, g) for g in globs)]
    assert unmatched == []


@pytest.mark.parametrize("suite", SUITES, ids=lambda s: s.version)
def test_manifest_is_plain_json_with_one_record_per_file(suite):
    """Each suite's manifest names exactly the TOML files of its folder."""
    doc = json.loads((suite.folder / "manifest.json").read_text())
    assert doc["suite"] == suite.folder.name
    assert sorted(r["file"] for r in doc["scenarios"]) == sorted(
        p.name for p in suite.folder.glob("*.toml")
    )
