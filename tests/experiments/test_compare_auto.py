"""compare(seeds="auto"), resume and the statistics of a comparison."""

from __future__ import annotations

import importlib
import json

import pytest

from fcplan import scheduling
from fcplan.errors import FcplanError
from fcplan.experiments import compare
from fcplan.scenario import load_scenario

compare_mod = importlib.import_module("fcplan.experiments.compare")


def short(seconds: float = 6):
    return load_scenario("practice").replace(duration_s=seconds)


@pytest.fixture(scope="module")
def auto():
    """greedy vs idle on a short practice scenario, seeds auto (batches of 4, cap 12)."""
    return compare(
        [short()], ["greedy", "idle"], "auto", jobs=2, seed_batch=4, max_seeds=12, progress=False
    )


def test_auto_plays_seeds_in_order_until_resolved(auto):
    """The seeds are 0..k-1 for a multiple of the batch; the result says why it stopped and the
    headline pair is resolved by the time it stopped."""
    assert auto.seeds == list(range(len(auto.seeds))) and len(auto.seeds) % 4 == 0
    assert auto.stopped.startswith("stopped at")
    (pair,) = auto.comparisons()
    assert pair.verdict() == "greedy better"
    assert auto.settings["seeds"] == "auto" and auto.settings["max_seeds"] == 12
    assert auto.format().rstrip().endswith(auto.stopped)


def test_auto_is_deterministic_across_jobs(auto):
    """The same auto comparison in this process stops at the same seed count with the same
    scores (seed order fixed, episodes are functions of their seed)."""
    again = compare(
        [short()], ["greedy", "idle"], "auto", jobs=1, seed_batch=4, max_seeds=12, progress=False
    )
    assert again.seeds == auto.seeds and again.stopped == auto.stopped
    key = "manual.final_score"
    assert [e[key] for e in again.episodes] == [e[key] for e in auto.episodes]


def test_unresolvable_pair_runs_to_the_cap(monkeypatch):
    """Two identical schedulers never differ: the comparison stops at the cap and names them."""
    from solvers.baselines import IdleScheduler

    monkeypatch.setitem(scheduling._RUNTIME, "idle-copy", IdleScheduler)
    res = compare(
        [short(3)],
        ["idle", "idle-copy"],
        "auto",
        jobs=1,
        seed_batch=2,
        max_seeds=4,
        progress=False,
    )
    assert res.seeds == [0, 1, 2, 3]
    assert "cap of 4 seeds" in res.stopped and "idle vs idle-copy" in res.stopped
    assert res.comparisons()[0].verdict() == "identical on all 4 pairs"


def test_resume_reuses_episodes_of_the_same_study(tmp_path, monkeypatch):
    """A checkpoint written after each batch lets a re-run reuse every stored episode (nothing
    is played again) and give the same result; another study's file is refused."""
    path = tmp_path / "cmp.json"
    kw = {"jobs": 1, "seed_batch": 2, "max_seeds": 4, "progress": False}
    first = compare([short(3)], ["greedy", "idle"], "auto", checkpoint=path, **kw)
    assert json.loads(path.read_text())["stopped"] == first.stopped
    calls = []
    real = compare_mod.run_episode
    monkeypatch.setattr(
        compare_mod, "run_episode", lambda *a, **k: calls.append(1) or real(*a, **k)
    )
    again = compare([short(3)], ["greedy", "idle"], "auto", resume=path, **kw)
    assert calls == [] and again.seeds == first.seeds and again.stopped == first.stopped
    more = compare([short(3)], ["greedy", "idle"], [0, 1, 2, 3, 4, 5], resume=path, **kw)
    assert len(calls) == 2 * (6 - len(first.seeds))
    assert more.episodes[0]["manual.final_score"] == first.episodes[0]["manual.final_score"]
    with pytest.raises(FcplanError, match="another study"):
        compare([short(4)], ["greedy", "idle"], [0], resume=path, **kw)
    assert compare([short(3)], ["idle"], [0], resume=tmp_path / "none.json", **kw).seeds == [0]


def test_statistics_of_a_comparison_with_the_oracle():
    """With the oracle compared: it is left out of the pairs, every other scheduler gets its
    fraction of the oracle's score, and the text says so; JSON keeps the paired table."""
    res = compare([short(8)], ["greedy", "random", "oracle"], [0, 1, 2], jobs=1, progress=False)
    assert res.references == ["oracle"]
    st = res.statistics()
    assert [(c.a, c.b) for c in st.paired["manual.final_score"]] == [("greedy", "random")]
    assert [f.scheduler for f in st.fractions] == ["greedy", "random"]
    assert "Fraction of oracle" in res.format()
    doc = res.to_dict()
    assert doc["paired"][0]["a"] == "greedy" and "verdict" in doc["paired"][0]


def test_metrics_are_checked_and_several_get_tables():
    """Every metric is a numeric metric column (one-line error otherwise); each gets a table."""
    with pytest.raises(FcplanError, match="not a numeric metric"):
        compare([short(3)], ["idle"], [0], metrics=["manual.grade"], progress=False)
    res = compare(
        [short(3)],
        ["greedy", "idle"],
        [0, 1],
        jobs=1,
        progress=False,
        metrics=["outcome.burned_area_cells", "manual.final_score"],
    )
    assert list(res.statistics().paired) == ["outcome.burned_area_cells", "manual.final_score"]
    text = res.format()
    assert text.index("Paired differences: burned") < text.index("Paired differences: final")
