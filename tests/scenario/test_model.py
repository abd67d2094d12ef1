"""Tests of fcplan.scenario.model: the Scenario, its validation and derived values."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

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


def _runtime_imports(module) -> set[str]:
    """Modules a scenario module imports at run time (any level, TYPE_CHECKING blocks aside)."""
    import ast
    import inspect

    tree = ast.parse(inspect.getsource(module))
    skip = {
        id(n)
        for node in ast.walk(tree)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        for n in ast.walk(node)
    }
    out = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_scenario_modules_import_one_way():
    """The scenario package layers without cycles: parts and grid import no scenario module above
    them, validate and document import only those, model builds on all four, write on model; the
    generator (knobs, placement, generate) builds on model, the frozen suites on the generator and
    write, and catalogue (which knows the suites' names) and read sit on top; the package imports
    nothing of fcplan beyond fcplan.errors."""
    from fcplan.scenario import (
        bounds,
        catalogue,
        document,
        fieldpaths,
        generate,
        grid,
        knobs,
        model,
        parts,
        placement,
        read,
        suite,
        validate,
        write,
    )

    layers = [
        (parts, set()),
        (grid, set()),
        (bounds, set()),
        (fieldpaths, {"parts"}),
        (validate, {"parts", "grid", "bounds", "fieldpaths"}),
        (document, {"parts", "grid", "validate"}),
        (model, {"parts", "validate", "document"}),
        (write, {"document", "model"}),
        (knobs, {"validate"}),
        (placement, {"grid", "model"}),
        (generate, {"grid", "knobs", "model", "placement", "validate"}),
        (suite, {"generate", "model", "parts", "write"}),
        (catalogue, {"validate", "suite"}),
        (read, {"catalogue", "model", "bounds"}),
    ]
    for module, allowed in layers:
        fcplan_imports = {m for m in _runtime_imports(module) if m.startswith("fcplan")}
        scenario = {m.rpartition(".")[2] for m in fcplan_imports if m.startswith("fcplan.scenario")}
        assert scenario <= allowed, (module.__name__, scenario - allowed)
        assert fcplan_imports - {f"fcplan.scenario.{m}" for m in allowed} <= {"fcplan.errors"}
