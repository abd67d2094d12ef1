"""Suite scenarios load by name everywhere a scenario name is accepted; suites are written and
read back; bad names and manifests give one-line errors."""

from __future__ import annotations

import json

import pytest

from fcplan.cli import main
from fcplan.errors import ScenarioError, UnknownNameError
from fcplan.experiments.config import load_sweep_config
from fcplan.scenario import list_scenarios, load_scenario, scenario_path
from fcplan.scenario.suite import (
    SUITE_VERSION,
    freeze_entry,
    load_suite,
    read_suite,
    suite_of,
    suite_scenario_path,
    suite_versions,
    write_suite,
)


def test_short_and_qualified_names_load_the_same_file():
    """``hard-01``, ``HARD-01`` and ``fcplan-bench-v1/hard-01`` name one file, whose scenario is
    named with the suite version (so results record it)."""
    path = scenario_path("fcplan-bench-v1/hard-01")
    assert scenario_path("hard-01") == scenario_path(" HARD-01 ") == path
    assert load_scenario("hard-01").name == "fcplan-bench-v1/hard-01"
    assert suite_of(load_scenario("scale-06").name) == SUITE_VERSION


def test_list_scenarios_keeps_the_manual_and_adds_the_suites_on_request():
    """list_scenarios() is unchanged (practice, 1..24, examples); with suites=True every shipped
    suite's qualified names follow, oldest suite first (v1's 18, then v2's 12)."""
    plain, every = list_scenarios(), list_scenarios(suites=True)
    assert every[: len(plain)] == plain and len(plain) == 27
    assert every[len(plain) :] == [n for v in suite_versions() for n in load_suite(v).names()]
    assert len(every) == 27 + 18 + 12
    assert len(load_suite().names("hard")) == 12 and len(load_suite().names("scale")) == 6


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("hard-13", "unknown scenario 'hard-13'"),
        ("fcplan-bench-v1/hard-13", "suite fcplan-bench-v1 has no scenario"),
        ("fcplan-bench-v9/hard-01", "unknown benchmark suite 'fcplan-bench-v9'"),
    ],
)
def test_unknown_suite_names_fail_in_one_line(name, text):
    """A name shaped like a suite scenario that does not exist is an UnknownNameError listing
    what does."""
    with pytest.raises(UnknownNameError) as info:
        load_scenario(name)
    msg = str(info.value)
    assert text in msg and "\n" not in msg
    assert "fcplan-bench-v1" in msg  # what exists is listed


def test_unknown_tier_names_the_known_tiers():
    """Suite.names of a tier the suite lacks lists its tiers."""
    with pytest.raises(UnknownNameError, match="tiers: hard, scale"):
        load_suite().names("medium")


def test_suite_names_work_in_the_cli_and_sweep_files(capsys):
    """``fcplan scenario validate`` and sweep configurations accept suite names."""
    assert main(["scenario", "validate", "hard-02", "fcplan-bench-v1/scale-01"]) == 0
    assert capsys.readouterr().out.count("valid") == 2
    cfg = load_sweep_config({"scenarios": ["hard-03"], "schedulers": ["idle"], "seeds": [0]})
    assert cfg.episodes()[0].base_scenario == "fcplan-bench-v1/hard-03"


def test_fcplan_scenarios_lists_the_tiers(capsys):
    """``fcplan scenarios`` lists the suite's scenarios after the manual's."""
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "fcplan-bench-v1/hard-01" in out and "fcplan-bench-v1/scale-06" in out


def test_paths_and_non_suite_names_are_left_alone():
    """A .toml path or a manual name is not taken for a suite scenario."""
    assert suite_scenario_path("hard-01.toml") is None
    assert suite_scenario_path("12") is None and suite_scenario_path("practice") is None
    assert scenario_path("hard-01.toml").name == "hard-01.toml"


def test_written_suite_reads_back_and_regenerates(tmp_path):
    """write_suite stores files and a manifest that read_suite reads back to equal entries,
    whose files equal their regeneration."""
    entries = [
        freeze_entry(
            "tiny-bench-v1", f"tiny-{k:02d}", "tiny", seed, n_regions=(1, 2), duration_s=60
        )
        for k, seed in enumerate((3, 8), 1)
    ]
    write_suite(tmp_path / "tiny-bench-v1", entries, "two tiny scenarios")
    suite = read_suite(tmp_path / "tiny-bench-v1")
    assert suite.entries == tuple(entries) and suite.description == "two tiny scenarios"
    for e in suite.entries:
        assert (suite.folder / e.file).read_text() == e.text()


def test_write_suite_refuses_a_folder_of_another_version(tmp_path):
    """The folder is named after the suite version its entries carry."""
    e = freeze_entry("tiny-bench-v1", "tiny-01", "tiny", 1, duration_s=60)
    with pytest.raises(ValueError, match="tiny-bench-v1"):
        write_suite(tmp_path / "other-bench-v1", [e])


def test_bad_manifests_fail_in_one_line(tmp_path):
    """A missing manifest, a version that does not match the folder, or a record with a bad knob
    is a one-line ScenarioError naming the manifest."""
    folder = tmp_path / "x-bench-v1"
    folder.mkdir()
    with pytest.raises(ScenarioError, match="manifest.json: manifest: cannot be read"):
        read_suite(folder)
    (folder / "manifest.json").write_text(json.dumps({"suite": "y-bench-v1", "scenarios": []}))
    with pytest.raises(ScenarioError, match="does not match its folder"):
        read_suite(folder)
    rec = load_suite().entries[0].to_dict()
    rec["knobs"]["tank"] = 0
    (folder / "manifest.json").write_text(json.dumps({"suite": "x-bench-v1", "scenarios": [rec]}))
    with pytest.raises(ScenarioError) as info:
        read_suite(folder)
    assert "scenarios[0]" in str(info.value) and "tank" in str(info.value)
    assert "\n" not in str(info.value)


def test_suite_versions_lists_the_shipped_suite():
    """The shipped suites are found in the package data."""
    assert SUITE_VERSION in suite_versions()
