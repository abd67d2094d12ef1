"""Tests of fcplan.scenario.io: the TOML format, loading, dumping and scenario names."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.errors import UnknownNameError
from fcplan.scenario import (
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    ScenarioError,
    dump_scenario,
    list_scenarios,
    load_scenario,
    scenario_path,
)
from tests.scenario.designs import BASE


def write(tmp_path: Path, text: str, name: str = "design.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def edit(old: str, new: str) -> str:
    """BASE with ``old`` replaced by ``new`` (``old`` must occur)."""
    assert old in BASE, old
    return BASE.replace(old, new)


def load_error(tmp_path: Path, text: str) -> str:
    """The one-line message of the ScenarioError that loading ``text`` raises."""
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    msg = str(info.value)
    assert "\n" not in msg, msg
    assert msg.startswith(f"{path}: "), msg
    return msg


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


def test_names_resolve_to_the_same_shipped_file():
    """12, "12", "#12", "012" and " #12 " all name scenario #12; 0 and "practice" the practice."""
    path = scenario_path(12)
    assert path.name == "12.toml"
    assert all(scenario_path(n) == path for n in ("12", "#12", "012", " #12 "))
    assert scenario_path(0) == scenario_path("practice") == scenario_path("Practice")
    assert scenario_path("scale_example").name == "scale_example.toml"
    assert load_scenario("01") == load_scenario(1)


def test_paths_are_loaded_as_files(tmp_path):
    """A path-like, a .toml name or a name with a separator is a file, not a shipped name."""
    path = write(tmp_path, BASE)
    assert scenario_path(path) == path
    assert scenario_path(str(path)) == path
    assert load_scenario(str(path)) == load_scenario(path)


def test_list_scenarios_order():
    """practice, 1..24, then the open-world examples."""
    names = list_scenarios()
    assert names == ["practice", *map(str, range(1, 25)), "open_world_example", "scale_example"]


@pytest.mark.parametrize("name", ["25", "#99", "nope", -1, 3.0])
def test_unknown_names_list_the_known_ones(name):
    """An unknown scenario name raises UnknownNameError, one line listing the known names."""
    with pytest.raises(UnknownNameError) as info:
        load_scenario(name)
    msg = str(info.value)
    assert "\n" not in msg
    assert repr(name) in msg
    assert "practice, 1, 2," in msg and "24, open_world_example, scale_example" in msg
    assert isinstance(info.value, KeyError)


def test_missing_file_names_the_file(tmp_path):
    """A .toml path that does not exist is a one-line ScenarioError naming it."""
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(ScenarioError, match=f"^{missing}: file: no such scenario file$"):
        load_scenario(missing)


def test_malformed_toml_gives_line_and_column(tmp_path):
    """Invalid TOML is reported with field 'toml' and the parser's line and column."""
    msg = load_error(tmp_path, edit("fronts = 4", "fronts = = 4"))
    assert ": toml: not valid TOML: " in msg
    assert "line 10, column" in msg


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
            "must be an integer >= 0",
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


def test_dump_writes_the_file_and_returns_the_text(tmp_path):
    """dump_scenario returns TOML text and writes it when given a path."""
    s = load_scenario(7)
    path = tmp_path / "seven.toml"
    text = dump_scenario(s, path)
    assert path.read_text(encoding="utf-8") == text
    assert tomllib.loads(text)["name"] == "#7"
    assert load_scenario(path) == s


def test_round_trip_keeps_non_default_details(tmp_path):
    """Centres, half widths, penalties, sizes, starts, altitudes and settings survive a dump."""
    base = load_scenario("open_world_example")
    agents = list(base.agents)
    agents[0] = dataclasses.replace(agents[0], start=(333.5, 870), start_altitude=55)
    agents[3] = dataclasses.replace(agents[3], battery=250.25)
    facilities = list(base.facilities)
    facilities[1] = dataclasses.replace(
        facilities[1], penalty=4, size=(100, 100), center=(510, 405), cell=None
    )
    facilities[4] = dataclasses.replace(facilities[4], penalty=0)
    s = base.replace(
        regions=(
            dataclasses.replace(base.regions[0], half_width=10.5, center=(251.5, 249), cell=None),
            *base.regions[1:],
        ),
        facilities=tuple(facilities),
        lakes=(Lake((123.25, 456)),),
        agents=tuple(agents),
        depot=Depot((500, 900), "horizontal", penalty=7.5, cell="D-09"),
        ticks_per_second=25,
        comm_range=None,
        action_gate="reference",
        notes=("a note",),
    )
    again = load_scenario(write(tmp_path, dump_scenario(s)))
    assert again == s


def test_round_trip_of_uniform_scenarios_writes_parameters_once():
    """In uniform mode the shared region parameters are written in [fire] only."""
    doc = load_scenario(1).to_dict()
    assert doc["fire"]["fronts"] == 10
    assert doc["fire"]["regions"] == [{"cell": "D-04"}]


text_strategy = st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=40)


@settings(max_examples=60, deadline=None)
@given(name=text_strategy.filter(lambda t: t.strip()), notes=st.lists(text_strategy, max_size=3))
def test_round_trip_of_arbitrary_text(tmp_path_factory, name, notes):
    """Any name and notes text (quotes, backslashes, control characters) survives a dump."""
    s = load_scenario(3).replace(name=name, number=None, notes=tuple(notes))
    path = tmp_path_factory.mktemp("rt") / "s.toml"
    dump_scenario(s, path)
    again = load_scenario(path)
    assert again == s


def test_python_built_parts_round_trip(tmp_path):
    """A scenario built from Python objects (centres, no cells) dumps and loads back equal."""
    s = load_scenario(1).replace(
        regions=(FireRegion((333, 333), 3, 0, 10, 5, 45),),
        fire_mode="specific",
        facilities=(Facility.standard("power_station", (700, 700)),),
        agents=(
            AgentSpec("P1", Role.PERCEPTION, (60, 420), (10, 100), 20, 500, 20, 0, 0.0),
            AgentSpec("H1", Role.HYBRID, (60, 480), (15, 100), 20, 500, 20, 2, 0.5),
        ),
    )
    assert load_scenario(write(tmp_path, dump_scenario(s))) == s
