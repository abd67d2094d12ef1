"""Seeded scenario generator: random FireCommander missions drawn from a recipe of knobs.

The manual's 24 scenarios are too easy to tell schedulers apart. This module draws new ones: a
:class:`GeneratorConfig` holds the knobs (map size, fire regions, facilities, team), and calling it
(or :func:`generate`) with a seed returns a validated :class:`~fcplan.scenario.model.Scenario`.
The same seed and knobs give an identical scenario in any process.

The model
---------
Every generated scenario follows the open-world GUI's placement rules, so one of manual size can be
built in the original game too:

* **Map.** The side is drawn in multiples of 100 px from ``world_size``. The depot (vertical or
  horizontal, ``depot_orientation``) sits on a random position along a map edge, as the GUI requires.
* **Fire regions** sit on grid cells at least ``min_depot_distance_px`` from the depot centre, on
  distinct cells while free ones remain. ``region_placement`` is ``"uniform"`` (any such cell),
  ``"clustered"`` (within ``cluster_radius_px`` of one of ``n_clusters`` random cluster cells) or
  ``"far"`` (far cells only). A cell is *far* when its centre lies at least ``far_fraction`` times the
  largest depot-to-cell distance of the map from the depot centre. The last ``late_share`` of the
  regions (nearest integer, halves up, and never all of them) are *late*: they lie on far cells,
  inside a cluster when one reaches that far, and ignite after a delay drawn from ``late_delay_s``.
  The others ignite at once. Fronts, fuel and wind are drawn per region (``fire_mode = "specific"``)
  or once for all of them (``"uniform"``).
* **Facilities** (houses, then hospitals, then power stations) take free 2 x 2 blocks whose centre
  lies ``facility_fire_distance_px = (lo, hi)`` from the nearest fire region centre, so the fire
  threatens them within the episode. They share no cell with the depot, a region or each other, and
  no footprint overlaps another. **Lakes** (decorative) take free 3 x 4 blocks.
* **Team.** Counts per role, then per agent a speed, battery, tank and prune confidence drawn from
  their ranges. Agents start in the depot's slots at the GUI's start altitude.

A layout that does not fit (no block left for a facility or lake) is drawn again from the same
stream, up to 20 times, before a :class:`~fcplan.errors.ScenarioError` names the knob to relax.
The draws come from four independent streams spawned from the seed (map, layout, fire parameters,
team), so changing only the team knobs keeps the map and its fire, and the other way round.

A generated scenario is named ``gen-<seed>-<hash>``, where ``<hash>`` is the first 8 hex digits of
the SHA-256 of the knob text, and its difficulty is ``"custom"``. Its only note records the exact
call, and :func:`recipe_of` reads that call back. So a scenario frozen to TOML can be regenerated:
``generate(**recipe_of(s)) == s``.

Examples
--------
>>> from fcplan.scenario.generate import GeneratorConfig, generate, recipe_of
>>> s = generate(7, world_size=1000, n_regions=3, duration_s=120)
>>> s.name.startswith("gen-7-"), s.world_size, len(s.regions), s.difficulty
(True, 1000, 3, 'custom')
>>> generate(**recipe_of(s)) == s
True
>>> hard = GeneratorConfig.hard()
>>> hard(3) == generate(3, hard)
True
>>> generate(1, world_size=850)
Traceback (most recent call last):
...
fcplan.errors.ScenarioError: generate: world_size: must be an integer or a pair [lo, hi] of integers, lo <= hi, in 800..10000, multiples of 100 (got 850)
"""

from __future__ import annotations

import ast
import dataclasses
import hashlib
import math
import re
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from fcplan.errors import ScenarioError
from fcplan.scenario.grid import CELL_PX, cell_center
from fcplan.scenario.knobs import check_knobs, knob, span
from fcplan.scenario.model import (
    ACTION_ALTITUDE,
    FACILITY_KINDS,
    FIRE_MODES,
    AgentSpec,
    Depot,
    FireRegion,
    Role,
    Scenario,
    Scoring,
)
from fcplan.scenario.placement import GridLayout, PlacementError, draw_depot
from fcplan.scenario.validate import is_integer

