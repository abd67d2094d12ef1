"""The scenario TOML document: its format, and its conversion to and from a Scenario's fields.

:func:`scenario_fields` reads a parsed document into the keyword arguments of
:class:`~fcplan.scenario.model.Scenario` (which then validates them); :func:`scenario_to_dict`
is the reverse. Files are read by :mod:`fcplan.scenario.read` and written by
:mod:`fcplan.scenario.write`.

A scenario file is a TOML document::

    name = "#12"
    number = 12                 # 0 practice, 1..24; omit for an open-world design
    difficulty = "moderate"     # practice | easy | moderate | hard | custom (default custom)
    world_size = 1200           # px, default 1200
    duration_s = 180            # simulated seconds, default 180
    ticks_per_second = 10       # default 10
    # comm_range = 300          # px, for decentralised schedulers; omit for unlimited
    # notes = ["..."]           # free text, loaded into Scenario.notes

    [fire]
    mode = "specific"           # uniform | specific (default specific)
    # action_gate = "sensed"    # sensed (manual rule) | reference (2020 code's looser gate)
    # wind_model = "tables"     # tables (the original's per-episode sample tables, default) |
    #                           #   fresh (new draws every fire step); see fcplan.fire
    # fronts, delay_s, fuel, wind_speed, wind_dir_deg, half_width here are defaults for every
    # region (in uniform mode, write them here only)

    [[fire.regions]]
    cell = "D-08"               # or center = [350, 750]
    fronts = 3                  # defaults: the manual's 10 fronts, delay 0 s, fuel 10,
    delay_s = 0                 #   wind 5 m/s at 45 degrees, ignition half width 50 px
    fuel = 5
    wind_speed = 5
    wind_dir_deg = 135

    [scoring]                   # optional
    propagation_weight = 0.1
    temporal_exponent = 1.25
    # [scoring.penalties]       # house = 1, hospital = 2, power_station = 5, depot = 5

    [depot]
    cell = "A-05"               # top-left cell of its block, or center = [100, 600]
    orientation = "vertical"    # vertical (2 x 4 cells) | horizontal (4 x 2), default vertical

    [[facilities]]              # houses first, then hospitals, then power stations
    kind = "house"              # house | hospital | power_station
    cell = "G-03"               # top-left cell of its 2 x 2 block, or center = [700, 300]
    # size = [120, 150]         # footprint override (px); penalty = 1 overrides per facility

    [[lakes]]
    cell = "E-09"               # top-left cell of its 3 x 4 block, or center = [550, 1000]

    [team.perception]           # [team.action], [team.hybrid] likewise; a role may be omitted
    count = 3
    altitude = [10, 100]        # per agent: [[10, 100], [10, 60], [20, 100]]
    battery = 500               # scalar, or one value per agent
    speed = 20

    [team.action]
    count = 2
    battery = 500
    speed = 20
    tank = 10
    prune_confidence = 0.9      # probability (the manual's 90 %)

Omitted team parameters take the manual's defaults: altitude [10, 100], battery 500, speed 20,
tank 10, prune confidence 0.9 (action) and 0.8 (hybrid). Agents start in the depot's slots
(:meth:`~fcplan.scenario.model.Depot.slots`) at altitude ``max(20, lo)`` (perception, hybrid) or
30 (action); optional per-agent ``start = [[x, y], ...]`` and ``start_altitude`` override that.

Unknown keys, wrong types (a bool is not a number) and out-of-range values are errors, reported as
one line ``<file>: <dotted.field>: <problem and allowed range> (got <value>)``.

Examples
--------
>>> fields = scenario_fields({"name": "tiny", "world_size": 800,
...     "fire": {"regions": [{"cell": "E-02", "fronts": 3}]}, "depot": {"cell": "A-01"},
...     "team": {"perception": {"count": 1}, "action": {"count": 1}}})
>>> fields["regions"][0].center, fields["regions"][0].fronts, fields["depot"].center
((450.0, 150.0), 3, (100.0, 200.0))
>>> [a.id for a in fields["agents"]], fields["agents"][1].start_altitude
(['P1', 'A1'], 30.0)
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from fcplan.errors import ScenarioError
from fcplan.scenario.grid import cell_center, format_cell, parse_cell
from fcplan.scenario.parts import (
    ACTION_ALTITUDE,
    DEFAULT_PENALTIES,
    DEFAULT_WIND_MODEL,
    FACILITY_KINDS,
    FACILITY_SIZES,
    FOOTPRINT_KINDS,
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    Scoring,
)
from fcplan.scenario.validate import is_integer, is_number

if TYPE_CHECKING:
    from fcplan.scenario.model import Scenario

__all__ = ["scenario_fields", "scenario_to_dict", "REGION_DEFAULTS", "TEAM_DEFAULTS"]

REGION_DEFAULTS: dict[str, Any] = {
    "fronts": 10,
    "delay_s": 0.0,
    "fuel": 10.0,
    "wind_speed": 5.0,
    "wind_dir_deg": 45.0,
    "half_width": 50.0,
}
"""Region parameters used when neither the region nor ``[fire]`` gives them (manual defaults)."""

TEAM_DEFAULTS: dict[str, Any] = {
    "altitude": (10.0, 100.0),
    "battery": 500.0,
    "speed": 20.0,
    "tank": 10,
    "prune_confidence": {Role.ACTION: 0.9, Role.HYBRID: 0.8},
}
"""Agent parameters used when a ``[team.<role>]`` section omits them (manual defaults)."""

_TOP_KEYS = (
    "name", "number", "difficulty", "world_size", "duration_s", "ticks_per_second",
    "comm_range", "notes", "fire", "scoring", "depot", "facilities", "lakes", "team",
)  # fmt: skip
_REGION_PARAMS = tuple(REGION_DEFAULTS)
_UNIFORM_PARAMS = ("fronts", "delay_s", "fuel", "wind_speed", "wind_dir_deg")
_FIRE_KEYS = ("mode", "action_gate", "wind_model", *_REGION_PARAMS, "regions")
_REGION_KEYS = ("cell", "center", *_REGION_PARAMS)
_SCORING_KEYS = ("propagation_weight", "temporal_exponent", "penalties")
_PENALTY_KEYS = FOOTPRINT_KINDS
_DEPOT_KEYS = ("cell", "center", "orientation")
_FACILITY_KEYS = ("kind", "cell", "center", "size", "penalty")
_LAKE_KEYS = ("cell", "center")
_ROLE_KEYS = {
    Role.PERCEPTION: ("count", "altitude", "battery", "speed", "start", "start_altitude"),
    Role.ACTION: ("count", "battery", "speed", "tank", "prune_confidence", "start"),
    Role.HYBRID: (
        "count", "altitude", "battery", "speed", "tank", "prune_confidence", "start",
        "start_altitude",
    ),
}  # fmt: skip

_REQUIRED = object()
_KINDS = {
    "str": "a string",
    "int": "an integer",
    "number": "a number",
    "pair": "a pair of numbers [x, y]",
    "strings": "a list of strings",
}


# -------------------------------------------------------------------------------------- reading
def _is_pair(v: Any) -> bool:
    return isinstance(v, list) and len(v) == 2 and all(map(is_number, v))


def _convert(value: Any, kind: str, field: str) -> Any:
    """Check the TOML type of ``value`` and convert it (numbers to float, pairs to tuples)."""
    ok = {
        "str": lambda v: isinstance(v, str),
        "int": is_integer,
        "number": is_number,
        "pair": _is_pair,
        "strings": lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v),
    }[kind](value)
    if not ok:
        raise ScenarioError(field, f"must be {_KINDS[kind]}", got=value)
    if kind == "number":
        return float(value)
    if kind == "pair":
        return (float(value[0]), float(value[1]))
    if kind == "strings":
        return tuple(value)
    return value


class _Table:
    """A TOML table being read: typed getters that know their dotted path; unknown keys are
    rejected on construction."""

    def __init__(self, value: Any, path: str, allowed: tuple[str, ...]):
        if not isinstance(value, dict):
            raise ScenarioError(path, "must be a table", got=value)
        self.data, self.path = value, path
        for key in value:
            if key not in allowed:
                raise ScenarioError(
                    self.field(key), f"unknown key; allowed keys: {', '.join(allowed)}"
                )

    def field(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.data

    def get(self, key: str, kind: str, default: Any = _REQUIRED) -> Any:
        if key not in self.data:
            if default is _REQUIRED:
                raise ScenarioError(self.field(key), f"is required ({_KINDS[kind]})")
            return default
        return _convert(self.data[key], kind, self.field(key))

    def table(self, key: str, allowed: tuple[str, ...]) -> _Table:
        return _Table(self.data.get(key, {}), self.field(key), allowed)

    def tables(self, key: str, allowed: tuple[str, ...]) -> list[_Table]:
        value = self.data.get(key, [])
        if not isinstance(value, list):
            raise ScenarioError(
                self.field(key), f"must be an array of tables [[{self.field(key)}]]", got=value
            )
        return [_Table(v, f"{self.field(key)}[{i}]", allowed) for i, v in enumerate(value)]

    def per_agent(
        self, key: str, kind: str, count: int, default: Any, *, shared: bool = True
    ) -> list[Any]:
        """A value given once for the whole role (if ``shared``), or a list with one per agent."""
        field = self.field(key)
        if key not in self.data:
            return [default] * count
        value = self.data[key]
        is_one = _is_pair(value) if kind == "pair" else not isinstance(value, list)
        if shared and is_one:
            return [_convert(value, kind, field)] * count
        one = (
            f"{_KINDS[kind]}, or a list with one per agent"
            if shared
            else f"a list with one {_KINDS[kind]} per agent"
        )
        if not isinstance(value, list):
            raise ScenarioError(field, f"must be {one}", got=value)
        if len(value) != count:
            raise ScenarioError(field, f"must be {one} ({count} agents)", got=value)
        return [_convert(v, kind, f"{field}[{i}]") for i, v in enumerate(value)]


def _place(t: _Table, kind: str, world: int) -> tuple[tuple[float, float], str | None]:
    """Centre and canonical cell of an object given by ``cell`` or ``center``."""
    if t.has("cell") and t.has("center"):
        raise ScenarioError(t.path, "give either cell or center, not both")
    if t.has("cell"):
        column, row = parse_cell(t.data["cell"], world, field=t.field("cell"))
        cell = format_cell(column, row)
        return cell_center(cell, kind, world), cell
    if t.has("center"):
        return t.get("center", "pair"), None
    raise ScenarioError(
        t.field("cell"), "is required: a grid cell like 'D-05' (or center = [x, y])"
    )


def scenario_fields(doc: Any) -> dict[str, Any]:
    """The keyword arguments of :class:`~fcplan.scenario.model.Scenario` (all but ``source``)
    read from a parsed TOML document (see the module docstring).

    Raises
    ------
    ScenarioError
        On unknown keys, wrong types and values no part can hold (the field path in the message,
        without a file: :meth:`Scenario.from_dict <fcplan.scenario.model.Scenario.from_dict>`
        adds it). The scenario-wide checks run when the Scenario is built.
    """
    top = _Table(doc, "", _TOP_KEYS)
    name = top.get("name", "str")
    number = top.get("number", "int", None)
    world = top.get("world_size", "int", 1200)
    if world < 100:
        raise ScenarioError("world_size", "must be an integer >= 100 (px)", got=world)

    fire = top.table("fire", _FIRE_KEYS)
    regions = []
    for t in fire.tables("regions", _REGION_KEYS):
        center, cell = _place(t, "region", world)
        params = {}
        for key in _REGION_PARAMS:
            kind = "int" if key == "fronts" else "number"
            source_table = t if t.has(key) else fire
            params[key] = source_table.get(key, kind, REGION_DEFAULTS[key])
        regions.append(FireRegion(center, cell=cell, **params))

    scoring_t = top.table("scoring", _SCORING_KEYS)
    scoring = Scoring(
        scoring_t.get("propagation_weight", "number", 0.1),
        scoring_t.get("temporal_exponent", "number", 1.25),
    )
    penalties_t = scoring_t.table("penalties", _PENALTY_KEYS)
    penalties = {k: penalties_t.get(k, "number", v) for k, v in DEFAULT_PENALTIES.items()}
    for kind, value in penalties.items():
        if not (math.isfinite(value) and value >= 0):
            raise ScenarioError(penalties_t.field(kind), "must be a number >= 0", got=value)

    if not top.has("depot"):
        raise ScenarioError("depot", "is required (a table with cell or center, and orientation)")
    depot_t = top.table("depot", _DEPOT_KEYS)
    orientation = depot_t.get("orientation", "str", "vertical")
    if orientation not in ("vertical", "horizontal"):
        raise ScenarioError(
            "depot.orientation", "must be one of 'vertical', 'horizontal'", got=orientation
        )
    center, cell = _place(depot_t, f"depot_{orientation}", world)
    depot = Depot(center, orientation, penalties["depot"], cell)

    facilities = []
    for t in top.tables("facilities", _FACILITY_KEYS):
        kind = t.get("kind", "str")
        if kind not in FACILITY_KINDS:
            raise ScenarioError(
                t.field("kind"),
                "must be one of 'house', 'hospital', 'power_station' (the depot goes in [depot])",
                got=kind,
            )
        center, cell = _place(t, kind, world)
        size = t.get("size", "pair", FACILITY_SIZES[kind])
        facilities.append(
            Facility(kind, center, size, t.get("penalty", "number", penalties[kind]), cell)
        )

    lakes = [Lake(*_place(t, "lake", world)) for t in top.tables("lakes", _LAKE_KEYS)]

    return dict(
        name=name,
        number=number,
        difficulty=top.get("difficulty", "str", "custom"),
        world_size=world,
        duration_s=top.get("duration_s", "number", 180.0),
        ticks_per_second=top.get("ticks_per_second", "int", 10),
        fire_mode=fire.get("mode", "str", "specific"),
        regions=tuple(regions),
        depot=depot,
        facilities=tuple(facilities),
        lakes=tuple(lakes),
        agents=_team(top, depot),
        scoring=scoring,
        action_gate=fire.get("action_gate", "str", "sensed"),
        wind_model=fire.get("wind_model", "str", DEFAULT_WIND_MODEL),
        comm_range=top.get("comm_range", "number", None),
        notes=top.get("notes", "strings", ()),
    )


def _team(top: _Table, depot: Depot) -> tuple[AgentSpec, ...]:
    team = top.table("team", tuple(r.key for r in Role))
    columns: list[tuple[Role, int, _Table]] = []
    for role in Role:
        if team.has(role.key):
            t = team.table(role.key, _ROLE_KEYS[role])
            count = t.get("count", "int")
            if count < 0:
                raise ScenarioError(t.field("count"), "must be an integer >= 0", got=count)
            columns.append((role, count, t))
    slots = depot.slots(sum(count for _, count, _ in columns))
    agents: list[AgentSpec] = []
    for role, count, t in columns:
        fixed = (ACTION_ALTITUDE, ACTION_ALTITUDE)
        altitude = (
            t.per_agent("altitude", "pair", count, TEAM_DEFAULTS["altitude"])
            if role.can_sense
            else [fixed] * count
        )
        default_z = [
            ACTION_ALTITUDE if role is Role.ACTION else min(max(20.0, lo), hi)
            for lo, hi in altitude
        ]
        start_z = (
            t.per_agent("start_altitude", "number", count, None) if role.can_sense else default_z
        )
        first = len(agents)
        starts = t.per_agent("start", "pair", count, None, shared=False)
        starts = [slots[first + k] if p is None else p for k, p in enumerate(starts)]
        battery = t.per_agent("battery", "number", count, TEAM_DEFAULTS["battery"])
        speed = t.per_agent("speed", "number", count, TEAM_DEFAULTS["speed"])
        if role.can_act:
            tank = t.per_agent("tank", "int", count, TEAM_DEFAULTS["tank"])
            prune = t.per_agent(
                "prune_confidence", "number", count, TEAM_DEFAULTS["prune_confidence"][role]
            )
        else:
            tank, prune = [0] * count, [0.0] * count
        for k in range(count):
            z = default_z[k] if start_z[k] is None else start_z[k]
            agents.append(
                AgentSpec(
                    id=f"{role.letter}{k + 1}",
                    role=role,
                    start=starts[k],
                    altitude=altitude[k],
                    start_altitude=z,
                    battery=battery[k],
                    speed=speed[k],
                    tank=tank[k],
                    prune_confidence=prune[k],
                )
            )
    return tuple(agents)


# -------------------------------------------------------------------------------------- writing
def _place_dict(obj: Any) -> dict[str, Any]:
    return {"cell": obj.cell} if obj.cell is not None else {"center": list(obj.center)}


def _one_or_list(values: list[Any]) -> Any:
    """A single value when every agent has the same, else the per-agent list."""
    values = [list(v) if isinstance(v, tuple) else v for v in values]
    return values[0] if all(v == values[0] for v in values) else values


def scenario_to_dict(s: Scenario) -> dict[str, Any]:
    """The TOML document of ``s``: what :func:`dump_scenario` writes.

    Values equal to the format's defaults are left out where that keeps the file short (ticks per
    second 10, one-cell ignition boxes, default penalties and sizes, depot-slot starts).
    """
    doc: dict[str, Any] = {"name": s.name}
    if s.number is not None:
        doc["number"] = s.number
    doc.update(difficulty=s.difficulty, world_size=s.world_size, duration_s=s.duration_s)
    if s.ticks_per_second != 10:
        doc["ticks_per_second"] = s.ticks_per_second
    if s.comm_range is not None:
        doc["comm_range"] = s.comm_range
    if s.notes:
        doc["notes"] = list(s.notes)

    fire: dict[str, Any] = {"mode": s.fire_mode}
    if s.action_gate != "sensed":
        fire["action_gate"] = s.action_gate
    fire["wind_model"] = s.wind_model  # (always: the default changed once, from "fresh")
    shared = _UNIFORM_PARAMS if s.fire_mode == "uniform" else ()
    fire.update({key: getattr(s.regions[0], key) for key in shared})
    regions = []
    for r in s.regions:
        entry = _place_dict(r)
        entry.update({key: getattr(r, key) for key in _UNIFORM_PARAMS if key not in shared})
        if r.half_width != REGION_DEFAULTS["half_width"]:
            entry["half_width"] = r.half_width
        regions.append(entry)
    fire["regions"] = regions
    doc["fire"] = fire

    scoring: dict[str, Any] = {
        "propagation_weight": s.scoring.propagation_weight,
        "temporal_exponent": s.scoring.temporal_exponent,
    }
    kind_penalty = dict(DEFAULT_PENALTIES)
    for kind in FACILITY_KINDS:
        values = {f.penalty for f in s.facilities if f.kind == kind}
        if len(values) == 1:
            kind_penalty[kind] = values.pop()
    kind_penalty["depot"] = s.depot.penalty
    penalties = {k: v for k, v in kind_penalty.items() if v != DEFAULT_PENALTIES[k]}
    if penalties:
        scoring["penalties"] = penalties
    doc["scoring"] = scoring

    doc["depot"] = {**_place_dict(s.depot), "orientation": s.depot.orientation}
    facilities = []
    for f in s.facilities:
        entry = {"kind": f.kind, **_place_dict(f)}
        if f.size != FACILITY_SIZES[f.kind]:
            entry["size"] = list(f.size)
        if f.penalty != kind_penalty[f.kind]:
            entry["penalty"] = f.penalty
        facilities.append(entry)
    if facilities:
        doc["facilities"] = facilities
    if s.lakes:
        doc["lakes"] = [_place_dict(lake) for lake in s.lakes]

    team: dict[str, Any] = {}
    slots = s.depot.slots(len(s.agents))
    for role in Role:
        members = [(n, a) for n, a in enumerate(s.agents) if a.role is role]
        if not members:
            continue
        agents = [a for _, a in members]
        entry = {"count": len(agents)}
        if role.can_sense:
            entry["altitude"] = _one_or_list([a.altitude for a in agents])
        entry["battery"] = _one_or_list([a.battery for a in agents])
        entry["speed"] = _one_or_list([a.speed for a in agents])
        if role.can_act:
            entry["tank"] = _one_or_list([a.tank for a in agents])
            entry["prune_confidence"] = _one_or_list([a.prune_confidence for a in agents])
        if any(a.start != slots[n] for n, a in members):
            entry["start"] = [list(a.start) for a in agents]
        default_z = [min(max(20.0, a.altitude[0]), a.altitude[1]) for a in agents]
        if role.can_sense and any(
            a.start_altitude != z for a, z in zip(agents, default_z, strict=True)
        ):
            entry["start_altitude"] = _one_or_list([a.start_altitude for a in agents])
        team[role.key] = entry
    doc["team"] = team
    return doc
