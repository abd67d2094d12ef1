"""The parts of a scenario: agent roles, fire regions, facilities, depot, lakes, agents, scoring.

These frozen records describe one piece of a FireCommander mission each; a
:class:`~fcplan.scenario.model.Scenario` holds them and validates them together, so that error
messages can name the full field path (``fire.regions[1].fuel``). Each record only normalises its
numbers (numpy scalars and lists become floats, ints and tuples); range checks are the scenario's.

The game's tables live here, defined once: facility kinds, footprint sizes and penalties, the
depot's sizes and agent slots, and the action agents' fixed altitude.

Units are those of the FireCommander GUI: 1 px = 1 map unit (1 m), x to the right, y downward,
times in simulated seconds. Agent ``speed`` is px per tick at 10 ticks per simulated second (the
manual's "velocity = step size" per frame) and ``battery`` is in the manual's capacity units (0.1
per px flown, 0.05 per hovering tick); the simulator rescales both when ``ticks_per_second`` is not
10.

Examples
--------
>>> Facility.standard("hospital", (700, 300)).footprint
(625.0, 775.0, 210.0, 390.0)
>>> Depot((100, 600), "vertical").as_facility().kind in FOOTPRINT_KINDS
True
>>> Role.HYBRID.letter, ACTION_ALTITUDE
('H', 30.0)
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

__all__ = [
    "Role",
    "FireRegion",
    "Facility",
    "Depot",
    "Lake",
    "AgentSpec",
    "Scoring",
    "FACILITY_KINDS",
    "FOOTPRINT_KINDS",
    "FACILITY_SIZES",
    "DEFAULT_PENALTIES",
    "DEPOT_SIZES",
    "DEPOT_SLOTS",
    "ACTION_ALTITUDE",
    "DIFFICULTIES",
    "FIRE_MODES",
    "ACTION_GATES",
    "WIND_MODELS",
    "DEFAULT_WIND_MODEL",
]

FACILITY_KINDS = ("house", "hospital", "power_station")
"""Kinds of :class:`Facility` in ``Scenario.facilities``, in the order they are listed."""

FOOTPRINT_KINDS = (*FACILITY_KINDS, "depot")
"""Kinds of every scored footprint (``Scenario.scored_facilities``): the facilities, then the
depot (:meth:`Depot.as_facility`)."""

FACILITY_SIZES: dict[str, tuple[float, float]] = {
    "house": (120.0, 150.0),
    "hospital": (150.0, 180.0),
    "power_station": (180.0, 220.0),
}
"""Scoring footprint (width, height) in px of each facility kind."""

DEFAULT_PENALTIES: dict[str, float] = {
    "house": 1.0,
    "hospital": 2.0,
    "power_station": 5.0,
    "depot": 5.0,
}
"""Penalty coefficient per burning cell inside each kind of footprint."""

DEPOT_SIZES: dict[str, tuple[float, float]] = {
    "vertical": (160.0, 400.0),
    "horizontal": (400.0, 160.0),
}
"""Depot footprint (width, height) in px per orientation."""

DEPOT_SLOTS: dict[str, tuple[tuple[float, float], ...]] = {
    "vertical": (
        (-40, -180), (-40, -120), (-40, -60), (-40, 0), (-40, 60), (-40, 120),
        (40, -180), (40, -120), (40, -60),
    ),
    "horizontal": (
        (-180, -40), (-100, -40), (-20, -40), (60, -40), (140, -40),
        (-180, 40), (-100, 40), (-20, 40), (60, 40),
    ),
}  # fmt: skip
"""The GUI's nine agent start slots, offsets from the depot centre (perception first, then action,
then hybrid)."""

ACTION_ALTITUDE = 30.0
"""Fixed flight altitude (m) of action agents."""

DIFFICULTIES = ("practice", "easy", "moderate", "hard", "custom")
FIRE_MODES = ("uniform", "specific")
ACTION_GATES = ("sensed", "reference")
WIND_MODELS = ("tables", "fresh")
"""Wind models of the fire (:mod:`fcplan.fire`): the original's per-episode sample tables, or
fresh draws every fire step."""
DEFAULT_WIND_MODEL = "tables"
"""Wind model of scenarios that do not name one (``[fire] wind_model``): the original's, so that
fcplan's fire is statistically the original's (:mod:`fcplan.fire`, "Wind"). It was ``"fresh"``
before recording format 2; documents written since always name their wind model."""


def _is_real(v: Any) -> bool:
    return isinstance(v, Real) and not isinstance(v, bool)


def _as_float(v: Any) -> Any:
    """``float(v)`` for a real number (numpy scalars included); anything else is left for the
    validator to report."""
    return float(v) if _is_real(v) else v


def _as_int(v: Any) -> Any:
    return int(v) if isinstance(v, Integral) and not isinstance(v, bool) else v


def _as_pair(v: Any) -> Any:
    if isinstance(v, (list, tuple)) or hasattr(v, "tolist"):
        v = v.tolist() if hasattr(v, "tolist") else v
        return tuple(_as_float(x) for x in v)
    return v


def _set(obj: Any, name: str, value: Any) -> None:
    object.__setattr__(obj, name, value)


class Role(enum.IntEnum):
    """Agent type. Perception agents sense fire, action agents put it out, hybrids do both.

    Examples
    --------
    >>> Role.HYBRID.letter, Role.HYBRID.can_sense, Role.HYBRID.can_act
    ('H', True, True)
    >>> Role.ACTION.key
    'action'
    """

    PERCEPTION = 0
    ACTION = 1
    HYBRID = 2

    @property
    def letter(self) -> str:
        """``"P"``, ``"A"`` or ``"H"``: the prefix of agent ids."""
        return "PAH"[self]

    @property
    def key(self) -> str:
        """Lower-case name, as in the TOML ``[team.<key>]`` sections."""
        return self.name.lower()

    @property
    def can_sense(self) -> bool:
        """True for perception and hybrid agents."""
        return self is not Role.ACTION

    @property
    def can_act(self) -> bool:
        """True for action and hybrid agents."""
        return self is not Role.PERCEPTION


@dataclass(frozen=True, slots=True)
class FireRegion:
    """An initial fire area.

    Parameters
    ----------
    center : tuple of float
        Centre (x, y) in px.
    fronts : int
        Number of initial firefronts, drawn in the ignition box.
    delay_s : float
        Simulated seconds before the region ignites (a delay past the end never fires).
    fuel : float
        Fuel (spread-rate) coefficient: the fuel field is drawn from U(0, fuel).
    wind_speed : float
        Mean wind speed (m/s).
    wind_dir_deg : float
        Mean wind direction, degrees; 0 pushes fronts toward +y (down), 90 toward +x.
    half_width : float
        Half side of the ignition box (50 px: one grid cell, as in the GUI).
    cell : str, optional
        Grid cell the region was placed on (``"D-05"``), if it was placed by cell.

    Examples
    --------
    >>> r = FireRegion((350, 450), fronts=5, delay_s=0, fuel=10, wind_speed=5, wind_dir_deg=45)
    >>> r.ignition_box
    (300.0, 400.0, 400.0, 500.0)
    """

    center: tuple[float, float]
    fronts: int
    delay_s: float
    fuel: float
    wind_speed: float
    wind_dir_deg: float
    half_width: float = 50.0
    cell: str | None = None

    def __post_init__(self) -> None:
        _set(self, "center", _as_pair(self.center))
        _set(self, "fronts", _as_int(self.fronts))
        for name in ("delay_s", "fuel", "wind_speed", "wind_dir_deg", "half_width"):
            _set(self, name, _as_float(getattr(self, name)))

    @property
    def ignition_box(self) -> tuple[float, float, float, float]:
        """Half-open box ``(x0, x1, y0, y1)`` = centre +- half_width. Initial fronts are drawn as
        integers uniformly in ``x0..x1-1`` and ``y0..y1-1``."""
        (x, y), h = self.center, self.half_width
        return (x - h, x + h, y - h, y + h)


def _footprint(
    center: tuple[float, float], size: tuple[float, float]
) -> tuple[float, float, float, float]:
    (x, y), (w, h) = center, size
    return (x - w / 2, x + w / 2, y - h / 2, y + h / 2)


@dataclass(frozen=True, slots=True)
class Facility:
    """A facility to protect. Burning cells inside its footprint cost ``penalty`` each.

    Parameters
    ----------
    kind : str
        ``"house"``, ``"hospital"``, ``"power_station"`` (or ``"depot"`` for
        :meth:`Depot.as_facility`).
    center : tuple of float
        Centre (x, y) in px.
    size : tuple of float
        Footprint (width, height) in px: house 120 x 150, hospital 150 x 180, power station
        180 x 220, depot 160 x 400 (vertical) or 400 x 160 (horizontal).
    penalty : float
        Penalty coefficient: house 1, hospital 2, power station 5, depot 5 by default.
    cell : str, optional
        Top-left cell of its 2 x 2 grid block, if it was placed by cell.

    Examples
    --------
    >>> f = Facility.standard("house", (800, 300))
    >>> f.size, f.penalty, f.footprint
    ((120.0, 150.0), 1.0, (740.0, 860.0, 225.0, 375.0))
    >>> f.contains(741, 300), f.contains(740, 300)
    (True, False)
    """

    kind: str
    center: tuple[float, float]
    size: tuple[float, float]
    penalty: float
    cell: str | None = None

    def __post_init__(self) -> None:
        _set(self, "center", _as_pair(self.center))
        _set(self, "size", _as_pair(self.size))
        _set(self, "penalty", _as_float(self.penalty))

    @classmethod
    def standard(
        cls,
        kind: str,
        center: tuple[float, float],
        *,
        cell: str | None = None,
        penalty: float | None = None,
    ) -> Facility:
        """A facility of ``kind`` with the game's footprint size and (unless given) penalty."""
        if kind not in FACILITY_SIZES:
            raise ValueError(f"kind must be one of {', '.join(FACILITY_KINDS)}, got {kind!r}")
        pen = DEFAULT_PENALTIES[kind] if penalty is None else penalty
        return cls(kind, center, FACILITY_SIZES[kind], pen, cell)

    @property
    def footprint(self) -> tuple[float, float, float, float]:
        """``(x0, x1, y0, y1)``: a cell (int x, int y) is inside iff ``x0 < x < x1`` and
        ``y0 < y < y1`` (strict)."""
        return _footprint(self.center, self.size)

    def contains(self, x: Any, y: Any) -> Any:
        """Whether the cell (x, y) is strictly inside the footprint. Works on numpy arrays too."""
        x0, x1, y0, y1 = self.footprint
        return (x0 < x) & (x < x1) & (y0 < y) & (y < y1)