__all__ = ["GENERATOR_VERSION", "PLACEMENTS", "PRESETS", "GeneratorConfig", "generate", "recipe_of"]

GENERATOR_VERSION = 1
"""Version of the drawing procedure, recorded in each recipe; it changes whenever the same recipe
would draw a different scenario."""

PLACEMENTS = ("uniform", "clustered", "far")
"""Values of ``GeneratorConfig.region_placement``."""

IntRange = int | tuple[int, int]
FloatRange = float | tuple[float, float]

_SOURCE = "generate"
_ATTEMPTS = 20
_CALL = "fcplan.scenario.generate.generate"
_NOTE_RE = re.compile(r"^recipe \(generator v(\d+)\): (.*)$", re.DOTALL)


@dataclass(frozen=True)
class GeneratorConfig:
    """The knobs of the scenario generator; call it with a seed to draw a scenario.

    Every knob has a default and an allowed range, checked on construction (a bad value raises a
    one-line :class:`~fcplan.errors.ScenarioError` naming the knob, the value and the range). A
    *range* knob takes ``(lo, hi)`` and draws uniformly in it (integers inclusive). A single value
    means ``(v, v)``, and ranges are stored as tuples. Distances are px, times simulated seconds,
    speeds px per tick at 10 ticks/s and batteries the manual's units, as in
    :class:`~fcplan.scenario.model.AgentSpec`.

    =========================  ==========  =========================  ==============================
    knob                       default     allowed                    meaning
    =========================  ==========  =========================  ==============================
    world_size                 1200        800..10000 (x100)          map side, px (range)
    duration_s                 180         1..36000                   episode length, s
    ticks_per_second           10          1..100                     simulation rate, Hz
    n_regions                  (1, 4)      1..500                     fire regions (range)
    region_placement           'uniform'   uniform, clustered, far    where regions go
    n_clusters                 (1, 2)      1..100                     region clusters (range)
    cluster_radius_px          300         50..10000                  cluster radius, px
    min_depot_distance_px      300         0..10000                   min region-depot distance, px
    far_fraction               0.5         0..0.95                    far: share of max distance
    late_share                 0           0..1                       share of regions igniting late
    late_delay_s               (60, 120)   0..36000                   late ignition delay, s (range)
    fronts                     (3, 8)      1..1000                    fronts per region (range)
    fuel                       (3, 15)     (0, 100]                   fuel coefficient (range)
    wind_speed                 (2, 8)      0..50                      wind speed, m/s (range)
    wind_dir_deg               (0, 360)    0..360                     wind direction, deg (range)
    fire_mode                  'specific'  uniform, specific          per-region or shared values
    depot_orientation          'any'       any, vertical, horizontal  depot shape
    n_houses                   (1, 3)      0..500                     houses (range)
    n_hospitals                (0, 1)      0..500                     hospitals (range)
    n_power_stations           (0, 1)      0..500                     power stations (range)
    facility_fire_distance_px  (150, 500)  0..20000                   facility to nearest region, px
    house_penalty              1           0..1000                    penalty of a house
    hospital_penalty           2           0..1000                    penalty of a hospital
    power_station_penalty      5           0..1000                    penalty of a power station
    depot_penalty              5           0..1000                    penalty of the depot
    n_lakes                    (0, 1)      0..100                     decorative lakes (range)
    n_perception               (2, 3)      0..500                     perception agents (range)
    n_action                   (2, 3)      0..500                     action agents (range)
    n_hybrid                   0           0..500                     hybrid agents (range)
    speed                      20          (0, 500]                   speed, px per tick (range)
    battery                    500         (0, 1e6]                   battery (range)
    tank                       10          1..1000                    dumps per sortie (range)
    perception_altitude        (10, 100)   (0, 1000]                  perception altitude bounds, m
    hybrid_altitude            (10, 100)   (0, 1000]                  hybrid altitude bounds, m
    action_prune_confidence    0.9         (0, 1]                     action confidence (range)
    hybrid_prune_confidence    0.8         (0, 1]                     hybrid confidence (range)
    comm_range                 None        (0, 1e6] or None           communication range, px
    =========================  ==========  =========================  ==============================

    Knobs are also checked together: the team must always be able to sense (``n_perception[0] +
    n_hybrid[0] >= 1``) and act (``n_action[0] + n_hybrid[0] >= 1``), and hybrids prune at exactly
    20 m. Late regions need ``fire_mode = "specific"`` and ``late_delay_s[1] < duration_s``.

    Examples
    --------
    >>> cfg = GeneratorConfig(world_size=800, n_regions=2)
    >>> cfg.world_size, cfg.n_regions
    ((800, 800), (2, 2))
    >>> cfg(0).world_size
    800
    >>> GeneratorConfig.scale().n_perception
    (8, 40)
    """

    world_size: IntRange = knob(
        (1200, 1200), "irange", 800, 10_000, step=100, doc="map side, px (range)"
    )
    duration_s: float = knob(180.0, "float", 1, 36_000, doc="episode length, s")
    ticks_per_second: int = knob(10, "int", 1, 100, doc="simulation rate, Hz")
    n_regions: IntRange = knob((1, 4), "irange", 1, 500, doc="fire regions (range)")
    region_placement: str = knob("uniform", "choice", choices=PLACEMENTS, doc="where regions go")
    n_clusters: IntRange = knob((1, 2), "irange", 1, 100, doc="region clusters (range)")
    cluster_radius_px: float = knob(300.0, "float", 50, 10_000, doc="cluster radius, px")
    min_depot_distance_px: float = knob(
        300.0, "float", 0, 10_000, doc="min region-depot distance, px"
    )
    far_fraction: float = knob(0.5, "float", 0, 0.95, doc="far: share of max distance")
    late_share: float = knob(0.0, "float", 0, 1, doc="share of regions igniting late")
    late_delay_s: FloatRange = knob(
        (60.0, 120.0), "frange", 0, 36_000, doc="late ignition delay, s (range)"
    )
    fronts: IntRange = knob((3, 8), "irange", 1, 1000, doc="fronts per region (range)")
    fuel: FloatRange = knob(
        (3.0, 15.0), "frange", 0, 100, open_lo=True, doc="fuel coefficient (range)"
    )
    wind_speed: FloatRange = knob((2.0, 8.0), "frange", 0, 50, doc="wind speed, m/s (range)")
    wind_dir_deg: FloatRange = knob(
        (0.0, 360.0), "frange", 0, 360, doc="wind direction, deg (range)"
    )
    fire_mode: str = knob(
        "specific", "choice", choices=FIRE_MODES, doc="per-region or shared values"
    )
    depot_orientation: str = knob(
        "any", "choice", choices=("any", "vertical", "horizontal"), doc="depot shape"
    )
    n_houses: IntRange = knob((1, 3), "irange", 0, 500, doc="houses (range)")
    n_hospitals: IntRange = knob((0, 1), "irange", 0, 500, doc="hospitals (range)")
    n_power_stations: IntRange = knob((0, 1), "irange", 0, 500, doc="power stations (range)")
    facility_fire_distance_px: FloatRange = knob(
        (150.0, 500.0), "frange", 0, 20_000, doc="facility to nearest region, px"
    )
    house_penalty: float = knob(1.0, "float", 0, 1000, doc="penalty of a house")
    hospital_penalty: float = knob(2.0, "float", 0, 1000, doc="penalty of a hospital")
    power_station_penalty: float = knob(5.0, "float", 0, 1000, doc="penalty of a power station")
    depot_penalty: float = knob(5.0, "float", 0, 1000, doc="penalty of the depot")
    n_lakes: IntRange = knob((0, 1), "irange", 0, 100, doc="decorative lakes (range)")
    n_perception: IntRange = knob((2, 3), "irange", 0, 500, doc="perception agents (range)")
    n_action: IntRange = knob((2, 3), "irange", 0, 500, doc="action agents (range)")
    n_hybrid: IntRange = knob((0, 0), "irange", 0, 500, doc="hybrid agents (range)")
    speed: FloatRange = knob(
        (20.0, 20.0), "frange", 0, 500, open_lo=True, doc="speed, px per tick (range)"
    )
    battery: FloatRange = knob(
        (500.0, 500.0), "frange", 0, 1e6, open_lo=True, doc="battery (range)"
    )
    tank: IntRange = knob((10, 10), "irange", 1, 1000, doc="dumps per sortie (range)")
    perception_altitude: tuple[float, float] = knob(
        (10.0, 100.0), "pair", 0, 1000, open_lo=True, doc="perception altitude bounds, m"
    )
    hybrid_altitude: tuple[float, float] = knob(
        (10.0, 100.0), "pair", 0, 1000, open_lo=True, doc="hybrid altitude bounds, m"
    )
    action_prune_confidence: FloatRange = knob(
        (0.9, 0.9), "frange", 0, 1, open_lo=True, doc="action confidence (range)"
    )
    hybrid_prune_confidence: FloatRange = knob(
        (0.8, 0.8), "frange", 0, 1, open_lo=True, doc="hybrid confidence (range)"
    )
    comm_range: float | None = knob(
        None, "optional", 0, 1e6, open_lo=True, doc="communication range, px"
    )

    KNOB_NAMES: ClassVar[tuple[str, ...]]

    def __post_init__(self) -> None:
        check_knobs(self, _SOURCE)
        self._check_together()

    def _check_together(self) -> None:
        def need(ok: bool, knob: str, problem: str) -> None:
            if not ok:
                raise ScenarioError(knob, problem, got=getattr(self, knob), source=_SOURCE)

        p, a, h = (span(v)[0] for v in (self.n_perception, self.n_action, self.n_hybrid))
        need(p + h >= 1, "n_perception", "plus n_hybrid must have a lower bound >= 1 (sensing)")
        need(a + h >= 1, "n_action", "plus n_hybrid must have a lower bound >= 1 (acting)")
        lo, hi = self.hybrid_altitude
        need(lo <= 20 <= hi, "hybrid_altitude", "must contain 20 m, where hybrids prune")
        if self.late_share > 0:
            need(
                self.fire_mode == "specific",
                "late_share",
                "must be 0 when fire_mode is 'uniform' (uniform regions share one delay)",
            )
            need(
                span(self.late_delay_s)[1] < self.duration_s,
                "late_delay_s",
                f"must end before duration_s ({self.duration_s:g} s) when late_share > 0",
            )

    def replace(self, **knobs: Any) -> GeneratorConfig:
        """A copy with ``knobs`` changed, validated again; an unknown knob is an error."""
        for name in knobs:
            if name not in self.KNOB_NAMES:
                known = ", ".join(self.KNOB_NAMES)
                raise ScenarioError(name, f"unknown knob; knobs: {known}", source=_SOURCE)
        return dataclasses.replace(self, **knobs)

    def as_dict(self) -> dict[str, Any]:
        """Every knob and its normalised value, in declaration order."""
        return {name: getattr(self, name) for name in self.KNOB_NAMES}

    def __call__(self, seed: int | np.random.Generator) -> Scenario:
        """Draw the scenario of ``seed`` (see :func:`generate`)."""
        return generate(seed, self)

    @classmethod
    def preset(cls, name: str, **knobs: Any) -> GeneratorConfig:
        """The named preset of :data:`PRESETS` (``"default"``, ``"hard"``, ``"scale"``), with
        ``knobs`` changed."""
        if name not in PRESETS:
            allowed = ", ".join(map(repr, PRESETS))
            raise ScenarioError("preset", f"must be one of {allowed}", got=name, source=_SOURCE)
        return cls().replace(**{**PRESETS[name], **knobs})

    @classmethod
    def hard(cls, **knobs: Any) -> GeneratorConfig:
        """Hard tier: manual-sized maps (800-1200 px) and teams (4-9 agents, at most 2 action
        agents), but fast fires, scarce tanks and batteries, late far ignitions, threatened
        facilities and 300-s episodes. The ``hard`` tier of the ``fcplan-bench-v1`` suite was
        drawn from it (:mod:`fcplan.scenario.suite`); about half of its draws are cleared by
        greedy and were screened out."""
        return cls.preset("hard", **knobs)

    @classmethod
    def scale(cls, **knobs: Any) -> GeneratorConfig:
        """Scale tier: 3,000-10,000 px maps, 20-100 agents and 10-40 clustered regions. (The
        suite's ``scale`` tier shrinks it to 3,000-5,000 px, 18-30 agents, 10-16 regions and
        180-s episodes, so that every built-in scheduler can be measured on it.)"""
        return cls.preset("scale", **knobs)


