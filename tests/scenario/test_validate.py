"""Tests of fcplan.scenario.validate: physical validity errors and the manual's GUI limits."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from fcplan.scenario import (
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Role,
    ScenarioError,
    load_scenario,
)
from tests.scenario.designs import BASE

REGION = """\
[[fire.regions]]
cell = "E-02"
fronts = 4
fuel = 8
wind_speed = 5
wind_dir_deg = 90
"""


def edit(old: str, new: str) -> str:
    """BASE with ``old`` replaced by ``new`` (``old`` must occur)."""
    assert old in BASE, old
    return BASE.replace(old, new)


def load_error(tmp_path: Path, text: str) -> str:
    """The one-line message of the ScenarioError that loading ``text`` raises."""
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    msg = str(info.value)
    assert "\n" not in msg, msg
    assert msg.startswith(f"{path}: "), msg
    return msg


def load_text(tmp_path: Path, text: str):
    path = tmp_path / "ok.toml"
    path.write_text(text, encoding="utf-8")
    return load_scenario(path)


# ------------------------------------------------------------------------------------------ errors
@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("fronts = 4", "fronts = 0", "fire.regions[0].fronts: must be an integer >= 1 (got 0)"),
        ("fuel = 8", "fuel = 0", "fire.regions[0].fuel: must be a number > 0 (got 0.0)"),
        (
            "wind_speed = 5",
            "wind_speed = -1",
            "fire.regions[0].wind_speed: must be a number >= 0 (m/s)",
        ),
        (
            "wind_dir_deg = 90",
            "wind_dir_deg = nan",
            "fire.regions[0].wind_dir_deg: must be a finite number",
        ),
        ("fuel = 8", "fuel = 8\ndelay_s = -1", "fire.regions[0].delay_s: must be a number >= 0"),
        (
            "fuel = 8",
            "fuel = 8\nhalf_width = 0",
            "fire.regions[0].half_width: must be a number > 0",
        ),
        ("duration_s = 120", "duration_s = 0", "duration_s: must be a number > 0"),
        (
            "world_size = 800",
            "world_size = 50",
            "world_size: must be an integer >= 100 (px) (got 50)",
        ),
        (
            "duration_s = 120",
            "duration_s = 120\nticks_per_second = 0",
            "ticks_per_second: must be an integer >= 1",
        ),
        (
            "duration_s = 120",
            "duration_s = 120\ncomm_range = 0",
            "comm_range: must be a number > 0",
        ),
        (
            "duration_s = 120",
            'duration_s = 120\ndifficulty = "brutal"',
            "difficulty: must be one of 'practice'",
        ),
        (
            'mode = "specific"',
            'mode = "chaotic"',
            "fire.mode: must be one of 'uniform', 'specific'",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nprune_confidence = 1.5",
            "team.action.prune_confidence: must be a probability in (0, 1] "
            "(the manual's 10..100 %) (got 1.5)",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nprune_confidence = [0.9, 0]",
            "team.action.prune_confidence[1]: must be a probability in (0, 1]",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\ntank = 0",
            "team.action.tank: must be an integer >= 1 (dumps) (got 0)",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nbattery = 0",
            "team.action.battery: must be a number > 0",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nspeed = [20, -5]",
            "team.action.speed[1]: must be a number > 0",
        ),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\ncount = 1\naltitude = [50, 10]",
            "team.perception.altitude: must be [lo, hi] with 0 < lo <= hi (m)",
        ),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\ncount = 1\naltitude = [0, 10]",
            "team.perception.altitude: must be [lo, hi] with 0 < lo <= hi (m)",
        ),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\ncount = 1\nstart_altitude = 200",
            "team.perception.start_altitude: must be within the altitude range [10, 100] (m)",
        ),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\ncount = 1\nstart = [[900, 10]]",
            "team.perception.start[0]: must lie inside the map [0, 800] x [0, 800]",
        ),
        (
            REGION,
            "",
            "fire.regions: must list at least one fire region",
        ),
        (
            'orientation = "vertical"',
            'orientation = "vertical"\n[scoring.penalties]\nhospital = -2',
            "scoring.penalties.hospital: must be a number >= 0 (got -2.0)",
        ),
    ],
)
def test_out_of_range_values_are_one_line_errors(tmp_path, old, new, expected):
    """Each invalid value gives one line: file, dotted field, allowed range, offending value."""
    assert expected in load_error(tmp_path, edit(old, new))


def test_overlapping_facilities_are_an_error(tmp_path):
    """Two facility footprints may not overlap; the message names both and their boxes."""
    msg = load_error(tmp_path, BASE + '\n[[facilities]]\nkind = "house"\ncell = "F-06"\n')
    assert (
        "facilities[1].cell: footprint x in (540, 660), y in (525, 675) overlaps house (600, 500)"
        in msg
    )
    assert (
        "(facilities[0]: x in (540, 660), y in (425, 575)); "
        "facility and depot footprints may not overlap" in msg
    )


def test_facility_overlapping_the_depot_is_an_error(tmp_path):
    """A facility may not overlap the depot footprint either."""
    msg = load_error(tmp_path, BASE + '\n[[facilities]]\nkind = "hospital"\ncenter = [190, 300]\n')
    assert (
        "facilities[1].center: footprint" in msg
        and "overlaps the depot (depot: x in (20, 180)" in msg
    )


def test_facility_outside_the_map_is_an_error(tmp_path):
    """A facility whose centre is off the map is rejected with the map's range."""
    msg = load_error(tmp_path, edit('cell = "F-05"', "center = [900, 100]"))
    assert (
        "facilities[0].center: must lie inside the map [0, 800] x [0, 800] (got '(900, 100)')"
        in msg
    )


