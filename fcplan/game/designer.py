"""The open-world designer: build a scenario step by step within the manual's GUI limits.

The FireCommander manual's open-world mode designs a scenario on four pages (general setting,
wildfire setting, facilities/targets, agents) and previews it before the game. :class:`Design`
holds such a design as plain values, one :class:`Field` per input box, each with the manual's limit
(tables "constraints and limitations on map elements and objects", "on wildfire model parameters",
"on wildfire propagation score", "on pruning confidence level", "on agent setting"):

==========================  ====================  ==========================================
field                       limit                 notes
==========================  ====================  ==========================================
world size                  800 / 1000 / 1200 px
duration                    60 / 120 / 180 s
fire regions                1..5                  placed on 100-px grid cells (``D-05``)
houses, hospitals,          0..5 each             2 x 2 cells (lake 3 x 4); no shared cells
power stations, lakes
agents P / A / H            0..9, at most 9       at least one agent senses, one acts
fronts per region           1..30                 at most 30 in total
fire delay                  0..180 s
fuel coefficient            2..20
wind speed, direction       2..10 m/s, 0..360 deg
temporal exponent           0..2
propagation weight          0..1
prune confidence            10..100 %             action 90 %, hybrid 80 % by default
altitude                    10..100 m             hybrid: lower 10..20 m, upper 20..100 m
battery, speed, tank        200..800, 10..30,
                            1..15
==========================  ====================  ==========================================

The fire uses the manual's *uniform* setting (one parameter set for every region) and the team its
*homogeneous* setting (one parameter set per role). A value outside its limit is refused by
:meth:`Design.set` with a one-line message naming the field and the limit; :meth:`Design.build`
checks the whole design (placement, overlaps) with :mod:`fcplan.scenario.validate` and returns the
scenario or the list of problems. Default cells are chosen automatically and kept apart.

Examples
--------
>>> d = Design()
>>> d.set("fronts", "40")
'fronts per region: 40 is outside the manual limit 1..30'
>>> d.set("fronts", "12") is None
True
>>> scenario, errors = d.build()
>>> errors, scenario.regions[0].fronts, scenario.difficulty
([], 12, 'custom')
"""

from __future__ import annotations

import math
from collections.abc import Set as AbstractSet
from dataclasses import dataclass
from typing import Any

from fcplan.errors import FcplanError
from fcplan.scenario.grid import GRID_BLOCKS, format_cell, parse_cell

__all__ = ["Design", "Field", "PAGES"]

PAGES = ("general", "fire", "sites", "team")
"""The designer's pages, in order (then the preview)."""

_KINDS = {
    "house": "houses",
    "hospital": "hospitals",
    "power_station": "power_stations",
    "lake": "lakes",
}
_ROLES = ("perception", "action", "hybrid")


@dataclass(frozen=True)
class Field:
    """One input box of the designer.

    Attributes
    ----------
    key : str
        Name used by :meth:`Design.set` (``"fronts"``, ``"house.0.cell"``, ``"action.tank"``).
    label : str
        Text shown to the player.
    kind : str
        ``"int"``, ``"float"``, ``"choice"`` or ``"cell"``.
    lo, hi : float
        Limits of a number (inclusive).
    step : float
        Change per ``-``/``+`` press.
    choices : tuple
        Allowed values of a ``"choice"`` field.
    unit : str
    """

    key: str
    label: str
    kind: str
    lo: float = 0.0
    hi: float = 0.0
    step: float = 1.0
    choices: tuple = ()
    unit: str = ""

    def limit_text(self) -> str:
        """The allowed values, as the manual states them."""
        if self.kind == "choice":
            return " / ".join(str(c) for c in self.choices)
        if self.kind == "cell":
            return "a grid cell such as D-05"
        return f"{self.lo:g}..{self.hi:g}{(' ' + self.unit) if self.unit else ''}"


def _general_fields() -> list[Field]:
    return [
        Field("world_size", "world size", "choice", choices=(800, 1000, 1200), unit="px"),
        Field("duration_s", "duration", "choice", choices=(60, 120, 180), unit="s"),
        Field("regions", "fire regions", "int", 1, 5),
        Field("houses", "houses", "int", 0, 5),
        Field("hospitals", "hospitals", "int", 0, 5),
        Field("power_stations", "power stations", "int", 0, 5),
        Field("lakes", "lakes", "int", 0, 5),
        Field("perception", "perception agents", "int", 0, 9),
        Field("action", "action agents", "int", 0, 9),
        Field("hybrid", "hybrid agents", "int", 0, 9),
    ]


