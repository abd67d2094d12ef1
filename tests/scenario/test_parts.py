"""Tests of fcplan.scenario.parts: roles, regions, facilities, depot, lakes, agents and the game's
tables."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import fcplan.scenario.model as model
import fcplan.scenario.parts as parts
from fcplan.scenario import Depot, Facility, FireRegion, Lake, Role
from fcplan.scenario.parts import DEPOT_SLOTS, FACILITY_KINDS, FOOTPRINT_KINDS


def test_role_letters_and_abilities():
    """P senses only, A acts only, H does both; letters are the id prefixes."""
    assert [r.letter for r in Role] == ["P", "A", "H"]
    assert [(r.can_sense, r.can_act) for r in Role] == [(True, False), (False, True), (True, True)]
    assert [int(r) for r in Role] == [0, 1, 2]
    assert Role.HYBRID.key == "hybrid"


def test_facility_standard_sizes_and_penalties():
    """Standard facilities get the game's footprint sizes and penalty coefficients."""
    house, hospital, power = (
        Facility.standard(k, (500, 500)) for k in ("house", "hospital", "power_station")
    )
    assert (house.size, house.penalty) == ((120, 150), 1)
    assert (hospital.size, hospital.penalty) == ((150, 180), 2)
    assert (power.size, power.penalty) == ((180, 220), 5)
    assert Facility.standard("house", (0, 0), penalty=3).penalty == 3
    with pytest.raises(ValueError, match="house, hospital, power_station"):
        Facility.standard("depot", (0, 0))


def test_footprint_membership_is_strict():
    """A cell is inside a footprint only strictly between its edges (the GUI's rule)."""
    f = Facility.standard("house", (800, 300))
    assert f.footprint == (740, 860, 225, 375)
    assert f.contains(741, 226) and f.contains(859, 374)
    assert not f.contains(740, 300) and not f.contains(860, 300) and not f.contains(800, 375)
    xs = np.array([739, 740, 741, 800, 859, 860])
    assert f.contains(xs, np.full(6, 300)).tolist() == [False, False, True, True, True, False]


def test_depot_sizes_and_facility_view():
    """A depot is 160 x 400 vertical, 400 x 160 horizontal, and is scored with penalty 5."""
    v, h = Depot((100, 600), "vertical"), Depot((500, 900), "horizontal", cell="D-09")
    assert v.size == (160, 400) and h.size == (400, 160)
    assert v.footprint == (20, 180, 400, 800)
    fac = h.as_facility()
    assert (fac.kind, fac.center, fac.size, fac.penalty, fac.cell) == (
        "depot",
        (500, 900),
        (400, 160),
        5,
        "D-09",
    )


@pytest.mark.parametrize("orientation", ["vertical", "horizontal"])
def test_first_nine_slots_are_the_gui_slots(orientation):
    """Agents 1..9 start at the depot centre plus the GUI's slot offsets, in order."""
    d = Depot((500, 500), orientation)
    expected = tuple((500 + dx, 500 + dy) for dx, dy in DEPOT_SLOTS[orientation])
    assert d.slots(9) == expected
    assert d.slots(4) == expected[:4]
    assert d.slots(0) == ()


@given(st.integers(10, 200), st.sampled_from(["vertical", "horizontal"]))
def test_extra_slots_are_an_even_lattice_inside_the_footprint(n, orientation):
    """Agents past the ninth sit on distinct lattice points strictly inside the depot footprint."""
    d = Depot((1000, 1000), orientation)
    x0, x1, y0, y1 = d.footprint
    extra = d.slots(n)[9:]
    assert len(extra) == n - 9
    assert all(x0 < x < x1 and y0 < y < y1 for x, y in extra)
    assert len(set(extra)) == len(extra)
    xs, ys = sorted({x for x, _ in extra}), sorted({y for _, y in extra})
    for values in (xs, ys):
        steps = np.diff(values)
        assert len(steps) == 0 or steps.max() - steps.min() <= 1  # evenly spaced (rounded to px)


def test_lake_circles():
    """A lake is drawn as three radius-100 circles at fixed offsets."""
    assert Lake((450, 1000)).circles == ((450, 1000, 100), (530, 920, 100), (470, 1080, 100))


def test_fire_region_ignition_box_is_centre_plus_minus_half_width():
    """The ignition box is the region's cell: centre +- 50 px by default."""
    r = FireRegion((350, 450), 5, 0, 10, 5, 45)
    assert r.ignition_box == (300, 400, 400, 500)
    assert dataclasses.replace(r, half_width=5).ignition_box == (345, 355, 445, 455)


def test_the_game_tables_are_defined_once():
    """FACILITY_KINDS (the facilities) and FOOTPRINT_KINDS (the facilities then the depot) are the
    kinds of a scenario's scored footprints; fcplan.scenario.model exports the same objects."""
    assert (*FACILITY_KINDS, "depot") == FOOTPRINT_KINDS
    assert set(parts.DEFAULT_PENALTIES) == set(FOOTPRINT_KINDS)
    assert set(parts.FACILITY_SIZES) == set(FACILITY_KINDS)
    for name in parts.__all__:
        assert getattr(model, name) is getattr(parts, name), name
    assert parts.ACTION_ALTITUDE == 30.0