def test_cell_off_the_grid_is_an_error(tmp_path):
    """A facility cell beyond the 8x8 grid of an 800 px map is rejected."""
    msg = load_error(tmp_path, edit('cell = "F-05"', 'cell = "I-05"'))
    assert "facilities[0].cell: must be a cell of the 8x8 grid of a 800 px map (A-01..H-08)" in msg


def test_footprint_may_overhang_the_map_edge():
    """Scenario #7's power station at C-11 ends 10 px below the map, as in the game: valid."""
    s = load_scenario(7)
    power = s.facilities[-1]
    assert power.kind == "power_station" and power.cell == "C-11"
    assert power.footprint[3] == 1210 > s.world_size


def test_region_inside_a_facility_is_an_error(tmp_path):
    """A fire may not start inside a facility footprint."""
    msg = load_error(tmp_path, edit('cell = "E-02"', "center = [610, 510]"))
    assert (
        "fire.regions[0].center: region centre lies inside the footprint of house (600, 500)" in msg
    )
    assert "fires may not start inside a facility or the depot (got '(610, 510)')" in msg


def test_region_inside_the_depot_is_an_error(tmp_path):
    """A fire may not start inside the depot."""
    msg = load_error(tmp_path, edit('cell = "E-02"', 'cell = "A-02"'))
    assert "fire.regions[0].cell: region centre lies inside the footprint of the depot" in msg


def test_region_on_a_footprint_edge_is_allowed(tmp_path):
    """Footprints are open boxes: a centre exactly on the edge is outside."""
    s = load_text(tmp_path, edit('cell = "E-02"', "center = [540, 500]"))
    assert s.regions[0].center == (540, 500)


def test_team_without_an_action_agent_is_an_error(tmp_path):
    """A team must be able to act (action or hybrid agents)."""
    msg = load_error(tmp_path, edit("[team.action]\ncount = 2", "[team.action]\ncount = 0"))
    assert (
        "team: needs at least one agent that can sense (perception or hybrid) and one that can act"
        in msg
    )
    assert "(got {'perception': 1, 'action': 0, 'hybrid': 0})" in msg


def test_team_without_a_perception_agent_is_an_error(tmp_path):
    """A team must be able to sense; a lone hybrid does both and is enough."""
    no_eyes = edit("[team.perception]\ncount = 1", "[team.perception]\ncount = 0")
    assert "team: needs at least one agent that can sense" in load_error(tmp_path, no_eyes)
    only_hybrid = no_eyes.replace("[team.action]\ncount = 2", "[team.hybrid]\ncount = 1")
    assert load_text(tmp_path, only_hybrid).team_counts == {
        "perception": 0,
        "action": 0,
        "hybrid": 1,
    }


