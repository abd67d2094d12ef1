"""Verifying a results folder: stored episodes played again must give the stored numbers."""

from __future__ import annotations

import json

import pytest

from fcplan.cli import main
from fcplan.errors import FcplanError
from fcplan.experiments import load_results, sweep, verify_results
from fcplan.experiments import play as play_module
from fcplan.experiments.results import write_row

pytest.importorskip("pandas")
pytest.importorskip("pyarrow")

SMALL = {
    "scenarios": ["practice"],
    "schedulers": ["greedy", "idle"],
    "seeds": [0, 1, 2],
    "overrides": {"duration_s": 4},
}


@pytest.fixture
def results(tmp_path):
    sweep(SMALL, tmp_path / "results", jobs=1, progress=False)
    return tmp_path / "results"


def _rewrite(folder, key, **changes):
    """Store the row ``key`` again with ``changes`` (as a later run would have stored it)."""
    df = load_results(folder)
    row = dict(df[df.key == key].iloc[0])
    row.update(changes)
    write_row(folder, {k: (v.tolist() if hasattr(v, "tolist") else v) for k, v in row.items()})


def test_unchanged_code_reproduces_every_sampled_episode(results):
    """The code that played a folder reproduces its episodes exactly: every check is 'same'."""
    v = verify_results(results, per_scheduler=3)
    assert [c.status for c in v.checks] == ["same"] * 6
    assert sorted({c.scheduler for c in v.checks}) == ["greedy", "idle"]
    assert v.ok and v.stale == []
    assert v.format().splitlines()[-1] == "ok: 6 episode(s) reproduced exactly"


def test_a_change_of_behaviour_makes_the_scheduler_stale(results, monkeypatch):
    """When today's code plays an episode differently, the scheduler is named stale and the
    differing column is reported with its stored and replayed values."""
    real = play_module.run_episode

    def changed(scenario, scheduler, *, seed, **kw):
        if getattr(scheduler, "name", "") == "greedy":
            seed = seed + 100  # the "new behaviour": another episode
        return real(scenario, scheduler, seed=seed, **kw)

    monkeypatch.setattr(play_module, "run_episode", changed)
    v = verify_results(results, per_scheduler=2)
    assert v.stale == ["greedy"] and not v.ok
    greedy = [c for c in v.checks if c.scheduler == "greedy"]
    assert all(c.status == "differs" for c in greedy)
    col, old, new = greedy[0].differences[0]
    assert col.startswith(("manual.", "reference2020.", "outcome.")) and old != new
    assert all(c.status == "same" for c in v.checks if c.scheduler == "idle")
    assert "STALE" in v.format() and "greedy" in v.format().splitlines()[-1]


def test_a_tampered_row_is_caught(results):
    """A stored number that the episode does not give is reported, whatever the column."""
    key = load_results(results).query("scheduler == 'idle'").key.iloc[0]
    _rewrite(results, key, **{"manual.final_score": 1234.5})
    v = verify_results(results, per_scheduler=3, schedulers=["idle"])
    bad = [c for c in v.checks if c.key == key]
    assert bad[0].status == "differs"
    assert bad[0].differences[0][0] == "manual.final_score"
    assert bad[0].differences[0][1] == 1234.5


def test_episodes_that_cannot_be_checked_are_counted_by_reason(results):
    """Failed episodes, wall-time episodes and episodes no manifest rebuilds are never drawn:
    they are counted by reason, and a label with nothing checkable is unverified, not ok."""
    keys = list(load_results(results).query("scheduler == 'greedy'").key)
    _rewrite(results, keys[0], deterministic=False)
    _rewrite(results, keys[1], status="failed", error="RuntimeError: boom")
    v = verify_results(results, per_scheduler=3, schedulers=["greedy"])
    assert [(c.key, c.status) for c in v.checks] == [(keys[2], "same")]
    reasons = v.skipped["greedy"]
    assert reasons["failed"] == 1
    assert [n for r, n in reasons.items() if "wall-time mode" in r] == [1]
    assert v.ok and "cannot be checked: 1 failed" in v.format()
    for manifest in results.glob("manifest-*.json"):
        manifest.unlink()
    v = verify_results(results, per_scheduler=1, schedulers=["idle"])
    assert v.checks == [] and v.unverified == ["idle"] and not v.ok
    assert v.skipped["idle"] == {"no manifest in the folder rebuilds them": 3}
    assert "UNVERIFIED" in v.format()


def test_a_replay_that_fails_is_a_difference(results, monkeypatch):
    """An episode that played before and raises now has changed behaviour: it differs."""

    def broken(*args, **kwargs):
        raise RuntimeError("new bug")

    monkeypatch.setattr(play_module, "run_episode", broken)
    v = verify_results(results, per_scheduler=1, schedulers=["idle"])
    assert v.stale == ["idle"]
    assert v.checks[0].differences[0] == ("status", "ok", "RuntimeError: new bug")


def test_the_draw_is_seeded(results):
    """The same seed on the same folder checks the same episodes; the sample is per label."""
    a = verify_results(results, per_scheduler=1, seed=5)
    b = verify_results(results, per_scheduler=1, seed=5)
    assert [c.key for c in a.checks] == [c.key for c in b.checks]
    assert len(a.checks) == 2


def test_bad_arguments_are_one_line_errors(results, tmp_path):
    """A missing folder, a per-scheduler count below 1 and an unknown label are FcplanErrors."""
    with pytest.raises(FcplanError, match="no such results folder"):
        verify_results(tmp_path / "nope")
    with pytest.raises(FcplanError, match="per_scheduler"):
        verify_results(results, per_scheduler=0)
    with pytest.raises(FcplanError, match="no episodes of scheduler 'cbba'"):
        verify_results(results, schedulers=["cbba"])


def test_cli_exit_status_says_whether_the_folder_holds(results, monkeypatch, capsys, tmp_path):
    """`fcplan verify` exits 0 when every check holds, 1 when a scheduler is stale, 2 on bad
    input, and --json writes every check."""
    out = tmp_path / "v.json"
    assert main(["verify", str(results), "--json", str(out)]) == 0
    assert "ok: 2 episode(s)" in capsys.readouterr().out
    assert json.loads(out.read_text())["stale"] == []
    key = load_results(results).query("scheduler == 'greedy'").key.iloc[0]
    _rewrite(results, key, **{"outcome.burned_area_cells": -1})
    assert main(["verify", str(results), "--per-scheduler", "3", "--scheduler", "greedy"]) == 1
    assert "STALE" in capsys.readouterr().out
    assert main(["verify", str(results), "--per-scheduler", "0"]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
