"""Tests of fcplan.scenario.model: the dataclasses and the Scenario's derived values."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.scenario import (
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    Scenario,
    ScenarioError,
    Scoring,
    load_scenario,
)
from fcplan.scenario.model import DEPOT_SLOTS


def make_scenario(**changes) -> Scenario:
    """A small valid scenario built directly in Python (no file)."""
    fields = dict(
        name="tiny",
        number=None,
        difficulty="custom",
        world_size=800,
        duration_s=60,
        ticks_per_second=10,
        fire_mode="specific",
        regions=[FireRegion((450, 150), 5, 0, 10, 5, 45, cell="E-02")],
        depot=Depot((100, 200), "vertical", cell="A-01"),
        facilities=[
            Facility.standard("house", (600, 600)),
            Facility.standard("hospital", (400, 600)),
        ],
        lakes=[Lake((650, 300))],
        agents=[
            AgentSpec("P1", Role.PERCEPTION, (60, 20), (10, 100), 20, 500, 20, 0, 0.0),
            AgentSpec("A1", Role.ACTION, (60, 80), (30, 30), 30, 500, 20, 10, 0.9),
        ],
        scoring=Scoring(),
    )
    fields.update(changes)
    return Scenario(**fields)


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


def test_dataclasses_coerce_sequences_and_numbers():
    """Lists become tuples and numbers become floats, so values compare and hash consistently."""
    r = FireRegion([350, 450], np.int64(5), 0, np.float32(10), 5, 45)
    assert r.center == (350.0, 450.0) and type(r.center[0]) is float
    assert type(r.fronts) is int and type(r.fuel) is float
    a = AgentSpec("A1", 1, [60, 80], [30, 30], 30, 500, 20, np.int16(3), 0.9)
    assert a.role is Role.ACTION and a.start == (60.0, 80.0) and type(a.tank) is int
    s = make_scenario()
    assert isinstance(s.regions, tuple) and isinstance(s.agents, tuple)
    assert hash(s) == hash(make_scenario())


def test_scenario_derived_values():
    """n_ticks, grid_size, team counts, agent ids and the scored facilities (depot last)."""
    s = make_scenario(ticks_per_second=4, duration_s=2.5)
    assert s.n_ticks == 10
    assert s.grid_size == 8
    assert s.team_counts == {"perception": 1, "action": 1, "hybrid": 0}
    assert s.agent_ids == ("P1", "A1")
    assert [f.kind for f in s.scored_facilities] == ["house", "hospital", "depot"]
    assert s.scored_facilities[-1] == s.depot.as_facility()


def test_agent_index_is_its_position_within_the_role():
    """AgentSpec.index is the number after the role letter."""
    s = load_scenario(21)
    assert [a.index for a in s.agents] == [1, 2, 3, 4, 1, 2, 3, 4]


def test_direct_construction_is_validated():
    """Scenario(...) in Python raises ScenarioError for invalid values, naming the field."""
    with pytest.raises(
        ScenarioError, match=r"^tiny: fire.regions\[0\].fronts: must be an integer >= 1"
    ):
        make_scenario(regions=[FireRegion((450, 150), 0, 0, 10, 5, 45)])
    with pytest.raises(ScenarioError, match=r"team.action.tank: must be an integer >= 1"):
        make_scenario(
            agents=[
                AgentSpec("P1", Role.PERCEPTION, (60, 20), (10, 100), 20, 500, 20, 0, 0.0),
                AgentSpec("A1", Role.ACTION, (60, 80), (30, 30), 30, 500, 20, 0, 0.9),
            ]
        )


def test_replace_revalidates_and_keeps_the_source():
    """replace() builds a new validated scenario; errors still name the original file."""
    s = load_scenario(12)
    assert s.replace(duration_s=60).n_ticks == 600
    assert s.replace(duration_s=60).source == s.source
    with pytest.raises(ScenarioError) as info:
        s.replace(ticks_per_second=0)
    msg = str(info.value)
    assert msg.startswith(f"{s.source}: ticks_per_second: must be an integer >= 1")
    assert "\n" not in msg


def test_equality_ignores_the_source_file():
    """Two scenarios with the same content are equal wherever they were loaded from."""
    s = load_scenario(3)
    assert dataclasses.replace(s, source="elsewhere.toml") == s
    assert s.replace(duration_s=120) != s


def test_summary_is_one_line():
    """summary() names the scenario, difficulty, team and regions on one line."""
    assert (
        load_scenario(12).summary() == "#12  moderate  team 3P/2A  regions D-08(3f) K-11(10f, +60s)"
    )
    tiny = make_scenario(regions=[FireRegion((455, 150), 5, 30, 10, 5, 45)])
    assert tiny.summary() == "tiny  custom  team 1P/1A  regions (455,150)(5f, +30s)  800px 60s"


def test_to_dict_from_dict_round_trip():
    """Scenario.from_dict(s.to_dict()) == s, and from_dict records the source."""
    s = load_scenario(16)
    again = Scenario.from_dict(s.to_dict(), source="copy.toml")
    assert again == s and again.source == "copy.toml"
    assert Scenario.from_dict(make_scenario().to_dict()) == make_scenario()
