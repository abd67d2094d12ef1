"""Scenario validation: physical validity (errors) and the manual's GUI limits (a report).

Two different questions are asked of a scenario:

* **Is it physically valid?** (:func:`check_scenario`, run by every ``Scenario(...)``.) Numbers in
  their domain (fronts >= 1, fuel > 0, probabilities in (0, 1], ...), the centre of every object
  and every agent start inside the map, no two facility/depot footprints overlapping, no fire
  region starting inside a footprint, a team that can both sense and act, identical region
  parameters in uniform fire mode. A violation raises :class:`~fcplan.errors.ScenarioError` with a
  one-line message ``<file>: <dotted.field>: <problem and allowed range> (got <value>)``.

  Upper bounds (ranges, counts, ticks, the memory an episode needs) are checked next
  (:func:`fcplan.scenario.bounds.check_bounds`): a scenario that validates also runs.

  A footprint may overhang the map edge: power stations are 220 px tall on a 200 px grid block, so
  the game's own scenario #7 has one (C-11) whose footprint ends 10 px below the map. Cells outside
  the map do not exist, so only the part inside is ever scored.
* **Could the original GUI have built it?** (:func:`manual_limit_violations`.) The manual's
  open-world limits (world 800/1000/1200 px, at most 5 regions, at most 9 agents, fuel 2..20, ...)
  and its placement rules (objects on grid cells without sharing cells, depot on an edge). Exceeding
  them is allowed, e.g. for scaling studies; the function returns one human line per exceeded
  limit, and an empty list for all 25 shipped scenarios.

Field paths follow the TOML layout (``fire.regions[1].fuel``, ``facilities[0].cell``,
``team.action.tank``). An agent value that differs between agents of the same role is reported
with the agent's index within its role: ``team.perception.altitude[1]``.

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> s = load_scenario(3)
>>> s.replace(world_size=2000).manual_limit_violations()[0]
'world_size: 2000 (manual: 800, 1000 or 1200)'
>>> try:
...     s.replace(duration_s=0)
... except ScenarioError as e:
...     print(e.field, "|", e.problem)
duration_s | must be a number > 0 (simulated seconds)
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.errors import ScenarioError
from fcplan.scenario.bounds import check_bounds
from fcplan.scenario.fieldpaths import AgentPaths, agent_field, is_integer, is_number
from fcplan.scenario.fieldpaths import fmt_box as _fmt_box
from fcplan.scenario.fieldpaths import fmt_point as _fmt_point
from fcplan.scenario.fieldpaths import fmt_value as _fmt
from fcplan.scenario.grid import (
    GRID_BLOCKS,
    block_cell,
    block_cells,
    cell_center,
    column_letters,
    parse_cell,
)
from fcplan.scenario.parts import (
    ACTION_ALTITUDE,
    ACTION_GATES,
    DEFAULT_PENALTIES,
    DIFFICULTIES,
    FACILITY_KINDS,
    FACILITY_SIZES,
    FIRE_MODES,
    WIND_MODELS,
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    Scoring,
)

if TYPE_CHECKING:
    from fcplan.scenario.model import Scenario

__all__ = ["check_scenario", "manual_limit_violations", "is_number", "is_integer", "agent_field"]

UNIFORM_FIELDS = ("fronts", "delay_s", "fuel", "wind_speed", "wind_dir_deg")
"""Region parameters that uniform fire mode shares between all regions."""


def _finite(v: Any) -> bool:
    return is_number(v) and math.isfinite(v)


def _require(ok: bool, field: str, problem: str, got: Any) -> None:
    if not ok:
        raise ScenarioError(field, problem, got=got)


def _positive(field: str, v: Any, unit: str = "") -> None:
    _require(_finite(v) and v > 0, field, f"must be a number > 0{unit}", v)


def _non_negative(field: str, v: Any, unit: str = "") -> None:
    _require(_finite(v) and v >= 0, field, f"must be a number >= 0{unit}", v)


def _int_at_least(field: str, v: Any, lo: int, unit: str = "") -> None:
    _require(is_integer(v) and v >= lo, field, f"must be an integer >= {lo}{unit}", v)


def _choice(field: str, v: Any, choices: Iterable[str]) -> None:
    choices = tuple(choices)
    _require(v in choices, field, f"must be one of {', '.join(map(repr, choices))}", v)


def _point(field: str, v: Any, world: int) -> None:
    ok = isinstance(v, tuple) and len(v) == 2 and all(_finite(c) for c in v)
    _require(ok, field, "must be a pair of finite numbers [x, y] (px)", v)
    _require(
        all(0 <= c <= world for c in v),
        field,
        f"must lie inside the map [0, {world}] x [0, {world}]",
        _fmt_point(v),
    )


def _where(path: str, obj: Any) -> str:
    """``path.cell`` if the object was placed by cell, else ``path.center``."""
    return f"{path}.cell" if getattr(obj, "cell", None) is not None else f"{path}.center"


def _check_cell(path: str, obj: Any, kind: str, world: int) -> None:
    """A ``cell`` must be on the grid and agree with the centre."""
    if obj.cell is None:
        return
    parse_cell(obj.cell, world, field=f"{path}.cell")
    expected = cell_center(obj.cell, kind, world)
    _require(
        tuple(obj.center) == expected,
        f"{path}.center",
        f"must be the centre {_fmt_point(expected)} of its cell {obj.cell} ({kind})",
        _fmt_point(obj.center),
    )


def _first_overlap(boxes: np.ndarray, a: tuple[float, ...]) -> int | None:
    """Row of the first of ``boxes`` ((m, 4) ``[x0, x1, y0, y1]``) whose open interior meets
    box ``a``'s (a point if ``x0 == x1``, ``y0 == y1``), or None; one vectorised pass."""
    hit = (a[0] < boxes[:, 1]) & (boxes[:, 0] < a[1]) & (a[2] < boxes[:, 3]) & (boxes[:, 2] < a[3])
    return int(np.argmax(hit)) if hit.any() else None


