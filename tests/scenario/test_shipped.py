"""Tests of the shipped scenario files against the FireCommander manual and the reference data.

``MANUAL`` transcribes the manual's scenario tables (spec/MANUAL.tex, "The Targets and Agent
Setting in the ... Scenario" and "The Fire Setting in the ... Scenario"; #8's "135. 225" read as
135, 225). ``REFERENCE`` holds the cells of the reference data (spec/scenarios.json), which the
manual does not give. ``CODE_DIFFERS`` lists the values where the 2020 reference code differs from
the manual: the files follow the manual and must say so.
"""

from __future__ import annotations

import re
from typing import NamedTuple

import pytest

from fcplan.scenario import (
    Role,
    cell_center,
    dump_scenario,
    list_scenarios,
    load_scenario,
    scenario_path,
)


class Row(NamedTuple):
    houses: int
    hospitals: int
    power_stations: int
    lakes: int
    perception: int
    action: int
    fronts: tuple[int, ...]
    delay_s: tuple[int, ...]
    fuel: tuple[int, ...]
    wind_speed: tuple[int, ...]
    wind_dir_deg: tuple[int, ...]


# houses, hospitals, power stations, lakes, P, A | per region: fronts, delay, fuel, wind, direction
MANUAL: dict[str | int, Row] = {
    "practice": Row(1, 1, 1, 1, 2, 2, (15,), (0,), (10,), (5,), (45,)),
    1: Row(5, 1, 1, 1, 2, 2, (10,), (0,), (10,), (5,), (45,)),
    2: Row(1, 1, 0, 1, 2, 1, (15,), (60,), (15,), (3,), (45,)),
    3: Row(1, 1, 1, 1, 1, 1, (5,), (0,), (15,), (5,), (45,)),
    4: Row(1, 1, 0, 1, 1, 1, (12,), (60,), (5,), (3,), (45,)),
    5: Row(2, 1, 1, 1, 3, 2, (3, 8), (0, 0), (5, 10), (5, 3), (45, 15)),
    6: Row(2, 1, 1, 1, 2, 3, (5, 3), (60, 0), (10, 10), (5, 5), (45, 15)),
    7: Row(2, 1, 1, 1, 3, 1, (3, 3), (0, 0), (5, 5), (5, 5), (135, 225)),
    8: Row(2, 1, 1, 1, 3, 1, (5, 7), (0, 60), (3, 3), (10, 10), (135, 225)),
    9: Row(2, 1, 1, 1, 2, 2, (5, 5), (0, 0), (10, 10), (5, 5), (45, 15)),
    10: Row(2, 1, 1, 1, 2, 2, (5, 5), (60, 0), (10, 10), (5, 5), (45, 15)),
    11: Row(2, 1, 1, 1, 2, 2, (5, 5), (0, 0), (5, 5), (5, 5), (135, 225)),
    12: Row(2, 1, 1, 1, 3, 2, (3, 10), (0, 60), (5, 10), (5, 10), (135, 225)),
    13: Row(5, 2, 1, 0, 2, 2, (3, 3, 3), (60, 0, 0), (10, 10, 10), (5, 5, 5), (75, 135, 225)),
    14: Row(2, 1, 1, 1, 3, 2, (5, 5, 5), (0, 120, 60), (10, 10, 10), (5, 5, 5), (135, 315, 225)),
    15: Row(5, 2, 1, 0, 3, 3, (3, 5, 7), (60, 0, 0), (10, 10, 10), (3, 5, 10), (75, 135, 225)),
    16: Row(2, 1, 1, 1, 2, 3, (3, 5, 7), (0, 120, 60), (3, 5, 10), (5, 5, 5), (135, 315, 225)),
    17: Row(4, 2, 2, 0, 4, 4, (5, 5, 5), (60, 0, 120), (10, 10, 10), (5, 5, 5), (75, 135, 225)),
    18: Row(2, 1, 1, 1, 2, 3, (3, 3, 5), (0, 0, 0), (5, 5, 10), (3, 3, 5), (135, 315, 225)),
    19: Row(4, 2, 2, 0, 2, 2, (5, 5, 5), (60, 0, 120), (10, 10, 10), (5, 5, 5), (75, 135, 225)),
    20: Row(2, 1, 1, 1, 2, 1, (3, 3, 3), (0, 0, 0), (5, 5, 5), (5, 5, 5), (135, 315, 225)),
    21: Row(4, 1, 2, 2, 4, 4, (5, 5, 5, 5), (60, 0, 0, 120), (10, 10, 10, 10), (5, 5, 5, 5),
            (75, 135, 135, 225)),
    22: Row(4, 1, 2, 2, 3, 3, (5, 5, 5, 5), (0, 0, 0, 120), (5, 5, 10, 10), (5, 5, 5, 5),
            (75, 135, 135, 225)),
    23: Row(4, 1, 2, 2, 3, 2, (3, 3, 5, 7), (60, 0, 0, 120), (3, 5, 3, 10), (5, 5, 5, 5),
            (75, 135, 135, 225)),
    24: Row(4, 1, 2, 2, 2, 2, (3, 5, 7, 8), (0, 0, 0, 120), (8, 8, 8, 8), (3, 3, 3, 3),
            (75, 135, 135, 225)),
}  # fmt: skip


