"""Tests of fcplan.scenario.bounds: every numeric field has an upper bound, the memory an episode
needs is estimated and capped, documents are checked for depth and size before they are read,
and validation is linear in the team size."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from fcplan.scenario import ScenarioError, load_scenario
from fcplan.scenario.bounds import (
    MAX_AGENTS,
    MAX_DEPTH,
    MEMORY_LIMIT_BYTES,
    RANGES,
    check_document,
    estimate_bytes,
)
from fcplan.scenario.read import scenario_from_dict


def doc_with(path: str, value) -> dict:
    """Scenario #12's document with ``value`` at the dotted ``path`` (``[i]`` indexes lists)."""
    doc = copy.deepcopy(load_scenario(12).to_dict())
    node = doc
    parts = path.split(".")
    for part in parts[:-1]:
        key, _, idx = part.partition("[")
        node = node[key] if not idx else node[key][int(idx[:-1])]
    node[parts[-1]] = value
    return doc


def error_of(path: str, value) -> ScenarioError:
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(doc_with(path, value), "mutant.toml")
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("mutant.toml: ")
    return exc.value


# The audit's crashers (issue 17) and their kin: each used to validate and then crash or exhaust
# memory in `fcplan run`.
CRASHERS = [
    ("scoring.temporal_exponent", 1000.0, "scoring.temporal_exponent"),
    ("fire.regions[0].half_width", 1e-300, "fire.regions[0].half_width"),
    ("duration_s", 1e12, "duration_s"),
    ("world_size", 10_000_000, "world_size"),
    ("fire.regions[0].fronts", 1_000_000_000, "fire.regions[0].fronts"),
    ("ticks_per_second", 1_000_000, "ticks_per_second"),
    ("fire.regions[0].delay_s", 1e300, "fire.regions[0].delay_s"),
    ("fire.regions[0].fuel", 1e300, "fire.regions[0].fuel"),
    ("fire.regions[0].wind_speed", 1e300, "fire.regions[0].wind_speed"),
    ("fire.regions[0].wind_dir_deg", 1e300, "fire.regions[0].wind_dir_deg"),
    ("team.action.speed", 1e300, "team.action.speed"),
    ("team.action.battery", 1e300, "team.action.battery"),
    ("team.action.tank", 100_000, "team.action.tank"),
    ("team.perception.altitude", [10.0, 1e300], "team.perception.altitude"),
    ("scoring.propagation_weight", 1e300, "scoring.propagation_weight"),
    ("comm_range", 1e300, "comm_range"),
    ("team.perception.count", 100_000_000, "team.perception.count"),
    ("duration_s", 0.01, "duration_s"),  # no tick at all
]


@pytest.mark.parametrize("path, value, field", CRASHERS)
def test_values_the_simulator_cannot_represent_are_refused_at_load(path, value, field):
    """Each of the audit's crashing values (overflow, empty ignition box, terabyte grids and
    traces, a billion fronts or agents) is a one-line ScenarioError naming the field, raised
    before anything is allocated."""
    assert error_of(path, value).field == field


@pytest.mark.parametrize(
    "name",
    ["duration_s", "ticks_per_second", "scoring.temporal_exponent", "scoring.propagation_weight"],
)
def test_the_top_of_each_range_is_valid_and_just_above_is_not(name):
    """The documented upper bound of a scenario-wide field is accepted and anything above it
    refused with the range in the message."""
    lo, hi, _, _ = RANGES[name]
    ok = doc_with(name, hi)
    if name == "ticks_per_second":  # keep the episode small: 1,000 ticks per second for 1 s
        ok["duration_s"] = 1.0
    scenario_from_dict(ok)
    above = hi + 1 if isinstance(hi, int) else hi * 1.0001
    err = error_of(name, above)
    assert f"{hi:g}" in err.problem


@pytest.mark.parametrize(
    "field, hi",
    [("fuel", 1_000.0), ("wind_speed", 100.0), ("delay_s", 1e6), ("wind_dir_deg", 3_600.0)],
)
def test_region_parameters_have_upper_bounds(field, hi):
    """Region fuel, wind speed, delay and wind direction accept their bound and refuse above it
    (and half_width must hold a whole pixel and fit the map)."""
    scenario_from_dict(doc_with(f"fire.regions[0].{field}", hi))
    assert error_of(f"fire.regions[0].{field}", hi * 1.01).field == f"fire.regions[0].{field}"
    assert error_of("fire.regions[0].half_width", 0.5).problem.startswith("must be a number in [1,")
    assert error_of("fire.regions[0].half_width", 1201.0).field == "fire.regions[0].half_width"