@dataclass(frozen=True, slots=True)
class Depot:
    """The agent base: where agents start, recharge and refill. It is also scored as a facility.

    Examples
    --------
    >>> d = Depot((100, 600), "vertical")
    >>> d.size, d.footprint
    ((160.0, 400.0), (20.0, 180.0, 400.0, 800.0))
    >>> d.slots(3)
    ((60.0, 420.0), (60.0, 480.0), (60.0, 540.0))
    """

    center: tuple[float, float]
    orientation: str
    penalty: float = 5.0
    cell: str | None = None

    def __post_init__(self) -> None:
        _set(self, "center", _as_pair(self.center))
        _set(self, "penalty", _as_float(self.penalty))

    @property
    def size(self) -> tuple[float, float]:
        """``(160, 400)`` when vertical, ``(400, 160)`` when horizontal."""
        return DEPOT_SIZES.get(self.orientation, DEPOT_SIZES["vertical"])

    @property
    def footprint(self) -> tuple[float, float, float, float]:
        """``(x0, x1, y0, y1)``, strict bounds as for :attr:`Facility.footprint`."""
        return _footprint(self.center, self.size)

    def as_facility(self) -> Facility:
        """The depot as a scored :class:`Facility` of kind ``"depot"``."""
        return Facility("depot", self.center, self.size, self.penalty, self.cell)

    def slots(self, n: int) -> tuple[tuple[float, float], ...]:
        """Start positions of ``n`` agents (perception first, then action, then hybrid).

        The first nine are the GUI's slots (``DEPOT_SLOTS``). The ``m`` agents beyond the ninth sit
        on an evenly spaced lattice inside the footprint: it is cut into ``a`` columns across its
        short side and ``b`` rows along its long side, ``a = max(1, round(sqrt(m * short / long)))``
        and ``b = ceil(m / a)``, so that the boxes are about square; extra agent ``k`` (0-based)
        takes the centre of box ``(k % a, k // a)``, rounded to whole px (halves up). Lattice
        points may coincide with GUI slots: agents are points, so sharing a start is harmless.

        Examples
        --------
        >>> Depot((100, 600), "vertical").slots(12)[9:]
        ((100.0, 467.0), (100.0, 600.0), (100.0, 733.0))
        """
        (cx, cy) = self.center
        rel = DEPOT_SLOTS.get(self.orientation, DEPOT_SLOTS["vertical"])
        out = [(float(cx + dx), float(cy + dy)) for dx, dy in rel[: max(n, 0)]]
        extra = n - len(rel)
        if extra > 0:
            x0, x1, y0, y1 = self.footprint
            w, h = x1 - x0, y1 - y0
            short, long_ = min(w, h), max(w, h)
            across = max(1, round(math.sqrt(extra * short / long_)))
            along = math.ceil(extra / across)
            for k in range(extra):
                i, j = k % across, k // across
                a = (i + 0.5) * short / across
                b = (j + 0.5) * long_ / along
                dx, dy = (a, b) if w <= h else (b, a)
                out.append((float(math.floor(x0 + dx + 0.5)), float(math.floor(y0 + dy + 0.5))))
        return tuple(out)


