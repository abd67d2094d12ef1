"""Results folders: atomic one-row files, one-line loading, clear errors for bad files."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.cli import main
from fcplan.errors import FcplanError
from fcplan.experiments import ResultsError, load_results, sweep
from fcplan.experiments.results import stored_status, write_row

pd = pytest.importorskip("pandas")
pytest.importorskip("pyarrow")

SMALL = {
    "scenarios": ["practice"],
    "schedulers": ["idle"],
    "seeds": [0],
    "overrides": {"duration_s": 3},
}


@pytest.fixture
def results(tmp_path):
    sweep(SMALL, tmp_path, jobs=1, progress=False)
    return tmp_path


@pytest.mark.parametrize(
    ("name", "content", "match"),
    [
        ("0123abcd.parquet", b"PAR1 this is not parquet", "not a readable Parquet file"),
        ("notes.txt", b"hello", "foreign file"),
    ],
)
def test_damaged_or_foreign_file_is_a_clear_error(results, name, content, match, capsys):
    """A corrupted Parquet file or a stray file raises ResultsError naming the file, and the CLI
    prints one line and exits 2."""
    (results / name).write_bytes(content)
    with pytest.raises(ResultsError, match=match) as e:
        load_results(results)
    assert name in str(e.value) and "\n" not in str(e.value)
    assert main(["report", str(results)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("fcplan: error:") and name in err and "\n" not in err


def test_parquet_not_written_by_fcplan_is_foreign(results):
    """A valid Parquet file without fcplan's metadata is refused as foreign."""
    pd.DataFrame({"key": ["x"], "status": ["ok"]}).to_parquet(results / "x.parquet")
    with pytest.raises(ResultsError, match="x.parquet: a Parquet file not written by fcplan"):
        load_results(results)


def test_truncated_row_file_is_named(results):
    """A row file cut short (as a non-atomic writer would leave it) is reported, not a crash."""
    good = next(results.glob("*.parquet"))
    data = good.read_bytes()
    (results / "deadbeef.parquet").write_bytes(data[: len(data) // 2])
    with pytest.raises(ResultsError, match="deadbeef.parquet"):
        stored_status(results)


def test_leftover_temporaries_and_subfolders_are_ignored(results):
    """In-flight temporaries (.tmp) and sub-folders (reports) are not rows."""
    (results / ".abc.123.tmp").write_bytes(b"partial")
    (results / "report").mkdir()
    (results / "report" / "x.png").write_bytes(b"png")
    assert len(load_results(results)) == 1


def test_missing_folder_is_a_clear_error(tmp_path):
    """Loading a folder that does not exist names it."""
    with pytest.raises(FcplanError, match="no such results folder"):
        load_results(tmp_path / "nope")


@settings(max_examples=25, deadline=None)
@given(
    st.dictionaries(
        st.from_regex(r"[a-z][a-z_]{0,8}", fullmatch=True).filter(lambda k: k != "key"),
        st.one_of(st.integers(-(2**40), 2**40), st.floats(allow_nan=False), st.text(max_size=20)),
        max_size=6,
    )
)
def test_write_then_load_round_trips_a_row(tmp_path_factory, row):
    """Any flat row of numbers and strings reads back unchanged, as one row."""
    d = tmp_path_factory.mktemp("rt")
    write_row(d, {"key": "k1", **row})
    df = load_results(d)
    assert len(df) == 1
    for k, v in row.items():
        got = df.iloc[0][k]
        assert got == v or (isinstance(v, float) and math.isclose(got, v))
    assert not list(d.glob(".*.tmp"))