# ------------------------------------------------------------------------------------------ errors
def check_scenario(s: Scenario) -> None:
    """Raise :class:`~fcplan.errors.ScenarioError` if ``s`` is not physically valid.

    The error's source is ``s.source`` (the file) or else ``s.name``.
    """
    source = (
        s.source if isinstance(s.source, str) else (s.name if isinstance(s.name, str) else None)
    )
    try:
        _check_header(s)
        _check_regions(s)
        _check_sites(s)
        paths = _check_agents(s)
        check_bounds(s, paths.of)
    except ScenarioError as err:
        raise (err.with_source(source) if source else err) from None


def _check_header(s: Scenario) -> None:
    _require(
        isinstance(s.name, str) and s.name.strip() != "",
        "name",
        "must be a non-empty string",
        s.name,
    )
    _require(
        s.number is None or (is_integer(s.number) and s.number >= 0),
        "number",
        "must be an integer >= 0 (0 practice, 1..24 scenarios) or absent",
        s.number,
    )
    _choice("difficulty", s.difficulty, DIFFICULTIES)
    _int_at_least("world_size", s.world_size, 100, " (px)")
    _positive("duration_s", s.duration_s, " (simulated seconds)")
    _int_at_least("ticks_per_second", s.ticks_per_second, 1)
    _choice("fire.mode", s.fire_mode, FIRE_MODES)
    _choice("fire.action_gate", s.action_gate, ACTION_GATES)
    _choice("fire.wind_model", s.wind_model, WIND_MODELS)
    if s.comm_range is not None:
        _positive("comm_range", s.comm_range, " (px), or absent for unlimited")
    _require(
        isinstance(s.notes, tuple) and all(isinstance(n, str) for n in s.notes),
        "notes",
        "must be a list of strings",
        s.notes,
    )
    _require(isinstance(s.scoring, Scoring), "scoring", "must be a Scoring", s.scoring)
    _non_negative("scoring.propagation_weight", s.scoring.propagation_weight)
    _non_negative("scoring.temporal_exponent", s.scoring.temporal_exponent)