@dataclass(frozen=True, slots=True)
class Lake:
    """A lake: decorative only (no effect on fire, agents or score).

    Drawn as three circles of radius 100 px at (x, y), (x + 80, y - 80) and (x + 20, y + 80).

    Examples
    --------
    >>> Lake((450, 1000)).circles
    ((450.0, 1000.0, 100.0), (530.0, 920.0, 100.0), (470.0, 1080.0, 100.0))
    """

    center: tuple[float, float]
    cell: str | None = None

    def __post_init__(self) -> None:
        _set(self, "center", _as_pair(self.center))

    @property
    def circles(self) -> tuple[tuple[float, float, float], ...]:
        """The three ``(x, y, radius)`` circles that draw the lake."""
        x, y = self.center
        return ((x, y, 100.0), (x + 80, y - 80, 100.0), (x + 20, y + 80, 100.0))


@dataclass(frozen=True, slots=True)
class AgentSpec:
    """One UAV of the team, as it is at the start of a game.

    Parameters
    ----------
    id : str
        Role letter plus 1-based index within the role: ``"P1"``, ``"A2"``, ``"H1"``.
    role : Role
        What the agent can do.
    start : tuple of float
        Start position (x, y) in px: its depot slot.
    altitude : tuple of float
        Allowed altitude range (lo, hi) in m; action agents fly at a fixed ``(30, 30)``.
    start_altitude : float
        Altitude at the start: ``max(20, lo)`` (kept within ``hi``) for perception and hybrid
        agents, 30 for action agents.
    battery : float
        Battery capacity (0.1 per px flown, 0.05 per hovering tick at 10 ticks/s).
    speed : float
        Step length in px per tick at 10 ticks/s (the manual's "velocity").
    tank : int
        Water dumps per sortie; 0 for perception agents.
    prune_confidence : float
        Probability that a dump puts out each sensed burning cell in the field of view, in (0, 1];
        0.0 for perception agents.

    Examples
    --------
    >>> a = AgentSpec("A1", Role.ACTION, (60, 540), (30, 30), 30, 500, 20, 10, 0.9)
    >>> a.index, a.role.can_act
    (1, True)
    """

    id: str
    role: Role
    start: tuple[float, float]
    altitude: tuple[float, float]
    start_altitude: float
    battery: float
    speed: float
    tank: int
    prune_confidence: float

    def __post_init__(self) -> None:
        role = self.role
        if isinstance(role, Integral) and not isinstance(role, (bool, Role)) and 0 <= role <= 2:
            _set(self, "role", Role(int(role)))
        _set(self, "start", _as_pair(self.start))
        _set(self, "altitude", _as_pair(self.altitude))
        _set(self, "tank", _as_int(self.tank))
        for name in ("start_altitude", "battery", "speed", "prune_confidence"):
            _set(self, name, _as_float(getattr(self, name)))

    @property
    def index(self) -> int:
        """1-based index within its role (``"A2"`` -> 2)."""
        return int(self.id[1:])


@dataclass(frozen=True, slots=True)
class Scoring:
    """Score weights of the negative reward: ``propagation_weight`` per burning cell and the
    ``temporal_exponent`` on time (used by the reference-2020 metrics).

    Facility penalty coefficients live on each :class:`Facility` and the :class:`Depot`.
    """

    propagation_weight: float = 0.1
    temporal_exponent: float = 1.25

    def __post_init__(self) -> None:
        _set(self, "propagation_weight", _as_float(self.propagation_weight))
        _set(self, "temporal_exponent", _as_float(self.temporal_exponent))
