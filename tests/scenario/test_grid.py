"""Tests of fcplan.scenario.grid: chess-cell names and object centres."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.errors import ScenarioError
from fcplan.scenario import cell_center, cell_name
from fcplan.scenario.grid import (
    GRID_BLOCKS,
    block_cell,
    block_cells,
    column_letters,
    format_cell,
    parse_cell,
)

columns = st.integers(min_value=0, max_value=2000)
rows = st.integers(min_value=1, max_value=2000)


@pytest.mark.parametrize(
    ("cell", "kind", "center"),
    [
        ("D-05", "region", (350, 450)),
        ("D-04", "region", (350, 350)),
        ("A-12", "region", (50, 1150)),
        ("H-03", "house", (800, 300)),
        ("I-08", "hospital", (900, 800)),
        ("J-06", "power_station", (1000, 600)),
        ("A-05", "depot_vertical", (100, 600)),
        ("D-09", "depot_horizontal", (500, 900)),
        ("D-09", "lake", (450, 1000)),
        ("F-02", "lake", (650, 300)),
    ],
)
def test_cell_center_matches_the_gui_mapping(cell, kind, center):
    """cell_center gives the GUI's centre for each kind of object (FIRECOMMANDER.md section 2)."""
    assert cell_center(cell, kind) == center


def test_cell_center_defaults_to_a_fire_region_and_returns_floats():
    """Without a kind the cell is a 1x1 fire region; coordinates are floats."""
    x, y = cell_center("D-05")
    assert (x, y) == (350.0, 450.0)
    assert isinstance(x, float) and isinstance(y, float)


def test_column_letters_continue_past_z():
    """Columns are A..Z, then AA, AB, ... (bijective base 26)."""
    assert [column_letters(i) for i in (0, 25, 26, 27, 51, 52, 701, 702)] == [
        "A",
        "Z",
        "AA",
        "AB",
        "AZ",
        "BA",
        "ZZ",
        "AAA",
    ]


def test_rows_have_at_least_two_digits():
    """Rows are zero-padded to two digits and grow to three past 99."""
    assert format_cell(0, 1) == "A-01"
    assert format_cell(0, 100) == "A-100"
    assert cell_name(0, 9950) == "A-100"


@given(columns, rows)
def test_cell_name_inverts_cell_center(column, row):
    """cell_name(cell_center(name)) == name for every canonical cell name."""
    name = format_cell(column, row)
    world = 100 * (max(column + 1, row) + 1)
    assert cell_name(*cell_center(name, "region", world)) == name
    assert parse_cell(name) == (column, row)


@given(st.floats(0, 1e5, allow_nan=False), st.floats(0, 1e5, allow_nan=False))
def test_cell_name_names_the_cell_containing_the_point(x, y):
    """The point lies in the 100-px cell named by cell_name (half-open on the right and bottom)."""
    cx, cy = cell_center(cell_name(x, y), "region", world_size=10**6)
    assert cx - 50 <= x < cx + 50
    assert cy - 50 <= y < cy + 50


@given(st.sampled_from(sorted(GRID_BLOCKS)), st.integers(0, 30), st.integers(1, 30))
def test_block_cell_inverts_cell_center_for_every_kind(kind, column, row):
    """block_cell(cell_center(cell, kind), kind) gives back the top-left cell."""
    cell = format_cell(column, row)
    assert block_cell(cell_center(cell, kind, 10**5), kind) == cell


def test_block_cell_is_none_off_the_grid():
    """A centre that no cell placement can produce has no block cell."""
    assert block_cell((810, 300), "house") is None
    assert block_cell((350, 455), "region") is None


def test_block_cells_cover_the_object_block():
    """A lake reserves 3 columns x 4 rows, a vertical depot 2 x 4."""
    assert len(block_cells("D-09", "lake")) == 12
    assert block_cells("A-05", "depot_vertical") == {(c, r) for c in (0, 1) for r in (5, 6, 7, 8)}


def test_parse_cell_is_lenient_about_case_and_padding():
    """'d-5' and ' D - 05 ' name the same cell as 'D-05'."""
    assert parse_cell("d-5") == parse_cell(" D - 05 ") == parse_cell("D-05") == (3, 5)


@pytest.mark.parametrize("bad", ["D5", "D-", "-05", "5-D", "D-00", "", "Ä-01"])
def test_malformed_cell_names_are_one_line_errors(bad):
    """Malformed names raise ScenarioError saying what a cell name looks like."""
    with pytest.raises(ScenarioError, match="cell name like 'D-05'") as info:
        cell_center(bad)
    assert "\n" not in str(info.value)


def test_cells_off_the_grid_are_rejected_with_the_grid_range():
    """M-01 is off the 12x12 grid of a 1200 px map; the message gives the valid range."""
    with pytest.raises(ScenarioError, match=r"12x12 grid of a 1200 px map \(A-01..L-12\)"):
        cell_center("M-01")
    with pytest.raises(ScenarioError, match="8x8 grid"):
        cell_center("A-09", world_size=800)
    assert cell_center("L-12") == (1150, 1150)


def test_unknown_kind_is_a_value_error():
    """An unknown object kind names the known ones."""
    with pytest.raises(ValueError, match="known kinds: region"):
        cell_center("A-01", "castle")


@pytest.mark.parametrize("bad", [(-1, 0), (0, float("nan")), (True, 0)])
def test_cell_name_rejects_negative_or_non_numbers(bad):
    """cell_name needs finite coordinates >= 0."""
    with pytest.raises(ScenarioError):
        cell_name(*bad)
