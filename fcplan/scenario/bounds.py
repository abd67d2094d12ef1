"""Upper bounds of a scenario: what the simulator can represent, in range, memory and nesting.

:mod:`fcplan.scenario.validate` checks that numbers are in their physical domain (fuel > 0, ...);
this module adds the other end, so that a scenario that validates also *runs*: no overflow, no
allocation the machine cannot make, no recursion on a hostile document. The bounds are generous
for scale studies (maps of 10,000 px and more, thousands of agents, hundreds of regions, a
simulated day) and are checked when a :class:`~fcplan.scenario.model.Scenario` is built
(:func:`check_bounds`) and, for the parsed TOML document, before it is read
(:func:`check_document`).

Ranges (a violation is a :class:`~fcplan.errors.ScenarioError` naming the field and the range):

=============================== ====================== =========================================
field                           range                  why
=============================== ====================== =========================================
``world_size``                  100..16,000 px         the cell grids are world_size^2
``duration_s``                  (0, 86,400] s          one simulated day
``ticks_per_second``            1..1,000
ticks (duration x tps)          1..10,000,000          int32 tick stamps, one trace row per tick
``comm_range``                  (0, 10^7] px
``scoring.propagation_weight``  [0, 1,000]
``scoring.temporal_exponent``   [0, 10]                ``t^p`` stays finite for t <= 86,400 s
penalties (facilities, depot)   [0, 10^6]
fire regions                    1..1,000
fronts                          1..100,000 per region, at most 100,000 in total
``delay_s``                     [0, 10^6] s
``fuel``                        (0, 1,000]             a front moves < fuel/2 px per tick
``wind_speed``                  [0, 100] m/s           FARSITE's exp(0.2566 U) stays finite
``wind_dir_deg``                [-3,600, 3,600]
``half_width``                  [1, world_size] px     the ignition box holds a whole pixel
facilities, lakes               at most 2,000 each
facility ``size``               (0, 10^5] px
agents                          at most 10,000
``altitude``                    (0, 1,000] m
``battery``                     (0, 10^7]
``speed``                       (0, 1,000] px per tick at 10 ticks/s
``tank``                        1..10,000 dumps        int16 trace columns
=============================== ====================== =========================================

Memory. :func:`estimate_bytes` estimates the peak memory of an episode from the scenario's
size, conservatively (measured peaks are 0.4-0.9 of it: ``bench/bench_memory_estimate.py``)::

    bytes = 128 MiB                                   interpreter, numpy, solvers
          + 24 (world_size + 1)^2                     fire, world and belief grids
          + ticks (96 agents + 32 (facilities + 1) + 128)         the trace (and its copy)
          + 2,200 fronts                              per-front buffers
          + 64 agents (ceil(world_size / 100)^2 + 1,000)          a replan's agent x task arrays

A scenario whose estimate exceeds :data:`MEMORY_LIMIT_BYTES` (8 GiB) is refused with the
estimate, its largest part and the fields that drive it.

Documents. :func:`check_document` walks a parsed TOML document without recursion before anything
else reads it: nesting deeper than :data:`MAX_DEPTH` levels, more agents, regions, facilities or
lakes than the bounds above are refused (so ``count = 1000000000`` fails before a slot is
allocated).

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> s = load_scenario(12)
>>> f"{estimate_bytes(s) / 2**20:.0f} MiB"
'163 MiB'
>>> s.replace(world_size=30_000)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.ScenarioError: ...12.toml: world_size: must be an integer in 100..16000 (px) (got 30000)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from fcplan.errors import ScenarioError

if TYPE_CHECKING:
    from fcplan.scenario.model import Scenario

__all__ = [
    "MAX_DEPTH",
    "MAX_AGENTS",
    "MAX_REGIONS",
    "MAX_FRONTS",
    "MAX_FACILITIES",
    "MAX_LAKES",
    "MAX_TICKS",
    "MEMORY_LIMIT_BYTES",
    "RANGES",
    "check_bounds",
    "check_document",
    "estimate_bytes",
    "format_bytes",
]

MAX_DEPTH = 16
"""Deepest nesting of tables and arrays in a scenario document (the format needs 5)."""
MAX_AGENTS = 10_000
MAX_REGIONS = 1_000
MAX_FRONTS = 100_000
MAX_FACILITIES = 2_000
MAX_LAKES = 2_000
MAX_TICKS = 10_000_000
MEMORY_LIMIT_BYTES = 8 * 2**30
"""Largest estimated episode memory (:func:`estimate_bytes`) a scenario may need."""

#: field -> (low, high, low is open, unit) of every bounded number (see the module docstring).
RANGES: dict[str, tuple[float, float, bool, str]] = {
    "world_size": (100, 16_000, False, "px"),
    "duration_s": (0, 86_400, True, "simulated seconds"),
    "ticks_per_second": (1, 1_000, False, ""),
    "comm_range": (0, 1e7, True, "px"),
    "scoring.propagation_weight": (0, 1_000, False, ""),
    "scoring.temporal_exponent": (0, 10, False, ""),
    "penalty": (0, 1e6, False, ""),
    "fronts": (1, MAX_FRONTS, False, ""),
    "delay_s": (0, 1e6, False, "simulated seconds"),
    "fuel": (0, 1_000, True, ""),
    "wind_speed": (0, 100, False, "m/s"),
    "wind_dir_deg": (-3_600, 3_600, False, "degrees"),
    "size": (0, 1e5, True, "px"),
    "altitude": (0, 1_000, True, "m"),
    "battery": (0, 1e7, True, ""),
    "speed": (0, 1_000, True, "px per tick at 10 ticks/s"),
    "tank": (1, 10_000, False, "dumps"),
}

_INTEGERS = ("world_size", "ticks_per_second", "fronts", "tank")
_BASE_BYTES = 128 * 2**20


def _range_text(name: str, hi: float | None = None) -> str:
    lo, top, lo_open, unit = RANGES[name]
    top = top if hi is None else hi
    unit = f" ({unit})" if unit else ""
    if name in _INTEGERS:
        return f"must be an integer in {lo:g}..{top:g}{unit}"
    return f"must be a number in {'(' if lo_open else '['}{lo:g}, {top:g}]{unit}"


def _within(field: str, name: str, v: Any, hi: float | None = None) -> None:
    """``v`` (already known to be a finite number in its physical domain) is in ``RANGES``."""
    lo, top, lo_open, _ = RANGES[name]
    top = top if hi is None else hi
    if not ((v > lo if lo_open else v >= lo) and v <= top):
        raise ScenarioError(field, _range_text(name, hi), got=v)


def _count(field: str, n: int, most: int, what: str) -> None:
    if n > most:
        raise ScenarioError(field, f"at most {most:,} {what} (got {n:,})")


# ------------------------------------------------------------------------------------- scenario
def check_bounds(s: Scenario, agent_path: Any = None) -> None:
    """Raise :class:`~fcplan.errors.ScenarioError` if ``s`` exceeds a bound of the module
    docstring (ranges, counts, ticks, memory). ``s`` must already be physically valid.

    ``agent_path(n, name)`` gives the TOML path of field ``name`` of agent ``n`` (default
    ``agents[n].name``).
    """
    path = agent_path or (lambda n, name: f"agents[{n}].{name}")
    for name in ("world_size", "duration_s", "ticks_per_second"):
        _within(name, name, getattr(s, name))
    if not 1 <= s.n_ticks <= MAX_TICKS:
        raise ScenarioError(
            "duration_s",
            f"duration_s x ticks_per_second must give 1..{MAX_TICKS:,} ticks",
            got=f"{s.duration_s:g} s x {s.ticks_per_second} = {s.n_ticks:,} ticks",
        )
    if s.comm_range is not None:
        _within("comm_range", "comm_range", s.comm_range)
    _within(
        "scoring.propagation_weight", "scoring.propagation_weight", s.scoring.propagation_weight
    )
    _within("scoring.temporal_exponent", "scoring.temporal_exponent", s.scoring.temporal_exponent)
    _within("scoring.penalties.depot", "penalty", s.depot.penalty)
    _check_regions(s)
    _count("facilities", len(s.facilities), MAX_FACILITIES, "facilities")
    for i, f in enumerate(s.facilities):
        _within(f"facilities[{i}].penalty", "penalty", f.penalty)
        for v in f.size:
            _within(f"facilities[{i}].size", "size", v)
    _count("lakes", len(s.lakes), MAX_LAKES, "lakes")
    _count("team", len(s.agents), MAX_AGENTS, "agents")
    for n, a in enumerate(s.agents):
        _within(path(n, "altitude"), "altitude", a.altitude[1])
        _within(path(n, "battery"), "battery", a.battery)
        _within(path(n, "speed"), "speed", a.speed)
        if a.role.can_act:
            _within(path(n, "tank"), "tank", a.tank)
    _check_memory(s)


def _check_regions(s: Scenario) -> None:
    _count("fire.regions", len(s.regions), MAX_REGIONS, "fire regions")
    for i, r in enumerate(s.regions):
        p = f"fire.regions[{i}]"
        for name in ("fronts", "delay_s", "fuel", "wind_speed", "wind_dir_deg"):
            _within(f"{p}.{name}", name, getattr(r, name))
        if not 1 <= r.half_width <= s.world_size:
            raise ScenarioError(
                f"{p}.half_width",
                f"must be a number in [1, {s.world_size}] (px, at most world_size)",
                got=r.half_width,
            )
    total = sum(r.fronts for r in s.regions)
    if total > MAX_FRONTS:
        raise ScenarioError(
            "fire.regions", f"at most {MAX_FRONTS:,} fronts in total (got {total:,})"
        )


def _parts(s: Scenario) -> dict[str, float]:
    """The terms of :func:`estimate_bytes` (bytes), named by what drives them."""
    w, n = s.world_size, len(s.agents)
    blocks = math.ceil(w / 100) ** 2
    return {
        "grid": 24.0 * (w + 1) ** 2,
        "trace": float(s.n_ticks) * (96 * n + 32 * (len(s.facilities) + 1) + 128),
        "fronts": 2_200.0 * sum(r.fronts for r in s.regions),
        "task graph": 64.0 * n * (blocks + 1_000),
    }


def estimate_bytes(s: Scenario) -> int:
    """Estimated peak memory (bytes) of an episode of ``s`` (formula in the module docstring)."""
    return int(_BASE_BYTES + sum(_parts(s).values()))


def format_bytes(n: float) -> str:
    """``n`` bytes in binary units, e.g. ``'8 GiB'``, ``'72.8 TiB'``.

    Examples
    --------
    >>> format_bytes(8 * 2**30), format_bytes(1536)
    ('8 GiB', '1.5 KiB')
    """
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.1f} {unit}".replace(".0 ", " ")
        n /= 1024
    raise AssertionError("unreachable")  # pragma: no cover


_DRIVERS = {
    "grid": ("world_size", "a smaller world_size"),
    "trace": ("duration_s", "a shorter duration_s, fewer ticks_per_second or fewer agents"),
    "fronts": ("fire.regions", "fewer fronts"),
    "task graph": ("team", "fewer agents or a smaller world_size"),
}


def _check_memory(s: Scenario) -> None:
    parts = _parts(s)
    total = estimate_bytes(s)
    if total <= MEMORY_LIMIT_BYTES:
        return
    biggest = max(parts, key=parts.__getitem__)
    field, fix = _DRIVERS[biggest]
    shown = ", ".join(f"{k} {format_bytes(v)}" for k, v in parts.items())
    raise ScenarioError(
        field,
        f"an episode would need about {format_bytes(total)} of memory ({shown}), more than the "
        f"{format_bytes(MEMORY_LIMIT_BYTES)} limit; use {fix}",
    )


# ------------------------------------------------------------------------------------- document
_LISTS = (
    (("fire", "regions"), MAX_REGIONS, "fire regions"),
    (("facilities",), MAX_FACILITIES, "facilities"),
    (("lakes",), MAX_LAKES, "lakes"),
)


def check_document(doc: Any) -> None:
    """Refuse a parsed scenario document that is too deep or too big to read safely.

    Checks, without recursion: nesting of tables and arrays at most :data:`MAX_DEPTH` levels;
    team ``count`` values that are integers within 0..:data:`MAX_AGENTS` and add up to at most
    :data:`MAX_AGENTS`; at most :data:`MAX_REGIONS` regions, :data:`MAX_FACILITIES` facilities and
    :data:`MAX_LAKES` lakes. Types and everything else are left to the reader.

    Examples
    --------
    >>> check_document({"team": {"action": {"count": 10**9}}})
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: team.action.count: must be an integer in 0..10000 (got 1000000000)
    >>> deep = [0]
    >>> for _ in range(10_000):
    ...     deep = [deep]
    >>> check_document({"notes": deep})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: notes: nested more than 16 levels deep ...
    """
    _check_depth(doc)
    if not isinstance(doc, Mapping):
        return
    for keys, most, what in _LISTS:
        node: Any = doc
        for k in keys:
            node = node.get(k) if isinstance(node, Mapping) else None
        if isinstance(node, list):
            _count(".".join(keys), len(node), most, what)
    team = doc.get("team")
    if not isinstance(team, Mapping):
        return
    total = 0
    for role, t in team.items():
        count = t.get("count") if isinstance(t, Mapping) else None
        if isinstance(count, int) and not isinstance(count, bool):
            if not 0 <= count <= MAX_AGENTS:
                raise ScenarioError(
                    f"team.{role}.count", f"must be an integer in 0..{MAX_AGENTS}", got=count
                )
            total += count
    _count("team", total, MAX_AGENTS, "agents")


def _check_depth(doc: Any) -> None:
    """Nesting of dicts and lists at most :data:`MAX_DEPTH` (an explicit stack: no recursion)."""
    stack: list[tuple[Any, int, str]] = [(doc, 0, "")]
    while stack:
        node, depth, path = stack.pop()
        if isinstance(node, Mapping):
            children = [(v, f"{path}.{k}" if path else str(k)) for k, v in node.items()]
        elif isinstance(node, (list, tuple)):
            children = [(v, path) for v in node]
        else:
            continue
        if depth >= MAX_DEPTH:
            raise ScenarioError(
                path or "document",
                f"nested more than {MAX_DEPTH} levels deep (tables and arrays); "
                "a scenario document needs at most 5",
            )
        stack.extend((v, depth + 1, p) for v, p in children)