class Cells(NamedTuple):
    mode: str
    regions: str
    houses: str
    hospitals: str
    power_stations: str
    lakes: str


# fire mode and top-left cells from the reference data (spec/scenarios.json)
HARD_REGIONS = "C-05 C-08 A-12 L-12"  # #21-#24
REFERENCE: dict[str | int, Cells] = {
    "practice": Cells("uniform", "D-04", "H-03", "I-08", "J-06", "D-09"),
    1: Cells("uniform", "D-04", "I-02 K-02 I-04 K-04 J-06", "F-10", "C-10", "F-02"),
    2: Cells("specific", "D-04", "H-03", "I-07", "", "D-09"),
    3: Cells("uniform", "D-04", "J-07", "G-10", "C-09", "G-01"),
    4: Cells("specific", "D-04", "H-03", "I-07", "", "D-09"),
    5: Cells("specific", "D-04 D-04", "I-07 K-07", "C-10", "F-10", "F-01"),
    6: Cells("specific", "D-04 D-04", "H-03 J-03", "I-08", "G-10", "C-09"),
    7: Cells("specific", "D-08 K-11", "I-06 K-06", "G-11", "C-11", "F-02"),
    8: Cells("specific", "D-08 K-11", "G-03 I-03", "I-07", "B-10", "F-09"),
    9: Cells("specific", "D-04 D-04", "H-07 J-07", "F-10", "C-10", "F-01"),
    10: Cells("specific", "D-04 D-04", "H-03 J-03", "I-08", "G-10", "C-09"),
    11: Cells("specific", "D-08 K-11", "I-07 K-07", "G-10", "C-10", "F-01"),
    12: Cells("specific", "D-08 K-11", "G-03 I-03", "I-07", "B-10", "E-09"),
    13: Cells("specific", "D-05 D-08 K-11", "I-02 K-02 I-04 K-04 J-06", "F-02 C-11", "F-10", ""),
    14: Cells("specific", "D-08 K-02 K-11", "F-02 H-02", "I-07", "B-10", "E-09"),
    15: Cells("specific", "D-05 D-08 K-11", "I-02 K-02 I-04 K-04 J-06", "F-02 C-11", "F-10", ""),
    16: Cells("specific", "D-08 K-02 K-11", "F-02 H-02", "I-07", "B-10", "E-09"),
    17: Cells("specific", "D-05 D-08 K-11", "I-02 K-02 I-06 K-06", "F-02 C-11", "J-04 F-10", ""),
    18: Cells("specific", "D-08 K-02 K-11", "F-02 H-02", "I-07", "B-10", "E-09"),
    19: Cells("specific", "D-05 D-08 K-11", "I-02 K-02 I-06 K-06", "F-02 C-11", "J-04 F-10", ""),
    20: Cells("specific", "D-08 K-02 K-11", "F-02 H-02", "I-07", "B-10", "E-09"),
    21: Cells("specific", HARD_REGIONS, "I-05 K-05 G-11 I-11", "F-02", "J-07 F-07", "I-01 D-09"),
    22: Cells("specific", HARD_REGIONS, "I-05 K-05 G-11 I-11", "F-02", "J-07 F-07", "I-01 D-09"),
    23: Cells("specific", HARD_REGIONS, "I-05 K-05 G-11 I-11", "F-02", "J-07 F-07", "I-01 D-09"),
    24: Cells("specific", HARD_REGIONS, "I-05 K-05 G-11 I-11", "F-02", "J-07 F-07", "I-01 D-09"),
}  # fmt: skip

# scenario -> (field, values in the reference code); the files follow the manual instead
CODE_DIFFERS: dict[str | int, tuple[str, str]] = {
    "practice": ("fronts", "5"),
    5: ("wind_dir_deg", "45, 75"),
    6: ("wind_dir_deg", "45, 75"),
    9: ("wind_dir_deg", "45, 75"),
    10: ("wind_dir_deg", "45, 75"),
    13: ("delay_s", "0, 60, 0"),
    15: ("delay_s", "0, 60, 0"),
    16: ("team", "3 / 2"),
}
PRACTICE_TEAM_IN_CODE = "2 / 3"

