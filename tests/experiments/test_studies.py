"""Studies in a results folder (:mod:`fcplan.experiments.studies`): one study is reported,
several are refused unless chosen or pooled on purpose, old rows are one study."""

from __future__ import annotations

import json

import pytest

from fcplan.errors import FcplanError
from fcplan.experiments.studies import LEGACY, select_study, studies

pd = pytest.importorskip("pandas")


def _frame(hashes):
    return pd.DataFrame({"study_hash": hashes, "sweep": ["s"] * len(hashes)})


def test_one_study_passes_without_a_note():
    """A folder with one study hash is reported as is."""
    sel = select_study(_frame(["ab12", "ab12"]), None)
    assert len(sel.rows) == 2 and sel.note == "" and sel.studies[0].episodes == 2


def test_mixed_studies_are_refused_in_one_line_naming_them(tmp_path):
    """Two studies: one line naming both (with names from the manifests and episode counts)
    and the two ways out."""
    (tmp_path / "manifest-ab12.json").write_text(json.dumps({"study_hash": "ab12", "name": "x"}))
    with pytest.raises(FcplanError) as info:
        select_study(_frame(["ab12", "cd34", "cd34"]), tmp_path)
    msg = str(info.value)
    assert "\n" not in msg and "2 studies" in msg
    assert "ab12 'x' (1 episode)" in msg and "cd34 's' (2 episodes)" in msg
    assert "--study" in msg and "--allow-mixed" in msg


def test_allow_mixed_pools_and_says_so():
    """allow_mixed keeps every row and the note says the report pools different studies."""
    sel = select_study(_frame(["ab12", "cd34"]), None, allow_mixed=True)
    assert len(sel.rows) == 2 and "pools 2 different studies" in sel.note


def test_study_selects_by_unique_prefix():
    """study= keeps one study by hash prefix; an unknown or ambiguous prefix is an error."""
    df = _frame(["ab12", "ab99", "cd34"])
    assert len(select_study(df, None, study="cd").rows) == 1
    with pytest.raises(FcplanError, match="'ab' is ambiguous"):
        select_study(df, None, study="ab")
    with pytest.raises(FcplanError, match="'zz' matches no study"):
        select_study(df, None, study="zz")


def test_rows_without_a_hash_are_one_study_said_once():
    """Rows written before study hashes (no column, or NaN) are one study with a note; mixed
    with hashed rows they count as another study."""
    old = pd.DataFrame({"scenario": ["#1", "#2"]})
    sel = select_study(old, None)
    assert [s.hash for s in sel.studies] == [LEGACY] and "before study hashes" in sel.note
    mixed = pd.DataFrame({"study_hash": [None, "ab12"]})
    assert [s.hash for s in studies(mixed)] == [LEGACY, "ab12"]
    with pytest.raises(FcplanError, match="2 studies"):
        select_study(mixed, None)
