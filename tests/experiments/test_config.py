"""Sweep files: grid expansion, keys, and errors naming the file, the field and what is allowed."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.cli import main
from fcplan.experiments import SweepConfigError, load_sweep_config


def _write(tmp_path, text):
    p = tmp_path / "study.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_toml_grid_expands_in_documented_order(tmp_path):
    """Scenarios x overrides x replan periods x scheduler variants x seeds, last fastest."""
    p = _write(
        tmp_path,
        'scenarios = ["practice", 1]\nseeds = [3, 4]\nreplan_period = [1, 2]\n'
        'schedulers = ["greedy", {name = "milp", grid = {slots = [2, 3]}}]\n'
        '[overrides]\n"team.perception.count" = [1, 2]\n"fire.regions[*].wind_speed" = 7\n',
    )
    cfg = load_sweep_config(p)
    eps = cfg.episodes()
    assert len(eps) == 2 * 2 * 2 * 3 * 2
    assert [e.label for e in eps[:6]] == ["greedy"] * 2 + ["milp:slots=2"] * 2 + [
        "milp:slots=3"
    ] * 2
    assert eps[0].overrides == {"team.perception.count": 1, "fire.regions[*].wind_speed": 7}
    assert eps[0].scenario.team_counts["perception"] == 1
    assert all(
        r.wind_speed == 7 for e in eps for r in e.scenario.regions if e.base_scenario == "#1"
    )
    assert len({e.key for e in eps}) == len(eps)
    assert cfg.config_hash == load_sweep_config(p).config_hash


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('scenarios = ["practice"]\nschedulers = ["greedy"]\nseeds = "x"\n', "seeds: expected"),
        ('scenarios = ["practice"]\nschedulers = ["gredy"]\nseeds = 0\n', "unknown scheduler"),
        ('scenarios = ["nope"]\nschedulers = ["greedy"]\nseeds = 0\n', "scenarios: unknown"),
        ('scenarios = [1]\nschedulers = ["greedy"]\nseeds = 0\nreplan = 1\n', "unknown key"),
        ('scenarios = [1]\nschedulers = ["greedy"]\nseeds = 0\nreplan_period = -1\n', "> 0"),
        (
            'scenarios = [1]\nschedulers = ["greedy:bogus=1"]\nseeds = 0\n',
            "schedulers\\[0\\]: scheduler 'greedy': bad setting bogus=1",
        ),
        (
            'scenarios = [1]\nschedulers = ["greedy"]\nseeds = 0\n[overrides]\n"tem.x" = 1\n',
            "no field 'tem' here; fields: .*team",
        ),
        (
            'scenarios = [1]\nschedulers = ["greedy"]\nseeds = 0\n[overrides]\n'
            '"team.action.tank" = [5, 0]\n',
            "make scenario #1 invalid: .*team.action.tank",
        ),
        ("scenarios = [1\n", "not valid TOML"),
    ],
)
def test_bad_files_name_file_and_field(tmp_path, text, match, capsys):
    """Each mistake raises SweepConfigError with the file and field; the CLI exits 2, one line."""
    p = _write(tmp_path, text)
    with pytest.raises(SweepConfigError, match=match) as e:
        load_sweep_config(p)
    assert str(e.value).startswith(str(p))
    assert main(["sweep", str(p), "--results", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(p) in err


def test_plus_joined_paths_share_one_axis():
    """`a+b` = [values] is one axis that sets both paths to each value."""
    cfg = load_sweep_config(
        {
            "scenarios": [12],
            "schedulers": ["greedy"],
            "seeds": [0],
            "overrides": {"team.perception.count+team.action.count": [1, 3]},
        }
    )
    eps = cfg.episodes()
    assert [e.scenario.team_counts for e in eps] == [
        {"perception": 1, "action": 1, "hybrid": 0},
        {"perception": 3, "action": 3, "hybrid": 0},
    ]


def test_missing_file_is_named(tmp_path):
    """A sweep file that does not exist is a one-line error naming it."""
    with pytest.raises(SweepConfigError, match="no such sweep file"):
        load_sweep_config(tmp_path / "absent.toml")


@settings(max_examples=15, deadline=None)
@given(
    seeds=st.lists(st.integers(0, 50), min_size=1, max_size=4, unique=True),
    durations=st.lists(st.integers(2, 30), min_size=1, max_size=3, unique=True),
    n_sched=st.integers(1, 3),
)
def test_grid_size_is_the_product_of_axes_and_keys_are_unique(seeds, durations, n_sched):
    """Expansion gives one episode per combination, each with its own key."""
    scheds = ["greedy", "idle", "random"][:n_sched]
    cfg = load_sweep_config(
        {
            "scenarios": ["practice"],
            "schedulers": scheds,
            "seeds": seeds,
            "overrides": {"duration_s": durations},
        }
    )
    eps = cfg.episodes()
    assert len(eps) == len(seeds) * len(durations) * n_sched
    assert len({e.key for e in eps}) == len(eps)
