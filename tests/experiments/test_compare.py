"""Tests for fcplan.experiments.compare: ranges, the episode grid, tables and result files."""

from __future__ import annotations

import csv
import importlib
import json
import math
import multiprocessing

import pytest

from fcplan import scheduling
from fcplan.errors import FcplanError, UnknownNameError
from fcplan.experiments.compare import (
    METRICS,
    ComparisonResult,
    compare,
)
from fcplan.scenario import load_scenario
from tests.experiments.schedulers import DiesOnce

# the package exports the function `compare`, which shadows the module's name as an attribute
compare_mod = importlib.import_module("fcplan.experiments.compare")

#: Columns that are measurements (they vary between runs); every other column is deterministic.
TIMING = {"solve_p50_ms", "solve_p95_ms", "wall_time_s_mean", "wall_time_s"}


def short(n: int, seconds: float = 20) -> object:
    return load_scenario(n).replace(duration_s=seconds)


@pytest.fixture(scope="module")
def base():
    """2 short scenarios (easy #3, moderate #12) x {greedy, idle} x 2 seeds, serial."""
    return compare([short(3), short(12)], ["greedy", "idle"], [0, 1], jobs=1)


def _scores(rows):
    return [{k: v for k, v in r.items() if k not in TIMING} for r in rows]


def _same(a, b):
    """Equal, NaN == NaN."""
    assert a.keys() == b.keys()
    for k in a:
        if isinstance(a[k], float) and math.isnan(a[k]):
            assert isinstance(b[k], float) and math.isnan(b[k]), k
        else:
            assert a[k] == b[k], k


# ---- validation -------------------------------------------------------------------------------


def test_names_are_validated_before_running(monkeypatch):
    """Unknown scenarios or schedulers and bad numbers fail before any episode runs."""
    ran = []
    monkeypatch.setattr(compare_mod, "run_episode", lambda *a, **k: ran.append(1))
    with pytest.raises(UnknownNameError, match="99"):
        compare([99], ["greedy"], [0], jobs=1)
    with pytest.raises(UnknownNameError, match="known schedulers: .*greedy"):
        compare([short(3)], ["greedy", "nope"], [0], jobs=1)
    for kwargs, match in [
        ({"jobs": 0}, "jobs"),
        ({"replan_period": 0}, "replan_period"),
        ({"time_limit": -1.0}, "time_limit"),
    ]:
        with pytest.raises(FcplanError, match=match):
            compare([short(3)], ["greedy"], [0], **kwargs)
    with pytest.raises(FcplanError, match="seeds"):
        compare([short(3)], ["greedy"], [-1], jobs=1)
    with pytest.raises(FcplanError, match="no schedulers"):
        compare([short(3)], [], [0], jobs=1)
    assert ran == []


def test_scheduler_that_cannot_be_built_is_a_clear_error(monkeypatch):
    """A factory raising at construction gives one FcplanError naming the scheduler, up front."""

    def broken(**settings):
        raise RuntimeError("no licence")

    monkeypatch.setitem(scheduling._RUNTIME, "broken-factory", broken)
    ran = []
    monkeypatch.setattr(compare_mod, "run_episode", lambda *a, **k: ran.append(1))
    with pytest.raises(FcplanError, match="'broken-factory' cannot be created: RuntimeError") as e:
        compare([short(3)], ["greedy", "broken-factory"], [0], jobs=1)
    assert "\n" not in str(e.value) and ran == []


# ---- running ----------------------------------------------------------------------------------


def test_parallel_equals_serial(base):
    """jobs=2 gives the same episodes, in grid order, and the same score columns as jobs=1."""
    par = compare([short(3), short(12)], ["greedy", "idle"], [0, 1], jobs=2)
    assert [(e["scenario"], e["scheduler"], e["seed"]) for e in base.episodes] == [
        (s, p, k) for s in ("#3", "#12") for p in ("greedy", "idle") for k in (0, 1)
    ]
    for a, b in zip(_scores(base.episodes), _scores(par.episodes), strict=True):
        _same(a, b)
    for a, b in zip(_scores(base.table()), _scores(par.table()), strict=True):
        _same(a, b)
    assert par.settings["jobs"] == 2 and base.settings["jobs"] == 1