GeneratorConfig.KNOB_NAMES = tuple(f.name for f in fields(GeneratorConfig))

PRESETS: dict[str, dict[str, Any]] = {
    "default": {},
    "hard": dict(
        world_size=(800, 1200), duration_s=300.0, n_regions=(4, 5), late_share=0.5,
        late_delay_s=(60.0, 180.0), fronts=(5, 8), fuel=(10.0, 20.0), wind_speed=(5.0, 10.0),
        n_houses=(2, 4), n_hospitals=(1, 2), n_power_stations=(1, 2), n_lakes=0,
        facility_fire_distance_px=(150.0, 350.0), n_perception=(3, 5), n_action=(1, 2),
        n_hybrid=(0, 2), battery=(200.0, 300.0), tank=(2, 4),
    ),
    "scale": dict(
        world_size=(3000, 10_000), duration_s=600.0, n_regions=(10, 40),
        region_placement="clustered", n_clusters=(3, 8), cluster_radius_px=800.0,
        late_share=0.3, late_delay_s=(60.0, 300.0), fronts=(4, 10), n_houses=(5, 20),
        n_hospitals=(1, 5), n_power_stations=(1, 5), facility_fire_distance_px=(150.0, 600.0),
        n_lakes=(0, 4), n_perception=(8, 40), n_action=(10, 50), n_hybrid=(2, 10),
        battery=(2000.0, 4000.0),
    ),
}  # fmt: skip
"""Named knob sets: ``"hard"`` and ``"scale"`` are the benchmark suite's tiers' starting points
(the suite's manifest records every knob of every frozen scenario)."""