def test_uniform_mode_requires_identical_region_parameters(tmp_path):
    """In uniform mode every region shares fronts, delay, fuel and wind."""
    two = (
        BASE
        + '\n[[fire.regions]]\ncell = "B-06"\nfronts = 4\nfuel = 9\n'
        + "wind_speed = 5\nwind_dir_deg = 90\n"
    )
    msg = load_error(tmp_path, two.replace('mode = "specific"', 'mode = "uniform"'))
    assert "fire.regions[1].fuel: must equal fire.regions[0].fuel (8) in uniform fire mode" in msg
    assert 'use mode = "specific" for per-region values (got 9.0)' in msg
    assert len(load_text(tmp_path, two).regions) == 2


def test_delay_past_the_end_is_allowed_but_outside_the_manual(tmp_path):
    """A region that ignites after the game ends is valid (it never fires); > 180 s is noted."""
    s = load_text(tmp_path, edit("fuel = 8", "fuel = 8\ndelay_s = 500"))
    assert s.regions[0].delay_s == 500
    assert "fire.regions[0].delay_s: 500 (manual: 0..180 s)" in s.manual_limit_violations()


def direct(**changes):
    """Scenario #1 rebuilt in Python with ``changes`` (its source is the shipped file)."""
    return load_scenario(1).replace(**changes)


def test_direct_construction_checks_agent_order_and_ids():
    """Agents must be listed P, A, H with ids numbered within their role."""
    s = load_scenario(1)
    p1, p2, a1, a2 = s.agents
    with pytest.raises(
        ScenarioError, match=r"agents\[1\].role: agents must be listed perception first"
    ):
        direct(agents=(a1, p1, p2, a2))
    with pytest.raises(
        ScenarioError, match=r"agents\[1\].id: must be 'P2' \(role letter \+ index\) \(got 'P7'\)"
    ):
        direct(agents=(p1, dataclasses.replace(p2, id="P7"), a1, a2))
    with pytest.raises(ScenarioError, match=r"agents\[0\]: must be an AgentSpec"):
        direct(agents=("P1", a1))


def test_direct_construction_checks_role_specific_values():
    """Action agents fly at 30 m; perception agents have no tank and no prune confidence."""
    p1, p2, a1, a2 = load_scenario(1).agents
    with pytest.raises(
        ScenarioError, match=r"team.action.altitude\[0\]: action agents fly at a fixed \[30, 30\]"
    ):
        direct(agents=(p1, p2, dataclasses.replace(a1, altitude=(20, 40)), a2))
    with pytest.raises(
        ScenarioError, match=r"team.perception.tank\[1\]: must be 0 for perception agents"
    ):
        direct(agents=(p1, dataclasses.replace(p2, tank=3), a1, a2))
    with pytest.raises(ScenarioError, match=r"team.perception.prune_confidence: must be 0"):
        p1, p2 = (dataclasses.replace(p, prune_confidence=0.5) for p in (p1, p2))
        direct(agents=(p1, p2, a1, a2))


def test_direct_construction_checks_cells_and_order():
    """A cell must agree with the centre; facilities are listed by kind; types are checked."""
    s = load_scenario(1)
    moved = dataclasses.replace(s.regions[0], center=(360, 350))
    with pytest.raises(
        ScenarioError,
        match=r"fire.regions\[0\].center: must be the centre \(350, 350\) of its cell D-04",
    ):
        direct(regions=(moved,))
    with pytest.raises(
        ScenarioError, match=r"facilities\[1\].kind: facilities must be listed houses first"
    ):
        direct(facilities=(s.facilities[-1], *s.facilities[:-1]))
    with pytest.raises(ScenarioError, match=r"fire.regions\[0\]: must be a FireRegion"):
        direct(regions=({"cell": "D-04"},))
    with pytest.raises(
        ScenarioError, match=r"depot.orientation: must be one of 'vertical', 'horizontal'"
    ):
        direct(depot=Depot((100, 600), "sideways"))
    with pytest.raises(ScenarioError, match=r"facilities\[0\].kind: must be one of 'house'"):
        direct(facilities=(Facility("shed", (800, 800), (10, 10), 1.0),))
    with pytest.raises(ScenarioError, match=r"notes: must be a list of strings"):
        direct(notes=(1,))
    with pytest.raises(ScenarioError, match=r"scoring.temporal_exponent: must be a number >= 0"):
        direct(scoring=dataclasses.replace(s.scoring, temporal_exponent=-1))


def test_errors_name_the_scenario_when_there_is_no_file():
    """A Scenario built in Python names itself in error messages."""
    s = dataclasses.replace(load_scenario(1), source=None)
    with pytest.raises(ScenarioError, match=r"^#1: duration_s: must be a number > 0"):
        s.replace(duration_s=-1)