def test_memory_estimate_refuses_what_would_not_fit_and_names_the_driver():
    """A scenario whose estimated episode memory exceeds MEMORY_LIMIT_BYTES is refused with the
    estimate, its parts and the field that drives it (the trace: duration_s; the grid:
    world_size); shipped scenarios need a small fraction of the limit."""
    for n in (1, 12, 24):
        assert estimate_bytes(load_scenario(n)) < MEMORY_LIMIT_BYTES / 20
    doc = doc_with("duration_s", 86_400.0)
    doc["ticks_per_second"] = 100
    doc["team"]["perception"]["count"] = 300
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(doc, "long.toml")
    assert exc.value.field == "duration_s"
    assert "GiB" in exc.value.problem and "8 GiB limit" in exc.value.problem
    doc = doc_with("world_size", 16_000)
    doc["team"]["perception"]["count"] = 3_000
    with pytest.raises(ScenarioError, match="memory"):
        scenario_from_dict(doc)


def test_scale_studies_stay_valid():
    """The scales the bounds are meant to allow validate: a 10,000 px map with 120 agents and
    45 regions for an hour, and a 10,000-agent team on a 2,000 px map."""
    doc = doc_with("world_size", 10_000)
    doc["duration_s"] = 3_600.0
    doc["team"]["perception"]["count"] = 60
    doc["team"]["action"]["count"] = 60
    region = doc["fire"]["regions"][0]
    doc["fire"]["regions"] = [
        dict(region, cell=f"{c}-{r:02d}") for c in "DEF" for r in range(3, 18)
    ]
    s = scenario_from_dict(doc)
    assert len(s.regions) == 45 and len(s.agents) == 120
    doc = doc_with("world_size", 2_000)
    doc["team"]["perception"]["count"] = MAX_AGENTS // 2
    doc["team"]["action"]["count"] = MAX_AGENTS // 2
    doc["team"]["perception"]["battery"] = [500.0 + k for k in range(MAX_AGENTS // 2)]
    assert len(scenario_from_dict(doc).agents) == MAX_AGENTS


def test_documents_are_checked_for_depth_and_counts_before_reading():
    """check_document refuses, without recursion and before any allocation, nesting deeper than
    MAX_DEPTH (even 100,000 levels), a count above MAX_AGENTS, and too many regions; a shipped
    document passes."""
    check_document(load_scenario(12).to_dict())
    deep: list = []
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(ScenarioError, match=f"more than {MAX_DEPTH} levels"):
        check_document({"name": "x", "notes": deep})
    with pytest.raises(ScenarioError, match="team.hybrid.count"):
        check_document({"team": {"hybrid": {"count": 10**12}}})
    with pytest.raises(ScenarioError, match="at most 10,000 agents"):
        check_document({"team": {"action": {"count": 6_000}, "perception": {"count": 6_000}}})
    with pytest.raises(ScenarioError, match="fire regions"):
        check_document({"fire": {"regions": [{}] * 1_001}})
    with pytest.raises(ScenarioError, match="notes"):
        scenario_from_dict({"name": "deep", "notes": deep})


def test_agent_errors_name_per_agent_fields_in_a_big_team():
    """In a team of thousands, a bad value of one agent is still named with its index within
    its role (the linear field paths agree with agent_field)."""
    from fcplan.scenario.validate import agent_field

    n = 3_000
    doc = doc_with("team.perception.count", n)
    doc["team"]["perception"]["speed"] = [20.0] * n
    doc["team"]["perception"]["speed"][2_345] = -1.0
    with pytest.raises(ScenarioError) as exc:
        scenario_from_dict(doc)
    assert exc.value.field == "team.perception.speed[2345]"
    s = load_scenario(12)
    agents = list(s.agents)
    from fcplan.scenario import Role

    assert agent_field(agents, Role.ACTION, 1, "tank") == "team.action.tank"
    assert agent_field(agents, Role.ACTION, 1, "start") == "team.action.start[1]"


def test_many_facilities_are_checked_for_overlap():
    """Footprint overlap and fires inside footprints are still found among 2,000 facilities
    (checked with vectorised passes), naming the first offending pair."""
    doc = doc_with("world_size", 16_000)
    xs, ys = np.meshgrid(np.arange(300, 15_000, 300), np.arange(300, 12_500, 300))
    doc["facilities"] = [
        {"kind": "house", "center": [float(x), float(y)]}
        for x, y in zip(xs.ravel(), ys.ravel(), strict=True)
    ][:2_000]
    doc["lakes"] = []
    doc["fire"]["regions"] = [{"center": [15_500.0, 15_500.0], "fronts": 3}]
    s = scenario_from_dict(doc)
    assert len(s.facilities) == 2_000
    doc["facilities"][1_999]["center"] = [310.0, 310.0]
    with pytest.raises(ScenarioError, match=r"facilities\[1999\].center: footprint .* overlaps"):
        scenario_from_dict(doc)