def _fire_fields(n_regions: int) -> list[Field]:
    out = [
        Field("fronts", "fronts per region", "int", 1, 30),
        Field("delay_s", "fire delay", "float", 0, 180, 10, unit="s"),
        Field("fuel", "fuel coefficient", "float", 2, 20),
        Field("wind_speed", "wind speed", "float", 2, 10, unit="m/s"),
        Field("wind_dir_deg", "wind direction", "float", 0, 360, 15, unit="deg"),
        Field("temporal_exponent", "temporal penalty coefficient", "float", 0, 2, 0.25),
        Field("propagation_weight", "fire propagation weight", "float", 0, 1, 0.05),
    ]
    out += [
        Field(f"region.{i}.cell", f"fire region {i + 1} cell", "cell") for i in range(n_regions)
    ]
    return out


def _team_fields(counts: dict[str, int]) -> list[Field]:
    out = []
    for role in _ROLES:
        if not counts[role]:
            continue
        r = role[0].upper()
        if role == "perception":
            out += [
                Field(f"{role}.alt_lo", f"{r} lowest altitude", "float", 10, 100, 5, unit="m"),
                Field(f"{role}.alt_hi", f"{r} highest altitude", "float", 10, 100, 5, unit="m"),
            ]
        elif role == "hybrid":
            out += [
                Field(f"{role}.alt_lo", f"{r} lowest altitude", "float", 10, 20, 5, unit="m"),
                Field(f"{role}.alt_hi", f"{r} highest altitude", "float", 20, 100, 5, unit="m"),
            ]
        out += [
            Field(f"{role}.battery", f"{r} battery", "float", 200, 800, 50),
            Field(f"{role}.speed", f"{r} velocity", "float", 10, 30, 1),
        ]
        if role != "perception":
            out += [
                Field(f"{role}.tank", f"{r} water tank", "int", 1, 15),
                Field(f"{role}.prune_confidence", f"{r} pruning confidence", "float", 10, 100, 5,
                      unit="%"),
            ]  # fmt: skip
    return out