# ----------------------------------------------------------------------------------- manual limits
def within_manual():
    """The open-world example: inside every manual limit."""
    s = load_scenario("open_world_example")
    assert s.manual_limit_violations() == []
    return s


def test_scale_design_lists_each_exceeded_limit():
    """A 2000 px, 6-region, 12-agent design is valid but lists those limits."""
    s = load_scenario(1)
    regions = tuple(FireRegion((150 + 300 * i, 1550), 3, 0, 10, 5, 45) for i in range(6))
    p = AgentSpec("P1", Role.PERCEPTION, (60, 420), (10, 100), 20, 500, 20, 0, 0.0)
    agents = tuple(dataclasses.replace(p, id=f"P{k + 1}") for k in range(6)) + tuple(
        AgentSpec(f"A{k + 1}", Role.ACTION, (60, 420), (30, 30), 30, 500, 20, 10, 0.9)
        for k in range(6)
    )
    big = s.replace(world_size=2000, regions=regions, fire_mode="specific", agents=agents)
    lines = big.manual_limit_violations()
    assert "world_size: 2000 (manual: 800, 1000 or 1200)" in lines
    assert "fire.regions: 6 regions (manual: 1..5)" in lines
    assert "team: 12 agents in total (manual: at most 9)" in lines
    assert all("\n" not in line for line in lines)


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (lambda s: s.replace(duration_s=90), "duration_s: 90 (manual: 60, 120 or 180)"),
        (lambda s: s.replace(world_size=1100), "world_size: 1100 (manual: 800, 1000 or 1200)"),
        (
            lambda s: s.replace(
                regions=tuple(dataclasses.replace(r, fronts=12) for r in s.regions)
            ),
            "fire.regions: 36 fronts in total (manual: at most 30 over all regions)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], fronts=31),)),
            "fire.regions[0].fronts: 31 (manual: 1..30)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], fuel=25),)),
            "fire.regions[0].fuel: 25 (manual: 2..20)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], fuel=1.5),)),
            "fire.regions[0].fuel: 1.5 (manual: 2..20)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], wind_speed=1),)),
            "fire.regions[0].wind_speed: 1 (manual: 2..10 m/s)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], wind_dir_deg=-45),)),
            "fire.regions[0].wind_dir_deg: -45 (manual: 0..360 degrees)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], delay_s=181),)),
            "fire.regions[0].delay_s: 181 (manual: 0..180 s)",
        ),
        (
            lambda s: s.replace(regions=(dataclasses.replace(s.regions[0], half_width=20),)),
            "fire.regions[0].half_width: 20 (manual: 50 px, one grid cell)",
        ),
        (
            lambda s: s.replace(scoring=dataclasses.replace(s.scoring, temporal_exponent=2.5)),
            "scoring.temporal_exponent: 2.5 (manual: 0..2)",
        ),
        (
            lambda s: s.replace(scoring=dataclasses.replace(s.scoring, propagation_weight=1.5)),
            "scoring.propagation_weight: 1.5 (manual: 0..1)",
        ),
        (
            lambda s: s.replace(depot=dataclasses.replace(s.depot, penalty=9)),
            "scoring.penalties.depot: 9 (manual: fixed at 5)",
        ),
        (
            lambda s: s.replace(
                facilities=(dataclasses.replace(s.facilities[0], penalty=2), *s.facilities[1:])
            ),
            "scoring.penalties.house: 2 (manual: fixed at 1)",
        ),
        (
            lambda s: s.replace(
                facilities=(
                    dataclasses.replace(s.facilities[0], size=(100, 100)),
                    *s.facilities[1:],
                )
            ),
            "facilities[0].size: 100 x 100 (manual: 120 x 150 for a house)",
        ),
        (lambda s: s.replace(lakes=s.lakes * 6), "lakes: 6 lakes (manual: 0..5)"),
    ],
)
def test_each_manual_limit_is_reported(change, expected):
    """Exceeding one manual limit adds its line, with the manual's allowed value."""
    s = change(within_manual())
    assert expected in s.manual_limit_violations()