# ------------------------------------------------------------------------------------- drawing
def _int(rng: np.random.Generator, v: IntRange) -> int:
    lo, hi = span(v)
    return int(rng.integers(lo, hi + 1))


def _real(rng: np.random.Generator, v: FloatRange, digits: int) -> float:
    """Uniform in the range, rounded to ``digits`` decimals and kept inside the range."""
    lo, hi = span(v)
    return float(min(max(round(float(rng.uniform(lo, hi)), digits), lo), hi))


def _n_late(cfg: GeneratorConfig, n: int) -> int:
    """Late regions among ``n``: ``late_share * n`` to the nearest integer (halves up), < n."""
    return min(n - 1, math.floor(cfg.late_share * n + 0.5))


def _layout(cfg: GeneratorConfig, rng: np.random.Generator, world: int, depot: Depot) -> GridLayout:
    """Regions, facilities and lakes; the positions are drawn again (same stream, same counts)
    while something does not fit."""
    n = _int(rng, cfg.n_regions)
    counts = {kind: _int(rng, getattr(cfg, f"n_{kind}s")) for kind in FACILITY_KINDS}
    n_lakes = _int(rng, cfg.n_lakes)
    penalties = {kind: getattr(cfg, f"{kind}_penalty") for kind in FACILITY_KINDS}
    problem = PlacementError("n_regions", "", "")
    for _ in range(_ATTEMPTS):
        lay = GridLayout(world, depot)
        try:
            lay.place_regions(
                rng,
                n,
                _n_late(cfg, n),
                placement=cfg.region_placement,
                min_depot_distance=cfg.min_depot_distance_px,
                far_fraction=cfg.far_fraction,
                n_clusters=_int(rng, cfg.n_clusters),
                cluster_radius=cfg.cluster_radius_px,
            )
            lay.place_facilities(
                rng, counts, distance=span(cfg.facility_fire_distance_px), penalties=penalties
            )
            lay.place_lakes(rng, n_lakes)
        except PlacementError as err:
            problem = err
            continue
        return lay
    raise ScenarioError(
        problem.knob,
        f"{problem.what} ({_ATTEMPTS} layouts of a {world} px map tried); {problem.hint}",
        got=getattr(cfg, problem.knob),
        source=_SOURCE,
    )


