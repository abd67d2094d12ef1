"""Sweeps: backends agree, failures are recorded, interrupted sweeps resume exactly once."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fcplan import scheduling
from fcplan.experiments import load_results, load_sweep_config, sweep
from tests.experiments.schedulers import DiesOnce

pytest.importorskip("pyarrow")
pytest.importorskip("pandas")

TINY = {
    "scenarios": ["practice", 1],
    "schedulers": ["greedy", "random"],
    "seeds": [0, 1],
    "replan_period": 2.0,
    "overrides": {"duration_s": 40},
}
METRIC_PREFIXES = ("manual.", "reference2020.")


def _metrics(df):
    cols = [c for c in df.columns if c.startswith(METRIC_PREFIXES)]
    return df.set_index(["scenario", "scheduler", "seed"]).sort_index()[cols]


def _assert_exactly_once(results: Path, config) -> None:
    df = load_results(results)
    keys = [e.key for e in load_sweep_config(config).episodes()]
    assert sorted(df["key"]) == sorted(keys)
    assert (df["status"] == "ok").all(), df.loc[df["status"] != "ok", "error"].tolist()
    assert not [p for p in results.iterdir() if p.name.endswith(".tmp")]


def test_local_pool_and_dask_local_give_identical_metrics(tmp_path):
    """The same sweep on the process pool and on --dask local has identical metrics per
    (scenario, scheduler, seed)."""
    pytest.importorskip("distributed")
    a = sweep(TINY, tmp_path / "pool", jobs=2, progress=False)
    b = sweep(TINY, tmp_path / "dask", jobs=2, dask="local", progress=False)
    assert a.backend.startswith("pool") and b.backend == "dask:local"
    assert a.ran == b.ran == 8 and a.failed == b.failed == 0
    ma, mb = _metrics(a.load()), _metrics(b.load())
    assert ma.index.equals(mb.index) and len(ma) == 8
    assert ma.equals(mb)
    assert np.isfinite(ma["manual.final_score"]).all()


class _FailsInWorkers:
    """A scheduler that can be built in the test process but raises in any other process."""

    name = "fails-in-workers"

    def __init__(self, parent: int = 0):
        if os.getpid() != parent:
            raise RuntimeError("injected failure")
        self._greedy = scheduling.make_scheduler("greedy")

    def plan(self, graph, *, time_limit=None, rng=None):
        return self._greedy.plan(graph, time_limit=time_limit, rng=rng)


def _greedy_factory(**settings):
    return scheduling.make_scheduler("greedy")


def test_failing_episodes_are_recorded_and_retried_on_request(tmp_path, monkeypatch):
    """A worker raising stores failed rows (with the error) and the rest completes; a re-run
    skips them unless retry_failed, which replaces them: every episode exactly once."""
    monkeypatch.setitem(scheduling._RUNTIME, "flaky", _FailsInWorkers)
    config = {
        **TINY,
        "scenarios": ["practice"],
        "schedulers": ["greedy", {"name": "flaky", "settings": {"parent": os.getpid()}}],
    }
    first = sweep(config, tmp_path, jobs=2, progress=False)
    assert (first.ran, first.failed, first.lost) == (4, 2, [])
    df = load_results(tmp_path)
    bad = df[df["status"] == "failed"]
    assert set(bad["scheduler_name"]) == {"flaky"}
    assert bad["error"].str.contains("RuntimeError: injected failure").all()
    assert np.isnan(bad["manual.final_score"].astype(float)).all()
    assert (df.loc[df["status"] == "ok", "scheduler"] == "greedy").all()
    again = sweep(config, tmp_path, jobs=2, progress=False)
    assert (again.ran, again.skipped) == (0, 4)
    monkeypatch.setitem(scheduling._RUNTIME, "flaky", _greedy_factory)
    fixed = sweep(config, tmp_path, jobs=2, progress=False, retry_failed=True)
    assert (fixed.ran, fixed.failed, fixed.skipped) == (2, 0, 2)
    _assert_exactly_once(tmp_path, config)


def test_killed_worker_loses_only_episodes_in_flight(tmp_path, monkeypatch):
    """A worker process that dies mid-episode breaks the pool; the pool restarts, the episodes in
    flight run again, and every episode is stored exactly once."""
    monkeypatch.setitem(scheduling._RUNTIME, "dies-once", DiesOnce)
    marker = tmp_path / "died"
    config = {
        **TINY,
        "schedulers": ["greedy", {"name": "dies-once", "settings": {"marker": str(marker)}}],
    }
    res = sweep(config, tmp_path / "r", jobs=2, progress=False)
    assert marker.exists()
    assert (res.ran, res.failed, res.lost) == (8, 0, [])
    _assert_exactly_once(tmp_path / "r", config)


def test_sigint_to_the_parent_then_rerun_completes_exactly_once(tmp_path):
    """Ctrl-C (SIGINT) to `fcplan sweep` stops it with status 130, leaving only whole rows; the
    same command then finishes with every episode stored exactly once."""
    cfg = tmp_path / "study.toml"
    cfg.write_text(
        'scenarios = ["practice", 1, 2]\nschedulers = ["greedy", "random"]\nseeds = "0-3"\n'
        "replan_period = 2.0\n[overrides]\nduration_s = 120\n",
        encoding="utf-8",
    )
    results = tmp_path / "results"
    cmd = [sys.executable, "-m", "fcplan", "sweep", str(cfg), "--results", str(results), "-j", "2"]
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a shell may start pytest with SIGINT ignored; the sweep must see Ctrl-C as a user would
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and proc.poll() is None:
        if results.is_dir() and any(p.suffix == ".parquet" for p in results.iterdir()):
            break
        time.sleep(0.02)
    assert proc.poll() is None, "the sweep ended before it could be interrupted"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted" in err
    partial = load_results(results)  # only whole rows: every file reads
    assert (partial["status"] == "ok").all() and 1 <= len(partial) < 24
    rerun = subprocess.run(cmd + ["-q"], capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert f"{len(partial)} already stored" in rerun.stdout
    _assert_exactly_once(results, cfg)


def test_progress_callback_and_summary(tmp_path):
    """progress(done, total, row) is called once per episode run; resumed episodes are skipped."""
    calls = []
    config = {**TINY, "scenarios": ["practice"], "overrides": {"duration_s": 5}}
    s = sweep(config, tmp_path, jobs=1, progress=lambda d, t, r: calls.append((d, t)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert "4 run now" in s.format() and s.backend == "serial"


def test_episodes_play_seed_by_seed_so_a_stopped_study_holds_whole_instances(tmp_path):
    """The first seed of every (scenario, scheduler) plays before any second seed, so a sweep
    stopped after that round has every scheduler on every scenario at seed 0 (paired over the
    whole grid), and a resumed sweep keeps the order for what is left."""
    config = {**TINY, "seeds": [3, 0, 1], "overrides": {"duration_s": 5}}
    order = []
    sweep(config, tmp_path, jobs=1, progress=lambda d, t, r: order.append(r["seed"]))
    assert order == [3] * 4 + [0] * 4 + [1] * 4  # the seeds' order in the file, 4 episodes each
    for p in sorted(tmp_path.glob("*.parquet"))[:5]:  # lose five stored episodes
        p.unlink()
    again = []
    sweep(config, tmp_path, jobs=1, progress=lambda d, t, r: again.append(r["seed"]))
    assert again == sorted(again, key=[3, 0, 1].index) and len(again) == 5


def test_sweeps_run_schedulers_in_their_deterministic_mode_by_default(tmp_path):
    """A sweep adds deterministic=true to schedulers that support it (recorded in the settings
    and deterministic columns); deterministic=False or a file's deterministic = false leaves it
    out, and a variant's own setting always wins."""
    config = {
        "scenarios": ["practice"],
        "schedulers": ["greedy", "routing", "routing:deterministic=false"],
        "seeds": [0],
        "overrides": {"duration_s": 3},
    }
    cfg = load_sweep_config(config)
    settings = {v.label: v.settings for v in cfg.schedulers}
    assert settings == {
        "greedy": {},
        "routing": {"deterministic": True},
        "routing:deterministic=false": {"deterministic": False},
    }
    assert load_sweep_config({**config, "deterministic": False}).schedulers[1].settings == {}
    assert load_sweep_config(config, deterministic=False).schedulers[1].settings == {}
    s = sweep({**config, "schedulers": ["greedy", "routing"]}, tmp_path, jobs=1, progress=False)
    df = s.load().set_index("scheduler")
    assert df.loc["routing", "settings"] == '{"deterministic": true}'
    assert bool(df.loc["routing", "deterministic"]) and bool(df.loc["greedy", "deterministic"])
    assert not df["fallback_majority"].any()