SHIPPED = list(MANUAL)
DIFFICULTY = {"practice": "practice"} | {n: "easy" for n in range(1, 7)}
DIFFICULTY |= {n: "moderate" for n in range(7, 19)} | {n: "hard" for n in range(19, 25)}


@pytest.mark.parametrize("key", SHIPPED)
def test_counts_and_team_match_the_manual(key):
    """Facility, lake and team counts are the manual's (no hybrid agents in scenario mode)."""
    s, row = load_scenario(key), MANUAL[key]
    kinds = [f.kind for f in s.facilities]
    assert kinds.count("house") == row.houses
    assert kinds.count("hospital") == row.hospitals
    assert kinds.count("power_station") == row.power_stations
    assert len(s.lakes) == row.lakes
    assert s.team_counts == {"perception": row.perception, "action": row.action, "hybrid": 0}


@pytest.mark.parametrize("key", SHIPPED)
def test_fire_parameters_match_the_manual(key):
    """Per-region fronts, delay, fuel, wind speed and direction are the manual's."""
    s, row = load_scenario(key), MANUAL[key]
    for name in ("fronts", "delay_s", "fuel", "wind_speed", "wind_dir_deg"):
        assert tuple(getattr(r, name) for r in s.regions) == getattr(row, name), name


@pytest.mark.parametrize("key", SHIPPED)
def test_cells_and_mode_match_the_reference_data(key):
    """Region, facility and lake cells and the fire mode are the reference data's."""
    s, ref = load_scenario(key), REFERENCE[key]
    assert s.fire_mode == ref.mode
    assert " ".join(r.cell for r in s.regions) == ref.regions
    for kind, cells in (
        ("house", ref.houses),
        ("hospital", ref.hospitals),
        ("power_station", ref.power_stations),
    ):
        assert " ".join(f.cell for f in s.facilities if f.kind == kind) == cells
    assert " ".join(lake.cell for lake in s.lakes) == ref.lakes


def test_coordinate_spot_checks():
    """A few centres written out in px: D-04, the depot, #24's A-12 region, facilities, lakes."""
    assert load_scenario(1).regions[0].center == (350, 350)
    assert load_scenario(12).regions[0].center == (350, 750)
    assert load_scenario(14).regions[1].center == (1050, 150)
    assert load_scenario(24).regions[2].center == (50, 1150)
    assert load_scenario(24).regions[3].center == (1150, 1150)
    assert load_scenario(21).regions[0].center == (250, 450)
    assert load_scenario(5).depot.center == (100, 600)
    assert load_scenario("practice").facilities[1].center == (900, 800)
    assert load_scenario(17).facilities[-2].center == (1000, 400)
    assert load_scenario(21).lakes[0].center == (950, 200)
    assert load_scenario(7).facilities[-1].footprint == (210, 390, 990, 1210)


@pytest.mark.parametrize("key", SHIPPED)
def test_scenario_mode_constants(key):
    """Every shipped scenario uses the scenario-mode constants of the reference data."""
    s = load_scenario(key)
    assert s.number == (0 if key == "practice" else key)
    assert s.name == ("practice" if key == "practice" else f"#{key}")
    assert s.difficulty == DIFFICULTY[key]
    assert (s.world_size, s.duration_s, s.ticks_per_second, s.n_ticks) == (1200, 180, 10, 1800)
    assert (s.depot.center, s.depot.orientation, s.depot.cell, s.depot.penalty) == (
        (100, 600),
        "vertical",
        "A-05",
        5,
    )
    assert (s.scoring.propagation_weight, s.scoring.temporal_exponent) == (0.1, 1.25)
    assert s.action_gate == "sensed" and s.comm_range is None
    assert [f.penalty for f in s.scored_facilities] == [
        {"house": 1, "hospital": 2, "power_station": 5, "depot": 5}[f.kind]
        for f in s.scored_facilities
    ]
    for a in s.agents:
        assert (a.battery, a.speed) == (500, 20)
        if a.role is Role.PERCEPTION:
            assert (a.altitude, a.start_altitude, a.tank, a.prune_confidence) == (
                (10, 100),
                20,
                0,
                0,
            )
        else:
            assert (a.altitude, a.start_altitude, a.tank, a.prune_confidence) == (
                (30, 30),
                30,
                10,
                0.9,
            )
    assert [a.start for a in s.agents] == list(s.depot.slots(len(s.agents)))
    assert s.agents[0].start == (60, 420)