def _regions(cfg: GeneratorConfig, rng: np.random.Generator, lay: GridLayout) -> list[FireRegion]:
    """Fire parameters per region (or once, in uniform mode); the last regions ignite late."""
    n = len(lay.region_cells)
    n_late = _n_late(cfg, n)

    def params(late: bool) -> dict[str, Any]:
        return {
            "fronts": _int(rng, cfg.fronts),
            "fuel": _real(rng, cfg.fuel, 1),
            "wind_speed": _real(rng, cfg.wind_speed, 1),
            "wind_dir_deg": _real(rng, cfg.wind_dir_deg, 0),
            "delay_s": _real(rng, cfg.late_delay_s, 0) if late else 0.0,
        }

    shared = params(False) if cfg.fire_mode == "uniform" else None
    return [
        FireRegion(
            cell_center(cell, "region", lay.world), cell=cell, **(shared or params(i >= n - n_late))
        )
        for i, cell in enumerate(lay.region_cells)
    ]


def _team(cfg: GeneratorConfig, rng: np.random.Generator, depot: Depot) -> list[AgentSpec]:
    counts = [
        (Role.PERCEPTION, _int(rng, cfg.n_perception)),
        (Role.ACTION, _int(rng, cfg.n_action)),
        (Role.HYBRID, _int(rng, cfg.n_hybrid)),
    ]
    slots = depot.slots(sum(count for _, count in counts))
    agents: list[AgentSpec] = []
    for role, count in counts:
        if role is Role.ACTION:
            altitude, confidence = (ACTION_ALTITUDE, ACTION_ALTITUDE), cfg.action_prune_confidence
        elif role is Role.HYBRID:
            altitude, confidence = cfg.hybrid_altitude, cfg.hybrid_prune_confidence
        else:
            altitude, confidence = cfg.perception_altitude, 0.0
        lo, hi = altitude
        z = ACTION_ALTITUDE if role is Role.ACTION else min(max(20.0, lo), hi)
        for k in range(count):
            speed, battery = _real(rng, cfg.speed, 1), _real(rng, cfg.battery, 0)
            acts = role.can_act
            agents.append(
                AgentSpec(
                    id=f"{role.letter}{k + 1}",
                    role=role,
                    start=slots[len(agents)],
                    altitude=altitude,
                    start_altitude=z,
                    battery=battery,
                    speed=speed,
                    tank=_int(rng, cfg.tank) if acts else 0,
                    prune_confidence=_real(rng, confidence, 2) if acts else 0.0,
                )
            )
    return agents