def _check_regions(s: Scenario) -> None:
    regions = s.regions
    _require(
        isinstance(regions, tuple) and len(regions) >= 1,
        "fire.regions",
        "must list at least one fire region",
        regions,
    )
    for i, r in enumerate(regions):
        p = f"fire.regions[{i}]"
        _require(isinstance(r, FireRegion), p, "must be a FireRegion", r)
        _point(_where(p, r), r.center, s.world_size)
        _check_cell(p, r, "region", s.world_size)
        _int_at_least(f"{p}.fronts", r.fronts, 1)
        _non_negative(f"{p}.delay_s", r.delay_s, " (simulated seconds)")
        _positive(f"{p}.fuel", r.fuel)
        _non_negative(f"{p}.wind_speed", r.wind_speed, " (m/s)")
        _require(
            _finite(r.wind_dir_deg),
            f"{p}.wind_dir_deg",
            "must be a finite number (degrees)",
            r.wind_dir_deg,
        )
        _positive(f"{p}.half_width", r.half_width, " (px)")
    if s.fire_mode == "uniform":
        first = regions[0]
        for i, r in enumerate(regions[1:], start=1):
            for name in UNIFORM_FIELDS:
                mine, theirs = getattr(r, name), getattr(first, name)
                _require(
                    mine == theirs,
                    f"fire.regions[{i}].{name}",
                    f"must equal fire.regions[0].{name} ({_fmt(theirs)}) in uniform fire mode; "
                    'use mode = "specific" for per-region values',
                    mine,
                )


def _check_sites(s: Scenario) -> None:
    world = s.world_size
    depot = s.depot
    _require(isinstance(depot, Depot), "depot", "must be a Depot", depot)
    _choice("depot.orientation", depot.orientation, ("vertical", "horizontal"))
    _point(_where("depot", depot), depot.center, world)
    _check_cell("depot", depot, f"depot_{depot.orientation}", world)
    _non_negative("scoring.penalties.depot", depot.penalty)

    placed: list[tuple[str, str, tuple[float, float, float, float]]] = [
        ("the depot", "depot", depot.footprint)
    ]
    boxes = np.array([depot.footprint] * (len(s.facilities) + 1))  # of ``placed``, in order
    last_kind = 0
    for i, f in enumerate(s.facilities):
        p = f"facilities[{i}]"
        _require(isinstance(f, Facility), p, "must be a Facility", f)
        _require(
            f.kind in FACILITY_KINDS,
            f"{p}.kind",
            "must be one of 'house', 'hospital', 'power_station' (the depot goes in [depot])",
            f.kind,
        )
        order = FACILITY_KINDS.index(f.kind)
        _require(
            order >= last_kind,
            f"{p}.kind",
            "facilities must be listed houses first, then hospitals, then power stations",
            f.kind,
        )
        last_kind = order
        _point(_where(p, f), f.center, world)
        _check_cell(p, f, f.kind, world)
        ok = (
            isinstance(f.size, tuple)
            and len(f.size) == 2
            and all(_finite(v) and v > 0 for v in f.size)
        )
        _require(ok, f"{p}.size", "must be a pair of numbers > 0 [width, height] (px)", f.size)
        _require(
            _finite(f.penalty) and f.penalty >= 0,
            f"{p}.penalty",
            "must be a number >= 0",
            f.penalty,
        )
        hit = _first_overlap(boxes[: len(placed)], f.footprint)
        if hit is not None:
            other, other_path, box = placed[hit]
            _require(
                False,
                _where(p, f),
                f"footprint {_fmt_box(f.footprint)} overlaps {other} "
                f"({other_path}: {_fmt_box(box)}); facility and depot footprints may not overlap",
                _fmt_point(f.center),
            )
        boxes[len(placed)] = f.footprint
        placed.append((f"{f.kind} {_fmt_point(f.center)}", p, f.footprint))

    for i, r in enumerate(s.regions):
        x, y = r.center
        hit = _first_overlap(boxes, (x, x, y, y))
        if hit is not None:
            other, other_path, (x0, x1, y0, y1) = placed[hit]
            _require(
                False,
                _where(f"fire.regions[{i}]", r),
                f"region centre lies inside the footprint of {other} ({other_path}: "
                f"{_fmt_box((x0, x1, y0, y1))}); "
                "fires may not start inside a facility or the depot",
                _fmt_point(r.center),
            )

    for i, lake in enumerate(s.lakes):
        p = f"lakes[{i}]"
        _require(isinstance(lake, Lake), p, "must be a Lake", lake)
        _point(_where(p, lake), lake.center, world)
        _check_cell(p, lake, "lake", world)


