"""Tests of fcplan.scenario.write: dumping TOML text, and round trips through a file."""

from __future__ import annotations

import dataclasses
import tomllib

from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.scenario import (
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    dump_scenario,
    load_scenario,
)
from tests.scenario.designs import write


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
