"""Scenario data model: an immutable, validated description of a FireCommander mission.

A :class:`Scenario` says everything the simulator needs before the first tick: map size and game
length, the fire regions (where fires start, how many fronts, when, and with which fuel and wind),
the depot where the team starts, recharges and refills, the facilities to protect (houses,
hospitals, power stations), decorative lakes, the agents (perception, action, hybrid UAVs) and the
scoring weights. It knows nothing about what happens during a game.

The parts (:class:`Role`, :class:`FireRegion`, :class:`Facility`, :class:`Depot`, :class:`Lake`,
:class:`AgentSpec`, :class:`Scoring`) and the game's tables (``FACILITY_KINDS``,
``FOOTPRINT_KINDS``, ``ACTION_ALTITUDE``, ...) are defined in :mod:`fcplan.scenario.parts` and
exported here too; units are documented there.

Every dataclass is frozen. Constructing a :class:`Scenario` validates it (see
:mod:`fcplan.scenario.validate`): an invalid scenario cannot exist. The parts are plain records
checked as part of the scenario they belong to, so that error messages can name the full field
path (``fire.regions[1].fuel``). :meth:`Scenario.to_dict` and :meth:`Scenario.from_dict` convert
to and from the TOML document of :mod:`fcplan.scenario.document`.

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> s = load_scenario(12)
>>> s.name, s.difficulty, s.team_counts
('#12', 'moderate', {'perception': 3, 'action': 2, 'hybrid': 0})
>>> [r.cell for r in s.regions], s.regions[1].delay_s
(['D-08', 'K-11'], 60.0)
>>> s.depot.center, s.depot.footprint
((100.0, 600.0), (20.0, 180.0, 400.0, 800.0))
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from fcplan.errors import ScenarioError
from fcplan.scenario.document import scenario_fields, scenario_to_dict
from fcplan.scenario.parts import (
    ACTION_ALTITUDE,
    ACTION_GATES,
    DEFAULT_PENALTIES,
    DEFAULT_WIND_MODEL,
    DEPOT_SIZES,
    DEPOT_SLOTS,
    DIFFICULTIES,
    FACILITY_KINDS,
    FACILITY_SIZES,
    FIRE_MODES,
    FOOTPRINT_KINDS,
    WIND_MODELS,
    AgentSpec,
    Depot,
    Facility,
    FireRegion,
    Lake,
    Role,
    Scoring,
    _as_float,
    _as_int,
    _set,
)
from fcplan.scenario.validate import check_scenario, manual_limit_violations

__all__ = [
    "Role",
    "FireRegion",
    "Facility",
    "Depot",
    "Lake",
    "AgentSpec",
    "Scoring",
    "Scenario",
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


@dataclass(frozen=True)
class Scenario:
    """A complete, validated FireCommander mission.

    Constructing one validates it and raises :class:`~fcplan.errors.ScenarioError` (a one-line
    message naming the field and the allowed range) if it is physically invalid. Being outside the
    manual's GUI limits is allowed: see :meth:`manual_limit_violations`.

    Parameters
    ----------
    name : str
        ``"practice"``, ``"#1"``..``"#24"``, or the design's own name.
    number : int or None
        0 for practice, 1..24 for the pre-designed scenarios, None for open-world designs.
    difficulty : str
        ``"practice"``, ``"easy"``, ``"moderate"``, ``"hard"`` or ``"custom"``.
    world_size : int
        Side of the square map in px (the manual allows 800, 1000, 1200).
    duration_s : float
        Game length in simulated seconds.
    ticks_per_second : int
        Simulation ticks per simulated second (10 in every shipped scenario).
    fire_mode : str
        ``"uniform"`` (one parameter set for every region, which must then be identical) or
        ``"specific"`` (per-region parameters).
    regions : tuple of FireRegion
    depot : Depot
    facilities : tuple of Facility
        Houses, then hospitals, then power stations. The depot is not among them.
    lakes : tuple of Lake
    agents : tuple of AgentSpec
        Perception agents first, then action, then hybrid; ids ``P1.., A1.., H1..``.
    scoring : Scoring
    action_gate : str
        ``"sensed"``: a dump only puts out cells the team has sensed (the manual's rule);
        ``"reference"``: the 2020 code's looser gate.
    comm_range : float or None
        Communication range in px for decentralised schedulers; None means unlimited.
    source : str or None
        File the scenario was loaded from. Not part of equality.
    notes : tuple of str
        Free-text notes from the file (e.g. where the reference code differs from the manual).
    wind_model : str
        ``"fresh"``: every fire step draws each front's wind speed and direction afresh;
        ``"tables"``: each region draws two tables of ``world_size`` samples once per episode and
        every step picks entries from them, as the original does (see :mod:`fcplan.fire`).
        Default :data:`~fcplan.scenario.parts.DEFAULT_WIND_MODEL`.

    Examples
    --------
    >>> from fcplan.scenario import load_scenario
    >>> s = load_scenario("practice")
    >>> s.n_ticks, s.grid_size, s.agent_ids
    (1800, 12, ('P1', 'P2', 'A1', 'A2'))
    >>> [f.kind for f in s.scored_facilities]
    ['house', 'hospital', 'power_station', 'depot']
    >>> s.replace(duration_s=60).n_ticks
    600
    """

    name: str
    number: int | None
    difficulty: str
    world_size: int
    duration_s: float
    ticks_per_second: int
    fire_mode: str
    regions: tuple[FireRegion, ...]
    depot: Depot
    facilities: tuple[Facility, ...]
    lakes: tuple[Lake, ...]
    agents: tuple[AgentSpec, ...]
    scoring: Scoring
    action_gate: str = "sensed"
    comm_range: float | None = None
    source: str | None = field(default=None, compare=False)
    notes: tuple[str, ...] = ()
    wind_model: str = DEFAULT_WIND_MODEL

    def __post_init__(self) -> None:
        for name in ("regions", "facilities", "lakes", "agents", "notes"):
            value = getattr(self, name)
            if isinstance(value, list):
                _set(self, name, tuple(value))
        _set(self, "number", _as_int(self.number))
        _set(self, "world_size", _as_int(self.world_size))
        _set(self, "ticks_per_second", _as_int(self.ticks_per_second))
        _set(self, "duration_s", _as_float(self.duration_s))
        if self.comm_range is not None:
            _set(self, "comm_range", _as_float(self.comm_range))
        check_scenario(self)

    # ----------------------------------------------------------------------------- derived values
    @property
    def n_ticks(self) -> int:
        """Number of ticks in a game: ``round(duration_s * ticks_per_second)``."""
        return round(self.duration_s * self.ticks_per_second)

    @property
    def grid_size(self) -> int:
        """Cells per side of the 100-px grid: ``world_size // 100``."""
        return self.world_size // 100

    @property
    def scored_facilities(self) -> tuple[Facility, ...]:
        """Facilities whose footprints are scored: ``facilities`` then the depot (last)."""
        return (*self.facilities, self.depot.as_facility())

    @property
    def team_counts(self) -> dict[str, int]:
        """Agents per role: ``{"perception": n, "action": n, "hybrid": n}``."""
        counts = {role.key: 0 for role in Role}
        for agent in self.agents:
            counts[agent.role.key] += 1
        return counts

    @property
    def agent_ids(self) -> tuple[str, ...]:
        """Agent ids in team order, e.g. ``("P1", "P2", "A1")``."""
        return tuple(a.id for a in self.agents)

    # ------------------------------------------------------------------------------------ methods
    def replace(self, **changes: Any) -> Scenario:
        """A copy with ``changes`` applied (as :func:`dataclasses.replace`), validated again.

        Examples
        --------
        >>> from fcplan.scenario import load_scenario
        >>> load_scenario(1).replace(duration_s=60).n_ticks
        600
        """
        return dataclasses.replace(self, **changes)

    def manual_limit_violations(self) -> list[str]:
        """One line per limit of the manual's open-world GUI that this scenario exceeds.

        An empty list means the scenario could have been designed in the original game. See
        :func:`fcplan.scenario.validate.manual_limit_violations` for the list of limits.

        Examples
        --------
        >>> from fcplan.scenario import load_scenario
        >>> load_scenario(5).manual_limit_violations()
        []
        >>> load_scenario("scale_example").manual_limit_violations()[0]
        'world_size: 2000 (manual: 800, 1000 or 1200)'
        """
        return manual_limit_violations(self)

    def summary(self) -> str:
        """One line describing the scenario.

        Examples
        --------
        >>> from fcplan.scenario import load_scenario
        >>> load_scenario(12).summary()
        '#12  moderate  team 3P/2A  regions D-08(3f) K-11(10f, +60s)'
        """
        counts = self.team_counts
        team = "/".join(
            f"{counts[r.key]}{r.letter}" for r in Role if counts[r.key] or r is not Role.HYBRID
        )
        regions = []
        for r in self.regions:
            where = r.cell or f"({r.center[0]:g},{r.center[1]:g})"
            delay = f", +{r.delay_s:g}s" if r.delay_s else ""
            regions.append(f"{where}({r.fronts}f{delay})")
        text = f"{self.name}  {self.difficulty}  team {team}  regions {' '.join(regions)}"
        if self.world_size != 1200 or self.duration_s != 180:
            text += f"  {self.world_size}px {self.duration_s:g}s"
        return text

    def to_dict(self) -> dict[str, Any]:
        """The scenario as its TOML document (nested dicts, lists and scalars).

        Examples
        --------
        >>> from fcplan.scenario import load_scenario
        >>> d = load_scenario(12).to_dict()
        >>> d["fire"]["regions"][1]["cell"], d["team"]["action"]["count"]
        ('K-11', 2)
        """
        return scenario_to_dict(self)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], source: str | None = None) -> Scenario:
        """Build and validate a scenario from its TOML document (see :meth:`to_dict`).

        ``source`` (a file name) is used in error messages and stored in :attr:`source`; without
        it, errors name the document's ``name``.

        Raises
        ------
        ScenarioError
            On unknown keys, wrong types and invalid values.

        Examples
        --------
        >>> doc = {"name": "tiny", "world_size": 800, "fire": {"regions": [{"cell": "E-02"}]},
        ...        "depot": {"cell": "A-01"}, "team": {"perception": {"count": 1},
        ...        "action": {"count": 1}}}
        >>> s = Scenario.from_dict(doc)
        >>> s.regions[0].center, s.regions[0].fronts, s.agent_ids
        ((450.0, 150.0), 10, ('P1', 'A1'))
        """
        label = source or (
            d.get("name") if isinstance(d, Mapping) and isinstance(d.get("name"), str) else None
        )
        try:
            fields = scenario_fields(dict(d) if isinstance(d, Mapping) else d)
            return cls(**fields, source=source)
        except ScenarioError as err:
            raise (err.with_source(label) if label else err) from None
