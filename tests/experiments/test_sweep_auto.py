"""Sweeps with seeds="auto", study hashes on every row, and reports of mixed folders."""

from __future__ import annotations

import pytest

from fcplan.cli import main
from fcplan.errors import FcplanError
from fcplan.experiments import load_results, load_sweep_config, report, sweep
from fcplan.experiments.results import write_row

pytest.importorskip("pandas")

STUDY = {
    "scenarios": ["practice"],
    "schedulers": ["greedy", "idle"],
    "seeds": [0],
    "overrides": {"duration_s": 5},
}


def test_auto_sweep_stops_resumes_and_keeps_one_study(tmp_path):
    """seeds='auto' replaces the file's seeds by batches 0.. until the pair is resolved; every
    row carries the same study hash (the batches are one study); a re-run plays nothing."""
    s = sweep(STUDY, tmp_path, jobs=2, progress=False, seeds="auto", seed_batch=3, max_seeds=9)
    df = load_results(tmp_path)
    n = df["seed"].nunique()
    assert sorted(df["seed"].unique()) == list(range(n)) and n % 3 == 0
    assert s.stopped.startswith("stopped at") and f"seeds auto: {s.stopped}" in s.format()
    assert df["study_hash"].nunique() == 1
    assert df["study_hash"].iloc[0] == load_sweep_config(STUDY).study_hash
    assert s.ran == len(df) and s.total == len(df)
    again = sweep(STUDY, tmp_path, jobs=1, progress=False, seeds="auto", seed_batch=3, max_seeds=9)
    assert again.ran == 0 and again.stopped == s.stopped
    assert len(list(tmp_path.glob("manifest-*.json"))) == 1
    assert report(tmp_path, plots=False).paired["verdict"].tolist() == ["greedy better"]


def test_bad_seeds_argument_is_one_line():
    """seeds= anything but 'auto' or None is refused; so is seeds='auto' in the file."""
    with pytest.raises(FcplanError, match="'auto' or None"):
        sweep(STUDY, "unused", seeds="all", progress=False)
    with pytest.raises(FcplanError, match="--seeds auto"):
        load_sweep_config({**STUDY, "seeds": "auto"})


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """One folder, two studies (different durations), plus an extension of the first."""
    d = tmp_path_factory.mktemp("mixed")
    sweep({**STUDY, "name": "long"}, d, jobs=1, progress=False)
    sweep({**STUDY, "name": "long", "seeds": [0, 1]}, d, jobs=1, progress=False)  # same study
    sweep({**STUDY, "name": "short", "overrides": {"duration_s": 3}}, d, jobs=1, progress=False)
    return d


def test_report_refuses_mixed_studies_and_names_them(mixed, capsys):
    """The report refuses a folder of two studies in one line naming both (by hash and name);
    more seeds of one study are the same study."""
    with pytest.raises(FcplanError) as info:
        report(mixed, plots=False)
    msg = str(info.value)
    assert "2 studies" in msg and "'long' (4 episodes)" in msg and "'short' (2 episodes)" in msg
    assert main(["report", str(mixed)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--allow-mixed" in err


def test_report_one_study_or_all_on_purpose(mixed, tmp_path):
    """--study keeps one study; --allow-mixed pools them and the report says so, pairing
    episodes within a study only."""
    long_hash = load_sweep_config({**STUDY, "name": "long"}).study_hash
    one = report(mixed, tmp_path / "one", plots=False, study=long_hash[:6])
    assert one.tables["per_scheduler"]["episodes"].tolist() == [2, 2]
    both = report(mixed, tmp_path / "both", plots=False, allow_mixed=True)
    assert "pools 2 different studies" in both.markdown
    assert both.paired["pairs"].tolist() == [3]  # 2 pairs in 'long', 1 in 'short'
    assert main(["report", str(mixed), "--allow-mixed", "--out", str(tmp_path / "cli")]) == 0


def test_rows_from_before_study_hashes_still_report(tmp_path):
    """A folder written before study hashes (rows without the column) reports as one study,
    and says so once."""
    sweep(STUDY, tmp_path, jobs=1, progress=False)
    df = load_results(tmp_path)
    for row in df.drop(columns=["study_hash"]).to_dict("records"):
        write_row(tmp_path, row)
    for p in tmp_path.glob("manifest-*.json"):
        p.unlink()
    md = report(tmp_path, plots=False).markdown
    assert md.count("before study hashes") == 1