def test_table_rows_and_columns(base):
    """One row per scheduler with counts, mean/CI of every metric, pooled solve times, fallbacks."""
    rows = base.table()
    assert [r["scheduler"] for r in rows] == ["greedy", "idle"]
    for r in rows:
        assert r["episodes"] == 4 and r["errors"] == 0
        for name in METRICS:
            assert math.isfinite(r[f"{name}_mean"]) and r[f"{name}_ci"] >= 0
        assert r["replans"] == sum(
            e["replans"] for e in base.episodes if e["scheduler"] == r["scheduler"]
        )
        assert 0 <= r["solve_p50_ms"] <= r["solve_p95_ms"]
        assert r["fallbacks"] == 0 and r["fallback_rate"] == 0.0
    eps = [e["manual.final_score"] for e in base.episodes if e["scheduler"] == "greedy"]
    assert rows[0]["final_score_mean"] == pytest.approx(sum(eps) / 4)
    assert rows[1]["ofs_mean"] == 0.0  # idle never prunes


def test_per_difficulty_breakdown(base):
    """by_difficulty splits each scheduler's episodes by Scenario.difficulty, easy before moderate."""
    rows = base.table(by_difficulty=True)
    assert [(r["scheduler"], r["difficulty"]) for r in rows] == [
        ("greedy", "easy"),
        ("greedy", "moderate"),
        ("idle", "easy"),
        ("idle", "moderate"),
    ]
    assert all(r["episodes"] == 2 for r in rows)
    assert "difficulty" in base.format(by_difficulty=True).splitlines()[1]


def test_format_is_a_fixed_width_table(base):
    """format() prints a header line, a column line and one aligned line per scheduler, then
    (unless statistics=False) the paired and ranking tables after a blank line."""
    lines = base.format(statistics=False).splitlines()
    assert lines[0].startswith("8 episodes: 2 scenario(s) x 2 scheduler(s) x 2 seed(s)")
    assert lines[1].split()[:3] == ["scheduler", "n", "err"]
    assert [ln.split()[0] for ln in lines[2:]] == ["greedy", "idle"]
    assert all("±" in ln for ln in lines[2:])
    assert len({len(ln) for ln in lines[1:]}) <= 2  # right-aligned columns
    full = base.format()
    assert str(base) == full and full.startswith(base.format(statistics=False) + "\n\n")
    assert "Paired differences: final score." in full and "Ranking per metric." in full


def test_paired_difference(base):
    """paired(a, b) is the CI of per-(scenario, seed) differences; a minus itself is 0."""
    d = base.paired("greedy", "idle")
    diffs = [
        g["manual.final_score"] - i["manual.final_score"]
        for g, i in zip(
            [e for e in base.episodes if e["scheduler"] == "greedy"],
            [e for e in base.episodes if e["scheduler"] == "idle"],
            strict=True,
        )
    ]
    assert d.n == 4 and d.mean == pytest.approx(sum(diffs) / 4)
    assert base.paired("idle", "idle").mean == 0.0
    with pytest.raises(UnknownNameError):
        base.paired("greedy", "nope")


class _Raises:
    name = "always-raises"

    def plan(self, graph, *, time_limit, rng):
        raise RuntimeError("solver exploded")