# -------------------------------------------------------------------------------------- public
def _seed_of(seed: Any) -> int:
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(2**63))
    if not is_integer(seed) or seed < 0:
        raise ScenarioError(
            "seed", "must be an integer >= 0 or a numpy.random.Generator", got=seed, source=_SOURCE
        )
    return int(seed)


def _knob_text(cfg: GeneratorConfig) -> str:
    return ", ".join(f"{name}={value!r}" for name, value in cfg.as_dict().items())


def generate(
    seed: int | np.random.Generator, config: GeneratorConfig | None = None, **knobs: Any
) -> Scenario:
    """Draw a validated scenario from ``seed`` and the generator's knobs.

    Parameters
    ----------
    seed : int or numpy.random.Generator
        An integer >= 0, or a generator from which one integer seed is drawn (that seed is what
        the scenario's name and recipe record).
    config : GeneratorConfig, optional
        The knobs (default ``GeneratorConfig()``); ``knobs`` change some of them.
    **knobs
        Knob values, as for :class:`GeneratorConfig`.

    Returns
    -------
    Scenario
        Named ``gen-<seed>-<hash of the knobs>``, difficulty ``"custom"``, with one note holding
        the exact call (read back by :func:`recipe_of`).

    Raises
    ------
    ScenarioError
        On an unknown or out-of-range knob (one line naming it), or when the objects asked for do
        not fit on the map.

    Examples
    --------
    >>> s = generate(3, n_regions=2, late_share=0.5, duration_s=150)
    >>> [r.delay_s > 0 for r in s.regions]
    [False, True]
    >>> generate(3, n_regions=2, late_share=0.5, duration_s=150) == s
    True
    """
    cfg = (config or GeneratorConfig()).replace(**knobs)
    seed = _seed_of(seed)
    map_rng, layout_rng, fire_rng, team_rng = (
        np.random.default_rng(child) for child in np.random.SeedSequence(seed).spawn(4)
    )
    lo, hi = span(cfg.world_size)
    world = CELL_PX * int(map_rng.integers(lo // CELL_PX, hi // CELL_PX + 1))
    depot = draw_depot(map_rng, world, cfg.depot_orientation, cfg.depot_penalty)
    lay = _layout(cfg, layout_rng, world, depot)
    text = _knob_text(cfg)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:8]
    note = f"recipe (generator v{GENERATOR_VERSION}): {_CALL}(seed={seed}, {text})"
    return Scenario(
        name=f"gen-{seed}-{digest}",
        number=None,
        difficulty="custom",
        world_size=world,
        duration_s=cfg.duration_s,
        ticks_per_second=cfg.ticks_per_second,
        fire_mode=cfg.fire_mode,
        regions=tuple(_regions(cfg, fire_rng, lay)),
        depot=depot,
        facilities=tuple(lay.facilities),
        lakes=tuple(lay.lakes),
        agents=tuple(_team(cfg, team_rng, depot)),
        scoring=Scoring(),
        comm_range=cfg.comm_range,
        notes=(note,),
    )


def recipe_of(scenario: Scenario) -> dict[str, Any]:
    """The generator call recorded in a generated scenario's notes, as keyword arguments.

    ``generate(**recipe_of(s))`` draws ``s`` again, also after a TOML round trip.

    Raises
    ------
    ScenarioError
        If no note holds a recipe, or the recipe was written by another generator version.

    Examples
    --------
    >>> r = recipe_of(generate(5, n_regions=(2, 3)))
    >>> r["seed"], r["n_regions"], r["world_size"]
    (5, (2, 3), (1200, 1200))
    """
    for note in scenario.notes:
        m = _NOTE_RE.match(note)
        if m is None:
            continue
        version = int(m.group(1))
        if version != GENERATOR_VERSION:
            raise ScenarioError(
                "notes",
                f"the recipe was written by generator v{version}; "
                f"this fcplan has v{GENERATOR_VERSION}",
                source=scenario.name,
            )
        call = ast.parse(m.group(2), mode="eval").body
        if not isinstance(call, ast.Call) or ast.unparse(call.func) != _CALL or call.args:
            break
        return {kw.arg: ast.literal_eval(kw.value) for kw in call.keywords if kw.arg}
    raise ScenarioError(
        "notes", "holds no generator recipe (not a generated scenario)", source=scenario.name
    )