def _check_agents(s: Scenario) -> AgentPaths:
    """Check every agent (linear in the team size); return the team's field paths."""
    world = s.world_size
    agents = list(s.agents)
    paths = AgentPaths(agents)
    last_role = Role.PERCEPTION
    seen = dict.fromkeys(Role, 0)
    for n, a in enumerate(agents):
        _require(isinstance(a, AgentSpec), f"agents[{n}]", "must be an AgentSpec", a)
        _require(isinstance(a.role, Role), f"agents[{n}].role", "must be a Role", a.role)
        _require(
            a.role >= last_role,
            f"agents[{n}].role",
            "agents must be listed perception first, then action, then hybrid",
            a.role.key,
        )
        last_role = a.role
        k = seen[a.role]
        seen[a.role] += 1
        expected_id = f"{a.role.letter}{k + 1}"
        _require(
            a.id == expected_id,
            f"agents[{n}].id",
            f"must be {expected_id!r} (role letter + index)",
            a.id,
        )

        def path(name: str, n: int = n) -> str:
            return paths.of(n, name)

        _point(path("start"), a.start, world)
        alt = a.altitude
        ok = isinstance(alt, tuple) and len(alt) == 2 and all(_finite(v) for v in alt)
        _require(
            ok and 0 < alt[0] <= alt[1],
            path("altitude"),
            "must be [lo, hi] with 0 < lo <= hi (m)",
            alt,
        )
        _require(
            _finite(a.start_altitude) and alt[0] <= a.start_altitude <= alt[1],
            path("start_altitude"),
            f"must be within the altitude range [{_fmt(alt[0])}, {_fmt(alt[1])}] (m)",
            a.start_altitude,
        )
        _positive(path("battery"), a.battery)
        _positive(path("speed"), a.speed, " (px per tick at 10 ticks/s)")
        if a.role is Role.ACTION:
            fixed = (ACTION_ALTITUDE, ACTION_ALTITUDE)
            _require(
                alt == fixed, path("altitude"), "action agents fly at a fixed [30, 30] (m)", alt
            )
        if a.role.can_act:
            _int_at_least(path("tank"), a.tank, 1, " (dumps)")
            _require(
                _finite(a.prune_confidence) and 0 < a.prune_confidence <= 1,
                path("prune_confidence"),
                "must be a probability in (0, 1] (the manual's 10..100 %)",
                a.prune_confidence,
            )
        else:
            _require(a.tank == 0, path("tank"), "must be 0 for perception agents", a.tank)
            _require(
                a.prune_confidence == 0,
                path("prune_confidence"),
                "must be 0 for perception agents",
                a.prune_confidence,
            )
    counts = {role.key: seen[role] for role in Role}
    _require(
        any(a.role.can_sense for a in agents) and any(a.role.can_act for a in agents),
        "team",
        "needs at least one agent that can sense (perception or hybrid) "
        "and one that can act (action or hybrid)",
        counts,
    )
    return paths


# ----------------------------------------------------------------------------------- manual limits
class _Report:
    """Collects manual-limit lines; a homogeneous team value gives one line, not one per agent."""

    def __init__(self) -> None:
        self.lines: dict[str, None] = {}

    def limit(self, ok: bool, field: str, got: str, allowed: str) -> None:
        if not ok:
            self.lines[f"{field}: {got} (manual: {allowed})"] = None

    def within(self, field: str, v: float, lo: float, hi: float, unit: str = "") -> None:
        self.limit(lo <= v <= hi, field, _fmt(v), f"{_fmt(lo)}..{_fmt(hi)}{unit}")