def team_change(role: Role, **changes):
    """Apply ``changes`` to every agent of ``role`` in the open-world example."""

    def apply(s):
        agents = tuple(dataclasses.replace(a, **changes) if a.role is role else a for a in s.agents)
        return s.replace(agents=agents)

    return apply


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (
            team_change(Role.PERCEPTION, battery=900),
            "team.perception.battery: 900 (manual: 200..800)",
        ),
        (team_change(Role.ACTION, speed=5), "team.action.speed: 5 (manual: 10..30)"),
        (team_change(Role.HYBRID, tank=16), "team.hybrid.tank: 16 (manual: 1..15)"),
        (
            team_change(Role.ACTION, prune_confidence=0.05),
            "team.action.prune_confidence: 0.05 (manual: 0.1..1, i.e. 10..100 %)",
        ),
        (
            team_change(Role.PERCEPTION, altitude=(5, 100), start_altitude=20),
            "team.perception.altitude: [5, 100] (manual: within 10..100 m)",
        ),
        (
            team_change(Role.PERCEPTION, altitude=(10, 120), start_altitude=20),
            "team.perception.altitude: [10, 120] (manual: within 10..100 m)",
        ),
        (
            team_change(Role.HYBRID, altitude=(25, 100), start_altitude=25),
            "team.hybrid.altitude: [25, 100] (manual: lower bound 10..20 m, upper bound 20..100 m)",
        ),
        (
            team_change(Role.HYBRID, altitude=(10, 15), start_altitude=15),
            "team.hybrid.altitude: [10, 15] (manual: lower bound 10..20 m, upper bound 20..100 m)",
        ),
        (
            team_change(Role.ACTION, start=(500, 500)),
            "team.action.start[0]: (500, 500) "
            "(manual: agents start in their depot slot (480, 860))",
        ),
        (
            team_change(Role.HYBRID, start_altitude=50),
            "team.hybrid.start_altitude: 50 (manual: the game starts at 20 m)",
        ),
    ],
)
def test_agent_limits_are_reported_once_per_value(change, expected):
    """Agent limits name the role field; a value shared by the role gives one line."""
    lines = change(within_manual()).manual_limit_violations()
    assert expected in lines
    assert len([line for line in lines if line.split(":")[0] == expected.split(":")[0]]) == 1


def test_placement_limits_are_reported():
    """Off-grid centres, shared grid cells and misplaced depots are outside the manual."""
    s = within_manual()
    off_grid = s.replace(lakes=(dataclasses.replace(s.lakes[0], center=(160, 800), cell=None),))
    assert (
        "lakes[0]: centre (160, 800) is off the grid (manual: objects are placed on grid cells)"
        in (off_grid.manual_limit_violations())
    )
    # a house block on the lake's cells (the pixel footprints do not overlap anything)
    crowded = s.replace(
        facilities=(*s.facilities[:3], Facility.standard("house", (200, 700)), *s.facilities[3:])
    )
    assert any(
        line.startswith("lakes[0]: its block at A-07 shares grid cells with facilities[3] (B-07)")
        for line in crowded.manual_limit_violations()
    )
    inland = s.replace(depot=Depot((500, 800), "horizontal"))
    assert (
        "depot: horizontal depot at D-08 "
        "(manual: top-left cell in row 1 or 9, on the top or bottom edge)"
        in inland.manual_limit_violations()
    )
    vertical = load_scenario(1).replace(depot=Depot((300, 600), "vertical"))
    assert (
        "depot: vertical depot at C-05 "
        "(manual: top-left cell in column A or K, on the left or right edge)"
        in vertical.manual_limit_violations()
    )
    right_edge = load_scenario(1).replace(depot=Depot((1100, 1000), "vertical"))
    assert not [line for line in right_edge.manual_limit_violations() if line.startswith("depot")]


def test_lake_block_past_the_map_edge_is_reported():
    """A lake's 3x4 block must fit on the grid in the GUI."""
    s = within_manual()
    edge = s.replace(lakes=(dataclasses.replace(s.lakes[0], center=(950, 200), cell="I-01"),))
    assert (
        "lakes[0]: its 3x4 block at I-01 extends past the 10x10 grid "
        "(manual: objects fit inside the map)" in (edge.manual_limit_violations())
    )


def test_fcplan_settings_are_not_manual_limits():
    """ticks_per_second, comm_range and action_gate are fcplan settings, never reported."""
    s = within_manual().replace(ticks_per_second=50, comm_range=10.0, action_gate="reference")
    assert s.manual_limit_violations() == []