def test_raising_scheduler_is_recorded_as_fallbacks(monkeypatch):
    """A run-time scheduler that raises every replan completes its episodes (in worker
    processes too) with every replan a fallback."""
    monkeypatch.setitem(scheduling._RUNTIME, "always-raises", _Raises)
    res = compare([short(3, 10)], ["always-raises", "greedy"], [0, 1], jobs=2)
    row = res.table()[0]
    assert row["scheduler"] == "always-raises" and row["episodes"] == 2 and row["errors"] == 0
    assert row["fallbacks"] == row["replans"] > 0 and row["fallback_rate"] == 1.0
    # greedy stood in for every replan, so the scores equal greedy's
    assert res.episodes[0]["manual.final_score"] == pytest.approx(
        res.episodes[2]["manual.final_score"]
    )


def test_failing_episode_is_recorded_and_others_complete(monkeypatch):
    """An exception escaping an episode is recorded with its message; the rest complete."""
    real = compare_mod.run_episode

    def flaky(scenario, scheduler, *, seed, **kw):
        if scheduler.name == "idle" and seed == 1:
            raise ValueError("boom\nsecond line")
        return real(scenario, scheduler, seed=seed, **kw)

    monkeypatch.setattr(compare_mod, "run_episode", flaky)
    seen = []
    res = compare(
        [short(3, 10)],
        ["greedy", "idle"],
        [0, 1],
        jobs=1,
        progress=lambda d, t, r: seen.append((d, t)),
    )
    assert seen == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert [e["error"] for e in res.episodes] == ["", "", "", "ValueError: boom second line"]
    assert res.errors == [res.episodes[3]]
    rows = {r["scheduler"]: r for r in res.table()}
    assert (rows["greedy"]["episodes"], rows["greedy"]["errors"]) == (2, 0)
    assert (rows["idle"]["episodes"], rows["idle"]["errors"]) == (1, 1)
    assert math.isnan(rows["idle"]["final_score_ci"])  # one completed episode
    assert "1 episode(s) failed" in res.format()


def test_dead_worker_restarts_the_pool_and_every_episode_completes(tmp_path, monkeypatch):
    """A worker process that dies mid-episode breaks the pool; the pool restarts (as for sweeps),
    the episodes in flight run again, and every episode completes with greedy's scores."""
    marker = tmp_path / "died"
    monkeypatch.setitem(scheduling._RUNTIME, "dies-once", DiesOnce)
    dies = f"dies-once:marker={marker}"
    res = compare([short(3, 10)], [dies, "greedy"], [0, 1], jobs=2)
    assert marker.exists()
    assert [e["error"] for e in res.episodes] == [""] * 4
    scores = {(e["scheduler"], e["seed"]): e["manual.final_score"] for e in res.episodes}
    assert [scores[dies, k] for k in (0, 1)] == [scores["greedy", k] for k in (0, 1)]


def test_keyboard_interrupt_stops_workers():
    """Ctrl-C during a parallel comparison re-raises and leaves no worker process behind."""

    def interrupt(done, total, row):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        compare([short(3, 10)], ["greedy", "idle"], [0, 1, 2, 3], jobs=2, progress=interrupt)
    assert multiprocessing.active_children() == []


# ---- files ------------------------------------------------------------------------------------


def test_json_round_trip(base, tmp_path):
    """to_json writes standard JSON (NaN as null) whose table equals table(); from_json gives
    back the same episodes, solve times and tables."""
    path = tmp_path / "cmp.json"
    one = compare([short(3, 10)], ["greedy"], [0], jobs=1)  # n = 1: NaN half-widths
    for res in (base, one):
        res.to_json(path)
        doc = json.loads(path.read_text(), parse_constant=lambda c: pytest.fail(c))
        assert doc["schedulers"] == res.schedulers and len(doc["episodes"]) == len(res.episodes)
        for stored, row in zip(doc["table"], res.table(), strict=True):
            for k, v in row.items():
                assert stored[k] == (None if isinstance(v, float) and math.isnan(v) else v), k
        back = ComparisonResult.from_json(path)
        assert back.solve_times_ms == res.solve_times_ms
        for a, b in zip(back.episodes, res.episodes, strict=True):
            _same(a, b)
        for a, b in zip(back.table(by_difficulty=True), res.table(by_difficulty=True), strict=True):
            _same(a, b)