def manual_limit_violations(s: Scenario) -> list[str]:
    """One line per limit of the manual's open-world GUI that ``s`` exceeds.

    Limits (manual tables "constraints and limitations on map elements", "on wildfire model
    parameters", "on wildfire propagation score", "on pruning confidence level", "on agent setting",
    and the placement rules of the open-world pages; where the manual's table is garbled the
    reference GUI's rule is used):

    * world size 800, 1000 or 1200 px; duration 60, 120 or 180 s;
    * 1..5 fire regions; 0..5 houses, hospitals, power stations and lakes each; at most 9 agents;
    * 1..30 fronts per region and at most 30 in total (the GUI's rule); delay 0..180 s;
      fuel 2..20; wind speed 2..10 m/s; wind direction 0..360 degrees; ignition box of one cell;
    * temporal exponent 0..2; propagation weight 0..1; the fixed facility penalties
      (1, 2, 5, depot 5) and footprint sizes;
    * prune confidence 10..100 %; perception altitude within 10..100 m; hybrid lower bound
      10..20 m and upper bound 20..100 m; battery 200..800; speed 10..30; tank 1..15;
      agents start in their depot slots at the GUI's start altitude;
    * every object placed on grid cells, its block inside the map and sharing no cell with another
      object (fire regions may share cells with each other); a vertical depot in column A or the
      second-to-last column, a horizontal depot in row 1 or the second-to-last row.

    ``ticks_per_second``, ``comm_range`` and ``action_gate`` are fcplan settings, not manual limits.

    Examples
    --------
    >>> from fcplan.scenario import load_scenario
    >>> load_scenario(24).manual_limit_violations()
    []
    """
    rep = _Report()
    rep.limit(
        s.world_size in (800, 1000, 1200), "world_size", str(s.world_size), "800, 1000 or 1200"
    )
    rep.limit(s.duration_s in (60, 120, 180), "duration_s", _fmt(s.duration_s), "60, 120 or 180")
    rep.limit(1 <= len(s.regions) <= 5, "fire.regions", f"{len(s.regions)} regions", "1..5")
    for kind in FACILITY_KINDS:
        n = sum(f.kind == kind for f in s.facilities)
        rep.limit(n <= 5, "facilities", f"{n} {kind.replace('_', ' ')}s", "0..5 of each kind")
    rep.limit(len(s.lakes) <= 5, "lakes", f"{len(s.lakes)} lakes", "0..5")
    rep.limit(len(s.agents) <= 9, "team", f"{len(s.agents)} agents in total", "at most 9")

    total = sum(r.fronts for r in s.regions)
    rep.limit(
        total <= 30, "fire.regions", f"{total} fronts in total", "at most 30 over all regions"
    )
    for i, r in enumerate(s.regions):
        p = f"fire.regions[{i}]"
        rep.within(f"{p}.fronts", r.fronts, 1, 30)
        rep.within(f"{p}.delay_s", r.delay_s, 0, 180, " s")
        rep.within(f"{p}.fuel", r.fuel, 2, 20)
        rep.within(f"{p}.wind_speed", r.wind_speed, 2, 10, " m/s")
        rep.within(f"{p}.wind_dir_deg", r.wind_dir_deg, 0, 360, " degrees")
        rep.limit(r.half_width == 50, f"{p}.half_width", _fmt(r.half_width), "50 px, one grid cell")

    rep.within("scoring.temporal_exponent", s.scoring.temporal_exponent, 0, 2)
    rep.within("scoring.propagation_weight", s.scoring.propagation_weight, 0, 1)
    for f in s.scored_facilities:
        default = DEFAULT_PENALTIES[f.kind]
        rep.limit(
            f.penalty == default,
            f"scoring.penalties.{f.kind}",
            _fmt(f.penalty),
            f"fixed at {_fmt(default)}",
        )
    for i, f in enumerate(s.facilities):
        w, h = FACILITY_SIZES[f.kind]
        size = f"{_fmt(f.size[0])} x {_fmt(f.size[1])}"
        rep.limit(
            f.size == (w, h), f"facilities[{i}].size", size, f"{_fmt(w)} x {_fmt(h)} for a {f.kind}"
        )

    _agent_limits(s, rep)
    _placement_limits(s, rep)
    return list(rep.lines)