class Design:
    """A scenario being designed in the open-world mode (see the module docstring).

    Attributes
    ----------
    values : dict of str to value
        Current value of every field.
    page : str
        The page shown (one of :data:`PAGES`).
    """

    def __init__(self) -> None:
        self.values: dict[str, Any] = {
            "name": "open-world design",
            "world_size": 1200,
            "duration_s": 180,
            "regions": 1,
            "houses": 2,
            "hospitals": 1,
            "power_stations": 1,
            "lakes": 1,
            "perception": 2,
            "action": 2,
            "hybrid": 0,
            "fronts": 10,
            "delay_s": 0.0,
            "fuel": 10.0,
            "wind_speed": 5.0,
            "wind_dir_deg": 45.0,
            "temporal_exponent": 1.25,
            "propagation_weight": 0.1,
            "depot.orientation": "vertical",
        }
        for role in _ROLES:
            self.values[f"{role}.battery"] = 500.0
            self.values[f"{role}.speed"] = 20.0
        self.values.update({"perception.alt_lo": 10.0, "perception.alt_hi": 100.0})
        self.values.update({"hybrid.alt_lo": 10.0, "hybrid.alt_hi": 100.0})
        for role, conf in (("action", 90.0), ("hybrid", 80.0)):
            self.values[f"{role}.tank"] = 10
            self.values[f"{role}.prune_confidence"] = conf
        self.page = PAGES[0]
        self._place_defaults()

    # ------------------------------------------------------------------ fields
    def counts(self) -> dict[str, int]:
        """Agents per role."""
        return {r: int(self.values[r]) for r in _ROLES}

    def fields(self, page: str | None = None) -> list[Field]:
        """The input boxes of ``page`` (default: the current page)."""
        page = page or self.page
        if page == "general":
            return _general_fields()
        if page == "fire":
            return _fire_fields(int(self.values["regions"]))
        if page == "team":
            return _team_fields(self.counts())
        if page == "sites":
            out = [
                Field("depot.cell", "agent base cell", "cell"),
                Field(
                    "depot.orientation", "agent base", "choice", choices=("vertical", "horizontal")
                ),
            ]
            for kind, count_key in _KINDS.items():
                for i in range(int(self.values[count_key])):
                    label = f"{kind.replace('_', ' ')} {i + 1} cell"
                    out.append(Field(f"{kind}.{i}.cell", label, "cell"))
            return out
        raise FcplanError(f"unknown designer page {page!r}; pages: {', '.join(PAGES)}")

    def field(self, key: str) -> Field:
        """The :class:`Field` named ``key`` on any page."""
        for page in PAGES:
            for f in self.fields(page):
                if f.key == key:
                    return f
        raise FcplanError(f"unknown design field {key!r}")

    def text(self, key: str) -> str:
        """The value of ``key`` as shown in its box."""
        v = self.values.get(key, "")
        return f"{v:g}" if isinstance(v, float) else str(v)

    # ------------------------------------------------------------------ edits
    def set(self, key: str, text: Any) -> str | None:
        """Set a field from typed text; return None, or a one-line message if it is refused."""
        f = self.field(key)
        raw = str(text).strip()
        try:
            value = self._parse(f, raw)
        except _RefusedError as exc:
            return str(exc)
        problem = self._cross_check(key, value)
        if problem:
            return problem
        self.values[key] = value
        if key in ("world_size", "regions", "depot.orientation") or key in _KINDS.values():
            self._place_defaults()
        return None

    def nudge(self, key: str, direction: int) -> str | None:
        """Press ``-`` (``direction=-1``) or ``+`` (``+1``) on a field; return a refusal or None."""
        f = self.field(key)
        v = self.values[key]
        if f.kind == "choice":
            k = (f.choices.index(v) + direction) % len(f.choices)
            return self.set(key, f.choices[k])
        if f.kind == "cell":
            col, row = parse_cell(v)
            return self.set(key, format_cell(max(col + direction, 0), row))
        return self.set(key, f"{v + direction * f.step:g}")

    def _parse(self, f: Field, raw: str) -> Any:
        if f.kind == "choice":
            for c in f.choices:
                if raw == str(c):
                    return c
            raise _RefusedError(f"{f.label}: {raw!r} is not allowed; choose {f.limit_text()}")
        if f.kind == "cell":
            return self._parse_cell(f, raw)
        try:
            v = float(raw)
        except ValueError:
            raise _RefusedError(f"{f.label}: {raw!r} is not a number ({f.limit_text()})") from None
        if not math.isfinite(v) or not f.lo <= v <= f.hi:
            raise _RefusedError(f"{f.label}: {raw} is outside the manual limit {f.limit_text()}")
        if f.kind == "int":
            if v != int(v):
                raise _RefusedError(f"{f.label}: {raw} is not a whole number ({f.limit_text()})")
            return int(v)
        return v

    def _parse_cell(self, f: Field, raw: str) -> str:
        n = int(self.values["world_size"]) // 100
        try:
            col, row = parse_cell(raw.upper(), int(self.values["world_size"]))
        except FcplanError:
            last = format_cell(n - 1, n)
            raise _RefusedError(
                f"{f.label}: {raw!r} is not a cell of the map (A-01..{last})"
            ) from None
        cols, rows = GRID_BLOCKS[self._grid_kind(f.key)]
        if col + cols > n or row - 1 + rows > n:
            raise _RefusedError(
                f"{f.label}: a {cols}x{rows}-cell block at {raw.upper()} does not fit on the "
                f"{n}x{n} map"
            )
        return format_cell(col, row)

    def _cross_check(self, key: str, value: Any) -> str | None:
        trial = {**self.values, key: value}
        if key in _ROLES:
            c = {r: int(trial[r]) for r in _ROLES}
            total = sum(c.values())
            if total > 9:
                return f"team: {total} agents in total; the manual allows at most 9 (keys 1-9)"
            if not (c["perception"] + c["hybrid"]) or not (c["action"] + c["hybrid"]):
                return "team: at least one agent must sense (P or H) and one must act (A or H)"
        if key in ("fronts", "regions"):
            total = int(trial["fronts"]) * int(trial["regions"])
            if total > 30:
                return f"fire: {total} fronts in total; the manual allows at most 30"
        for role in ("perception", "hybrid"):
            if key.startswith(role + ".alt") and trial[f"{role}.alt_lo"] > trial[f"{role}.alt_hi"]:
                return f"{role} altitude: the lowest altitude must not exceed the highest"
        return None

    # ------------------------------------------------------------------ placement
    def _grid_kind(self, key: str) -> str:
        head = key.split(".")[0]
        if head == "region":
            return "region"
        if head == "depot":
            return f"depot_{self.values['depot.orientation']}"
        return head

    def _object_keys(self) -> list[str]:
        keys = ["depot.cell"]
        for kind, count_key in _KINDS.items():
            keys += [f"{kind}.{i}.cell" for i in range(int(self.values[count_key]))]
        return keys

    def _place_defaults(self) -> None:
        """Give every object a cell that fits the map and shares no cell with another object:
        keep the current cell where it still does, else take the first free block."""
        n = int(self.values["world_size"]) // 100
        taken: set[tuple[int, int]] = set()
        for key in self._object_keys():
            cols, rows = GRID_BLOCKS[self._grid_kind(key)]
            cell = self.values.get(key)
            if key == "depot.cell":
                vertical = self.values["depot.orientation"] == "vertical"
                default = format_cell(0, n // 2 - 1) if vertical else format_cell(n // 2 - 2, n - 1)
                cell = cell if cell and self._fits(cell, cols, rows, n, taken) else default
                if not self._fits(cell, cols, rows, n, taken):
                    cell = default
            elif not (cell and self._fits(cell, cols, rows, n, taken)):
                cell = self._first_free(cols, rows, n, taken)
            self.values[key] = cell
            if cell:
                c0, r0 = parse_cell(cell)
                taken |= {(c0 + i, r0 + j) for i in range(cols) for j in range(rows)}
        for i in range(int(self.values["regions"])):
            key = f"region.{i}.cell"
            cell = self.values.get(key)
            if not (cell and self._fits(cell, 1, 1, n, taken)):
                cell = self._first_free(1, 1, n, taken, start=(n // 2 - 1 + i, n // 2 - 1 - i))
            self.values[key] = cell

    @staticmethod
    def _fits(cell: str, cols: int, rows: int, n: int, taken: AbstractSet[tuple[int, int]]) -> bool:
        try:
            c0, r0 = parse_cell(cell)
        except FcplanError:
            return False
        block = {(c0 + i, r0 + j) for i in range(cols) for j in range(rows)}
        return c0 + cols <= n and r0 - 1 + rows <= n and not (block & taken)

    def _first_free(
        self,
        cols: int,
        rows: int,
        n: int,
        taken: AbstractSet[tuple[int, int]],
        start: tuple[int, int] = (0, 0),
    ) -> str | None:
        sc, sr = start
        order = sorted(
            ((c, r) for c in range(n) for r in range(1, n + 1)),
            key=lambda cr: (abs(cr[0] - sc) + abs(cr[1] - 1 - sr), -cr[0], cr[1]),
        )
        if start == (0, 0):  # facilities: fill from the right-hand side, away from the depot
            order = [(c, r) for c in range(n - 1, -1, -1) for r in range(1, n + 1)]
        for c, r in order:
            cell = format_cell(c, r)
            if self._fits(cell, cols, rows, n, taken):
                return cell
        return None

    # ------------------------------------------------------------------ result
    def to_dict(self) -> dict[str, Any]:
        """The design as a scenario TOML document (see :mod:`fcplan.scenario.io`)."""
        v = self.values
        doc: dict[str, Any] = {
            "name": v["name"],
            "difficulty": "custom",
            "world_size": int(v["world_size"]),
            "duration_s": float(v["duration_s"]),
            "fire": {
                "mode": "uniform",
                **{k: v[k] for k in ("fronts", "delay_s", "fuel", "wind_speed", "wind_dir_deg")},
                "regions": [{"cell": v[f"region.{i}.cell"]} for i in range(int(v["regions"]))],
            },
            "scoring": {
                "propagation_weight": v["propagation_weight"],
                "temporal_exponent": v["temporal_exponent"],
            },
            "depot": {"cell": v["depot.cell"], "orientation": v["depot.orientation"]},
            "facilities": [
                {"kind": kind, "cell": v[f"{kind}.{i}.cell"]}
                for kind, count_key in _KINDS.items()
                if kind != "lake"
                for i in range(int(v[count_key]))
            ],
            "lakes": [{"cell": v[f"lake.{i}.cell"]} for i in range(int(v["lakes"]))],
            "team": {},
        }
        for role in _ROLES:
            if not v[role]:
                continue
            t: dict[str, Any] = {
                "count": int(v[role]),
                "battery": v[f"{role}.battery"],
                "speed": v[f"{role}.speed"],
            }
            if role != "action":
                t["altitude"] = [v[f"{role}.alt_lo"], v[f"{role}.alt_hi"]]
            if role != "perception":
                t["tank"] = int(v[f"{role}.tank"])
                t["prune_confidence"] = v[f"{role}.prune_confidence"] / 100.0
            doc["team"][role] = t
        return doc

    def build(self) -> tuple[Any, list[str]]:
        """The designed scenario and the list of problems (empty when it can be played).

        Returns
        -------
        (Scenario or None, list of str)
            Problems are physical errors (:class:`fcplan.errors.ScenarioError`) or limits of the
            manual's GUI that the design exceeds; with any problem the scenario is None.
        """
        from fcplan.scenario import Scenario

        missing = [k for k in self._object_keys() if not self.values.get(k)]
        if missing:
            return None, [f"{k}: no free grid cell is left on the map for it" for k in missing]
        try:
            scenario = Scenario.from_dict(self.to_dict(), source="design")
        except FcplanError as exc:
            return None, [str(exc)]
        problems = scenario.manual_limit_violations()
        return (None, problems) if problems else (scenario, [])

    def place(self, key: str, x: float, y: float) -> str | None:
        """Put the object of cell field ``key`` so that its block starts at map point (x, y)."""
        return self.set(key, format_cell(int(x // 100), int(y // 100) + 1))


class _RefusedError(Exception):
    """A field value refused by the designer (the message is shown to the player)."""