@pytest.mark.parametrize("key", SHIPPED)
def test_differences_from_the_reference_code_are_noted(key):
    """Where the code differs from the manual, the file notes the code's value; else no notes."""
    s = load_scenario(key)
    text = scenario_path(key).read_text(encoding="utf-8")
    if key not in CODE_DIFFERS:
        assert s.notes == ()
        assert "reference code uses" not in text
        return
    _, code_values = CODE_DIFFERS[key]
    assert any(f"reference code {code_values};" in note for note in s.notes), s.notes
    assert all("this file follows the manual" in note for note in s.notes)
    assert "the reference code uses" in text
    if key == "practice":
        assert any(f"reference code {PRACTICE_TEAM_IN_CODE};" in note for note in s.notes)


def test_difference_comments_sit_at_the_values():
    """The comment stating the code's value is on the line of the manual's value."""
    five = scenario_path(5).read_text(encoding="utf-8")
    assert re.search(r"^wind_dir_deg = 15 +# \[manual F\]; the reference code uses 75$", five, re.M)
    thirteen = scenario_path(13).read_text(encoding="utf-8")
    assert re.search(r"^delay_s = 60 +# \[manual F\]; the reference code uses 0$", thirteen, re.M)
    sixteen = scenario_path(16).read_text(encoding="utf-8")
    assert re.search(r"^count = 2 +# \[manual T\]; the reference code uses 3$", sixteen, re.M)
    practice = scenario_path("practice").read_text(encoding="utf-8")
    assert re.search(r"^fronts = 15 +# \[manual F\]; the reference code uses 5$", practice, re.M)


@pytest.mark.parametrize("key", SHIPPED)
def test_files_name_their_sources(key):
    """Every file's header cites the manual's tables and the reference data."""
    text = scenario_path(key).read_text(encoding="utf-8")
    assert "[manual T]  FireCommander manual" in text
    assert "[manual F]  the same manual" in text
    assert "[reference] FireCommander2020 ScenarioModeParams.py" in text
    assert '"The Fire Setting in the' in text


@pytest.mark.parametrize("name", list_scenarios())
def test_every_shipped_file_round_trips(name, tmp_path):
    """load -> dump_scenario -> load gives an equal scenario for every shipped file."""
    s = load_scenario(name)
    path = tmp_path / "copy.toml"
    dump_scenario(s, path)
    assert load_scenario(path) == s


@pytest.mark.parametrize("key", [*SHIPPED, "open_world_example"])
def test_shipped_designs_are_within_the_manual(key):
    """manual_limit_violations() is empty for the 25 scenarios and the open-world example."""
    assert load_scenario(key).manual_limit_violations() == []


def test_open_world_example_shows_what_scenarios_do_not():
    """The open-world example: 1000 px, horizontal depot, hybrids, heterogeneous agents."""
    s = load_scenario("open_world_example")
    assert s.number is None and s.difficulty == "custom"
    assert s.world_size == 1000 and s.depot.orientation == "horizontal"
    assert s.team_counts["hybrid"] == 2
    perception = [a for a in s.agents if a.role is Role.PERCEPTION]
    assert len({a.altitude for a in perception}) == 2
    assert s.depot.center == cell_center("D-09", "depot_horizontal", 1000)


def test_scale_example_is_valid_but_beyond_the_manual():
    """The scale example exceeds the manual (map, regions, team) but loads without error."""
    s = load_scenario("scale_example")
    assert (s.world_size, len(s.regions), len(s.agents)) == (2000, 8, 30)
    lines = s.manual_limit_violations()
    assert "world_size: 2000 (manual: 800, 1000 or 1200)" in lines
    assert "fire.regions: 8 regions (manual: 1..5)" in lines
    assert "team: 30 agents in total (manual: at most 9)" in lines
    x0, x1, y0, y1 = s.depot.footprint
    assert all(x0 < a.start[0] < x1 and y0 < a.start[1] < y1 for a in s.agents)


def test_only_scenario_files_in_the_folder():
    """The scenarios folder holds practice, 01..24 and the two examples, nothing else."""
    folder = scenario_path(1).parent
    names = sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))
    numbered = [f"{n:02d}.toml" for n in range(1, 25)]
    expected = sorted(["practice.toml", *numbered, "open_world_example.toml", "scale_example.toml"])
    assert [n for n in names if n != "__pycache__"] == expected


def test_manual_team_differs_from_the_code_in_16():
    """#16 follows the manual's 2 perception / 3 action (the code has 3 / 2)."""
    s = load_scenario(16)
    assert s.agent_ids == ("P1", "P2", "A1", "A2", "A3")
    assert s.agents[2].start == (60, 540)
