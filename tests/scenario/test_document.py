"""Tests of fcplan.scenario.document: the TOML format read into a Scenario (defaults, types,
unknown keys, structural errors)."""

from __future__ import annotations

import tomllib

import pytest

from fcplan.scenario import Role, ScenarioError, load_scenario
from fcplan.scenario.document import REGION_DEFAULTS, TEAM_DEFAULTS, scenario_fields
from tests.scenario.designs import BASE, edit, load_error, write


def test_base_design_loads_with_defaults(tmp_path):
    """Omitted values take the format's defaults (manual defaults, slots, start altitudes)."""
    s = load_scenario(write(tmp_path, BASE))
    assert s.name == "small" and s.number is None and s.difficulty == "custom"
    assert s.ticks_per_second == 10 and s.action_gate == "sensed" and s.comm_range is None
    r = s.regions[0]
    assert (r.center, r.cell, r.fronts, r.delay_s, r.fuel, r.wind_speed, r.wind_dir_deg) == (
        (450, 150),
        "E-02",
        4,
        0,
        8,
        5,
        90,
    )
    assert r.half_width == 50
    assert s.depot.center == (100, 200) and s.depot.penalty == 5
    assert s.facilities[0].center == (600, 500) and s.facilities[0].penalty == 1
    p1, a1, a2 = s.agents
    assert (p1.altitude, p1.start_altitude, p1.battery, p1.speed, p1.tank) == (
        (10, 100),
        20,
        500,
        20,
        0,
    )
    assert (a1.altitude, a1.start_altitude, a1.tank, a1.prune_confidence) == ((30, 30), 30, 10, 0.9)
    assert [a.start for a in s.agents] == [(60, 20), (60, 80), (60, 140)]
    assert s.source == str(tmp_path / "design.toml")


def test_fire_table_values_are_defaults_for_every_region(tmp_path):
    """Region parameters in [fire] apply to every region that does not give its own."""
    text = edit('mode = "specific"', 'mode = "specific"\nfuel = 3\ndelay_s = 20')
    text += "\n[[fire.regions]]\ncenter = [725, 675]\nfronts = 2\nwind_dir_deg = 0\n"
    s = load_scenario(write(tmp_path, text))
    assert [r.fuel for r in s.regions] == [8, 3]
    assert [r.delay_s for r in s.regions] == [20, 20]
    assert s.regions[1].cell is None and s.regions[1].center == (725, 675)


def test_hybrid_and_heterogeneous_team(tmp_path):
    """Per-agent lists give heterogeneous agents; hybrids default to 80 % confidence."""
    text = BASE + (
        "\n[team.hybrid]\ncount = 2\naltitude = [[10, 60], [25, 100]]\nbattery = [300, 700]\n"
        "speed = 15\ntank = [3, 4]\n"
    )
    s = load_scenario(write(tmp_path, text))
    h1, h2 = s.agents[3:]
    assert (h1.id, h1.role, h1.altitude, h1.battery, h1.speed, h1.tank) == (
        "H1",
        Role.HYBRID,
        (10, 60),
        300,
        15,
        3,
    )
    assert (h2.altitude, h2.start_altitude, h2.battery, h2.tank) == ((25, 100), 25, 700, 4)
    assert h1.prune_confidence == h2.prune_confidence == 0.8
    assert h2.start == s.depot.slots(5)[4]


@pytest.mark.parametrize(
    ("old", "new", "field", "allowed"),
    [
        (
            "fronts = 4",
            "frontz = 4",
            "fire.regions[0].frontz",
            "allowed keys: cell, center, fronts",
        ),
        ('name = "small"', 'name = "small"\nseed = 1', "seed", "allowed keys: name, number"),
        (
            'orientation = "vertical"',
            'orientation = "vertical"\nangle = 0',
            "depot.angle",
            "allowed keys: cell, center, orientation",
        ),
        (
            "[team.action]",
            "[team.action]\naltitude = [10, 100]",
            "team.action.altitude",
            "allowed keys: count, battery, speed, tank, prune_confidence, start",
        ),
        (
            "[team.action]",
            "[team.drones]\ncount = 1\n[team.action]",
            "team.drones",
            "allowed keys: perception, action, hybrid",
        ),
    ],
)
def test_unknown_keys_are_errors(tmp_path, old, new, field, allowed):
    """An unknown key names its dotted path and lists the allowed keys."""
    msg = load_error(tmp_path, edit(old, new))
    assert f": {field}: unknown key; {allowed}" in msg