def _agent_limits(s: Scenario, rep: _Report) -> None:
    agents = list(s.agents)
    slots = s.depot.slots(len(agents))
    paths = AgentPaths(agents)
    for n, a in enumerate(agents):
        k = paths.index[n]

        def path(name: str, n: int = n) -> str:
            return paths.of(n, name)

        lo, hi = a.altitude
        alt = f"[{_fmt(lo)}, {_fmt(hi)}]"
        if a.role is Role.PERCEPTION:
            rep.limit(lo >= 10 and hi <= 100, path("altitude"), alt, "within 10..100 m")
        elif a.role is Role.HYBRID:
            ok = 10 <= lo <= 20 and 20 <= hi <= 100
            rep.limit(ok, path("altitude"), alt, "lower bound 10..20 m, upper bound 20..100 m")
        rep.within(path("battery"), a.battery, 200, 800)
        rep.within(path("speed"), a.speed, 10, 30)
        if a.role.can_act:
            rep.within(path("tank"), a.tank, 1, 15)
            ok = 0.1 <= a.prune_confidence <= 1
            rep.limit(
                ok, path("prune_confidence"), _fmt(a.prune_confidence), "0.1..1, i.e. 10..100 %"
            )
        if n < 9:
            where = f"team.{a.role.key}.start[{k}]"
            slot = f"agents start in their depot slot {_fmt_point(slots[n])}"
            rep.limit(tuple(a.start) == slots[n], where, _fmt_point(a.start), slot)
        z = ACTION_ALTITUDE if a.role is Role.ACTION else max(20.0, lo)
        rep.limit(
            a.start_altitude == z,
            path("start_altitude"),
            _fmt(a.start_altitude),
            f"the game starts at {_fmt(z)} m",
        )


def _placement_limits(s: Scenario, rep: _Report) -> None:
    n = s.grid_size
    objects: list[tuple[str, str, Any]] = []  # (field, grid kind, object)
    objects += [(f"fire.regions[{i}]", "region", r) for i, r in enumerate(s.regions)]
    objects.append(("depot", f"depot_{s.depot.orientation}", s.depot))
    objects += [(f"facilities[{i}]", f.kind, f) for i, f in enumerate(s.facilities)]
    objects += [(f"lakes[{i}]", "lake", lake) for i, lake in enumerate(s.lakes)]

    placed: list[tuple[str, str, str]] = []  # (field, grid kind, cell) in placement order
    # grid cell -> rows of ``placed`` on it (regions may share cells: they see only not_region)
    anyone: dict[tuple[int, int], list[int]] = {}
    not_region: dict[tuple[int, int], list[int]] = {}
    for field, kind, obj in objects:
        cell = block_cell(obj.center, kind)
        if cell is None:
            rep.limit(
                False,
                field,
                f"centre {_fmt_point(obj.center)} is off the grid",
                "objects are placed on grid cells",
            )
            continue
        cells = block_cells(cell, kind)
        cols, rows = GRID_BLOCKS[kind]
        inside = all(c < n and r <= n for c, r in cells)
        rep.limit(
            inside,
            field,
            f"its {cols}x{rows} block at {cell} extends past the {n}x{n} grid",
            "objects fit inside the map",
        )
        occupant = not_region if kind == "region" else anyone
        for j in sorted({j for c in cells for j in occupant.get(c, ())}):
            other_field, _, other_cell = placed[j]
            got = f"its block at {cell} shares grid cells with {other_field} ({other_cell})"
            rep.limit(False, field, got, "objects may not overlap on the grid, except fire regions")
        for c in cells:
            anyone.setdefault(c, []).append(len(placed))
            if kind != "region":
                not_region.setdefault(c, []).append(len(placed))
        placed.append((field, kind, cell))

    cell = block_cell(s.depot.center, f"depot_{s.depot.orientation}")
    if cell is not None:
        column, row = parse_cell(cell)
        if s.depot.orientation == "vertical":
            edge = (
                f"top-left cell in column A or {column_letters(n - 2)}, on the left or right edge"
            )
            rep.limit(column in (0, n - 2), "depot", f"vertical depot at {cell}", edge)
        else:
            edge = f"top-left cell in row 1 or {n - 1}, on the top or bottom edge"
            rep.limit(row in (1, n - 1), "depot", f"horizontal depot at {cell}", edge)