def test_csv_round_trip(base, tmp_path):
    """to_csv writes the table (header = table keys); the numbers read back equal table()."""
    path = tmp_path / "cmp.csv"
    base.to_csv(path)
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    table = base.table()
    assert len(rows) == len(table) and list(rows[0]) == list(table[0])
    for got, want in zip(rows, table, strict=True):
        for k, v in want.items():
            if isinstance(v, (str, bool)) or v is None:
                assert got[k] == ("" if v is None else str(v))
            else:
                assert float(got[k]) == pytest.approx(v, rel=1e-12, nan_ok=True), k


def test_scheduler_specs_are_compared_as_separate_rows():
    """Two specs of one scheduler with different settings are run and reported as two rows,
    labelled by their specs."""
    from fcplan.experiments import compare as run_compare
    from fcplan.scenario import load_scenario

    sc = load_scenario(3).replace(duration_s=10)
    res = run_compare([sc], ["greedy", "greedy:route_length=1"], [0], jobs=1)
    rows = {r["scheduler"]: r for r in res.table()}
    assert set(rows) == {"greedy", "greedy:route_length=1"}
    assert all(r["episodes"] == 1 and r["errors"] == 0 for r in rows.values())


# ---- deterministic mode ---------------------------------------------------------------------


def test_jobs_do_not_change_the_tables_in_the_deterministic_mode():
    """The same comparison with --jobs 1 and --jobs 2 gives identical tables (every column but
    the timing ones) and episodes for greedy, routing (deterministic mode by default), idle and
    random; every row records the mode."""
    scen = [short(3, 8), short(12, 8)]
    names = ["greedy", "routing", "idle", "random"]
    serial = compare(scen, names, [0, 1], jobs=1)
    pooled = compare(scen, names, [0, 1], jobs=2)
    for a, b in zip(_scores(serial.table()), _scores(pooled.table()), strict=True):
        _same(a, b)
    for a, b in zip(_scores(serial.episodes), _scores(pooled.episodes), strict=True):
        _same(a, b)
    assert all(r["deterministic"] is True for r in serial.table())
    assert serial.settings["deterministic"] is True
    assert " det " in serial.format().splitlines()[2] + " "


def test_the_wall_time_mode_is_explicit_and_recorded():
    """deterministic=False (--wall-time) leaves routing's wall-clock limit on, and a spec's own
    deterministic=false wins over the default; both show as 'wall' in the table."""
    scen = [short(3, 3)]
    wall = compare(scen, ["routing", "greedy"], [0], jobs=1, deterministic=False)
    rows = {r["scheduler"]: r for r in wall.table()}
    assert rows["routing"]["deterministic"] is False and rows["greedy"]["deterministic"] is True
    assert wall.settings["deterministic"] is False
    spec = compare(scen, ["routing:deterministic=false"], [0], jobs=1)
    assert spec.table()[0]["deterministic"] is False
    assert "wall" in spec.format()


def test_episodes_that_mostly_fell_back_are_flagged(monkeypatch):
    """An episode whose scheduler fell back on more than half of its replans carries
    fallback_majority; the table counts them and the text warns under the table."""

    class Broken:
        name = "broken-test"

        def plan(self, graph, *, time_limit=None, rng=None):
            raise RuntimeError("always")

    monkeypatch.setitem(scheduling._RUNTIME, "broken-test", Broken)
    res = compare([short(3, 5)], ["greedy", "broken-test"], [0], jobs=1)
    rows = {r["scheduler"]: r for r in res.table()}
    assert (
        rows["broken-test"]["fallback_majority"] == 1 and rows["greedy"]["fallback_majority"] == 0
    )
    assert res.episodes[1]["fallback_majority"] is True
    assert "broken-test: 1 of 1 episode(s) fell back to greedy" in res.format()