@pytest.mark.parametrize(
    ("old", "new", "field", "problem"),
    [
        ("fronts = 4", 'fronts = "4"', "fire.regions[0].fronts", "must be an integer (got '4')"),
        ("fronts = 4", "fronts = 4.0", "fire.regions[0].fronts", "must be an integer (got 4.0)"),
        ("fuel = 8", "fuel = true", "fire.regions[0].fuel", "must be a number (got True)"),
        ("world_size = 800", "world_size = 800.5", "world_size", "must be an integer"),
        ('cell = "E-02"', "cell = 5", "fire.regions[0].cell", "must be a cell name like 'D-05'"),
        ('cell = "E-02"', "center = [450]", "fire.regions[0].center", "must be a pair of numbers"),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nbattery = [500]",
            "team.action.battery",
            "one per agent (2 agents)",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 3\nstart = [60, 80]",
            "team.action.start",
            "must be a list with one a pair of numbers [x, y] per agent",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\nstart = [60, 80]",
            "team.action.start[0]",
            "must be a pair of numbers [x, y] (got 60)",
        ),
        (
            "[team.action]\ncount = 2",
            "[team.action]\ncount = 2\ntank = [1, false]",
            "team.action.tank[1]",
            "must be an integer (got False)",
        ),
        ('name = "small"', "name = 3", "name", "must be a string (got 3)"),
        ('name = "small"', 'name = "small"\nnotes = "x"', "notes", "must be a list of strings"),
    ],
)
def test_wrong_types_are_errors(tmp_path, old, new, field, problem):
    """A value of the wrong TOML type names the field and the expected type (bool is no number)."""
    msg = load_error(tmp_path, edit(old, new))
    assert f": {field}: " in msg and problem in msg


@pytest.mark.parametrize(
    ("old", "new", "field", "problem"),
    [
        (
            'cell = "E-02"',
            'cell = "E-02"\ncenter = [450, 150]',
            "fire.regions[0]",
            "give either cell or center, not both",
        ),
        ('cell = "E-02"\n', "", "fire.regions[0].cell", "is required"),
        ('cell = "E-02"', 'cell = "I-02"', "fire.regions[0].cell", "8x8 grid of a 800 px map"),
        ('name = "small"\n', "", "name", "is required (a string)"),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\nbattery = 3",
            "team.perception.count",
            "is required",
        ),
        (
            "[team.perception]\ncount = 1",
            "[team.perception]\ncount = -1",
            "team.perception.count",
            "must be an integer in 0..10000",
        ),
        (
            'orientation = "vertical"',
            'orientation = "diagonal"',
            "depot.orientation",
            "must be one of 'vertical', 'horizontal'",
        ),
        ('kind = "house"', 'kind = "depot"', "facilities[0].kind", "the depot goes in [depot]"),
        ("[fire]", '[fire]\naction_gate = "never"', "fire.action_gate", "'sensed', 'reference'"),
    ],
)
def test_structural_errors_name_the_field(tmp_path, old, new, field, problem):
    """Missing or contradictory keys are one-line errors naming the dotted field."""
    msg = load_error(tmp_path, edit(old, new))
    assert f": {field}: " in msg and problem in msg


def test_missing_depot_is_an_error(tmp_path):
    """A design without [depot] is rejected (agents need somewhere to start)."""
    text = edit('[depot]\ncell = "A-01"\norientation = "vertical"\n', "")
    assert ": depot: is required" in load_error(tmp_path, text)


def test_from_dict_errors_use_the_name_without_a_file():
    """from_dict without a source attributes errors to the scenario name."""
    doc = tomllib.loads(edit("fronts = 4", "fronts = 0"))
    with pytest.raises(
        ScenarioError, match=r"^small: fire.regions\[0\].fronts: must be an integer >= 1"
    ):
        load_scenario(1).from_dict(doc)


def test_fields_are_the_scenario_arguments_with_the_manual_defaults():
    """scenario_fields gives every Scenario argument but the source, filling omitted region and
    team values with REGION_DEFAULTS and TEAM_DEFAULTS."""
    import dataclasses

    from fcplan.scenario import Scenario

    doc = tomllib.loads(edit("fronts = 4\n", ""))
    fields = scenario_fields(doc)
    names = {f.name for f in dataclasses.fields(Scenario)}
    assert set(fields) == names - {"source"}
    assert fields["regions"][0].fronts == REGION_DEFAULTS["fronts"]
    p1, a1, _ = fields["agents"]
    assert p1.altitude == TEAM_DEFAULTS["altitude"] and p1.role is Role.PERCEPTION
    assert a1.prune_confidence == TEAM_DEFAULTS["prune_confidence"][Role.ACTION]
    assert Scenario(**fields) == Scenario.from_dict(doc)
