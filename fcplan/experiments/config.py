"""Sweep configurations: a TOML grid of scenarios, schedulers, seeds and scenario overrides.

A sweep file (``fcplan sweep study.toml``) describes a grid; every combination is one episode::

    name = "team-size study"          # optional, free text
    scenarios = ["practice", "1-3"]   # names, numbers, ranges "1-24", or TOML file paths
                                      #   (relative paths are relative to this file)
    seeds = "0-4"                     # a range string or a list of integers >= 0
    replan_period = 1.0               # simulated s between replans; a list makes it a grid axis
    time_limit = 0.1                  # s per scheduler call; omit for each scheduler's own;
                                      #   a list makes it an axis
    deterministic = true              # default: schedulers with a deterministic mode run in it;
                                      #   false is the wall-time mode (fcplan sweep --wall-time)

    schedulers = ["greedy", "routing:time_limit=0.05"]   # names or name:key=value specs
    # or, with labels, fixed settings and setting grids:
    # [[schedulers]]
    # name = "milp"
    # label = "milp"                  # optional (default: the spec, e.g. "milp:slots=3")
    # settings = { time_limit = 0.2 } # fixed settings
    # grid = { slots = [2, 3] }       # one variant per value (per combination)

    [overrides]                       # dotted paths into the scenario's TOML document
    "team.perception.count" = [2, 3, 4]           # a list is an axis: one value per episode
    "fire.regions[*].wind_speed" = [5, 15]        # [*]: every region; [0]: the first one
    duration_s = 60                               # a scalar applies to every episode
    "team.perception.count+team.action.count" = [1, 2]  # "+": one axis setting both paths
    "team.perception.altitude" = [[10, 60]]       # a list-valued field: wrap it in a list

Expansion order: scenario, overrides (in file order, last varying fastest), replan period, time
limit, scheduler variant, seed. Every override combination is applied to every scenario and
validated *before* anything runs; errors (:class:`SweepConfigError`) name the sweep file, the field
and what is allowed.

Deterministic mode. By default every scheduler variant whose factory takes a ``deterministic``
setting (:func:`fcplan.scheduling.supports_deterministic`) gets ``deterministic = true`` unless it
sets the setting itself, so an episode's metrics do not depend on machine load or the number of
workers. ``deterministic = false`` (or ``sweep(..., deterministic=False)``, ``fcplan sweep
--wall-time``) is the wall-time mode; the settings column of every result row records which.

Each :class:`EpisodeSpec` has a ``key``: a hash of everything that determines the episode (the
scenario document after overrides, the scheduler name, label and settings, the seed, the replan
period and the time limit). Results are stored by key, so a re-run skips what is done even if the
file was reordered or extended. Episodes are pure functions of their spec: the same key gives the
same metrics on any machine, worker or backend.

Examples
--------
>>> cfg = load_sweep_config({"scenarios": ["practice"], "schedulers": ["greedy", "random"],
...                          "seeds": "0-1", "overrides": {"duration_s": 10}})
>>> [(e.scenario.name, e.label, e.seed) for e in cfg.episodes()]  # doctest: +NORMALIZE_WHITESPACE
[('practice', 'greedy', 0), ('practice', 'greedy', 1), ('practice', 'random', 0),
 ('practice', 'random', 1)]
>>> cfg.episodes()[0].scenario.duration_s
10.0
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fcplan.errors import FcplanError, ScenarioError, SeedError
from fcplan.experiments.overrides import SweepConfigError, apply_overrides

__all__ = [
    "EpisodeSpec",
    "SchedulerVariant",
    "SweepConfig",
    "SweepConfigError",
    "apply_overrides",
    "load_sweep_config",
]

_TOP_KEYS = (
    "name",
    "scenarios",
    "schedulers",
    "seeds",
    "replan_period",
    "time_limit",
    "overrides",
    "deterministic",
)
_SCHEDULER_KEYS = ("name", "label", "settings", "grid")


def _canon(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=str)


def short_hash(obj: Any, n: int = 16) -> str:
    """Hex digest (first ``n`` characters) of ``obj``'s canonical JSON."""
    return hashlib.sha256(_canon(obj).encode()).hexdigest()[:n]


@dataclass(frozen=True)
class SchedulerVariant:
    """One scheduler with fixed settings; ``label`` names it in results and reports."""

    label: str
    name: str
    settings: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class EpisodeSpec:
    """Everything one episode needs (picklable; sent to workers).

    Attributes
    ----------
    key : str
        Content hash (see the module docstring).
    scenario : Scenario
        With the overrides applied.
    base_scenario : str
        The scenario as named in the sweep (e.g. ``"#3"``).
    label, scheduler : str
        The variant's label and its registered scheduler name.
    settings, overrides : dict
        Scheduler settings; the override values of this episode (dotted path -> value).
    seed : int
    replan_period : float
    time_limit : float or None
    """

    key: str
    scenario: Any
    base_scenario: str
    label: str
    scheduler: str
    settings: dict[str, Any]
    overrides: dict[str, Any]
    seed: int
    replan_period: float
    time_limit: float | None


@dataclass(frozen=True, eq=False)
class SweepConfig:
    """A validated sweep grid (see the module docstring); :meth:`episodes` expands it."""

    scenarios: tuple[Any, ...]  # Scenario objects, in the order given
    schedulers: tuple[SchedulerVariant, ...]
    seeds: tuple[int, ...]
    overrides: dict[str, tuple[Any, ...]]
    replan_periods: tuple[float, ...] = (1.0,)
    time_limits: tuple[float | None, ...] = (None,)
    name: str = ""
    source: str = "<sweep>"
    deterministic: bool = True

    def to_dict(self) -> dict[str, Any]:
        """The normalised grid as JSON-ready data (scenarios by name)."""
        return {
            "name": self.name,
            "scenarios": [s.name for s in self.scenarios],
            "schedulers": [
                {"label": v.label, "name": v.name, "settings": v.settings} for v in self.schedulers
            ],
            "seeds": list(self.seeds),
            "overrides": {k: list(v) for k, v in self.overrides.items()},
            "replan_period": list(self.replan_periods),
            "time_limit": list(self.time_limits),
            "deterministic": self.deterministic,
        }

    @property
    def config_hash(self) -> str:
        """Hash of the grid, including the full scenario documents (12 hex characters)."""
        d = self.to_dict()
        d["scenarios"] = [s.to_dict() for s in self.scenarios]
        return short_hash(d, 12)

    @property
    def study_hash(self) -> str:
        """Hash of the grid without its seeds (12 hex characters): the *study*.

        Two sweeps of one study differ only in their seeds, so their episodes can be pooled
        (running more seeds into a folder extends the study); the report refuses to pool
        episodes of different studies (:func:`fcplan.experiments.report`).

        Examples
        --------
        >>> a = load_sweep_config({"scenarios": [3], "schedulers": ["idle"], "seeds": "0-1"})
        >>> b = load_sweep_config({"scenarios": [3], "schedulers": ["idle"], "seeds": "0-9"})
        >>> a.study_hash == b.study_hash, a.config_hash == b.config_hash
        (True, False)
        """
        d = self.to_dict()
        d["scenarios"] = [s.to_dict() for s in self.scenarios]
        del d["seeds"], d["name"]
        return short_hash(d, 12)

    def override_combinations(self) -> list[dict[str, Any]]:
        """Every combination of override values (one dict per combination)."""
        keys = list(self.overrides)
        return [
            dict(zip(keys, vals, strict=True))
            for vals in itertools.product(*(self.overrides[k] for k in keys))
        ]

    def episodes(self) -> list[EpisodeSpec]:
        """The grid as episode specs, in expansion order (see the module docstring).

        Raises
        ------
        SweepConfigError
            If an override combination makes a scenario invalid (the message names the sweep
            file, the override and the scenario's own error).
        """
        out = []
        for scen in self.scenarios:
            for combo in self.override_combinations():
                s = apply_overrides(scen, combo, source=self.source)
                doc = s.to_dict()
                for rp, tl, var, seed in itertools.product(
                    self.replan_periods, self.time_limits, self.schedulers, self.seeds
                ):
                    key = short_hash(
                        {
                            "scenario": doc,
                            "scheduler": var.name,
                            "label": var.label,
                            "settings": var.settings,
                            "seed": seed,
                            "replan_period": rp,
                            "time_limit": tl,
                        }
                    )
                    out.append(
                        EpisodeSpec(
                            key=key,
                            scenario=s,
                            base_scenario=scen.name,
                            label=var.label,
                            scheduler=var.name,
                            settings=dict(var.settings),
                            overrides=dict(combo),
                            seed=seed,
                            replan_period=rp,
                            time_limit=tl,
                        )
                    )
        return out


# --------------------------------------------------------------------------------------------
# loading and validation


def _err(source: str, field_: str, problem: str, got: Any = ...) -> SweepConfigError:
    msg = f"{source}: {field_}: {problem}"
    if got is not ...:
        msg += f" (got {got!r})"
    return SweepConfigError(msg)


def _number_axis(
    source: str, field_: str, value: Any, default: Any, *, allow_none: bool
) -> tuple[Any, ...]:
    if value is None:
        return (default,)
    values = value if isinstance(value, list) else [value]
    if not values:
        raise _err(source, field_, "must not be an empty list")
    out = []
    for v in values:
        ok = (
            isinstance(v, (int, float))
            and not isinstance(v, bool)
            and math.isfinite(float(v))
            and v > 0
        )
        if not ok:
            raise _err(source, field_, "must be a number > 0 or a list of them", v)
        out.append(float(v))
    return tuple(dict.fromkeys(out))


def _seeds(source: str, value: Any) -> tuple[int, ...]:
    from fcplan.experiments.ranges import RangeError, parse_range
    from fcplan.world import seed_list

    if value is None:
        raise _err(source, "seeds", 'is required, e.g. seeds = "0-4" or seeds = [0, 7]')
    if isinstance(value, str):
        if value.strip().lower() == "auto":
            raise _err(
                source,
                "seeds",
                "give seeds here and run fcplan sweep --seeds auto (or "
                "sweep(..., seeds='auto')) to add seeds until the schedulers are told apart",
            )
        try:
            return tuple(parse_range(value, names=False))  # type: ignore[arg-type]
        except RangeError as exc:
            raise _err(source, "seeds", str(exc)) from None
    if isinstance(value, bool) or not isinstance(value, (list, int)) or value == []:
        raise _err(source, "seeds", 'must be a range string like "0-4" or a list of integers')
    try:
        return tuple(seed_list(value, name=f"{source}: seeds"))
    except SeedError as exc:
        raise SweepConfigError(str(exc)) from None


def _scenarios(source: str, value: Any, base_dir: Path | None) -> tuple[Any, ...]:
    from fcplan.experiments.ranges import RangeError, parse_range
    from fcplan.scenario import Scenario, load_scenario

    if value is None:
        raise _err(source, "scenarios", 'is required, e.g. scenarios = ["practice", "1-24"]')
    items = value if isinstance(value, list) else [value]
    if not items:
        raise _err(source, "scenarios", "must not be empty")
    names: list[Any] = []
    for item in items:
        if isinstance(item, Scenario) or (isinstance(item, int) and not isinstance(item, bool)):
            names.append(item)
        elif isinstance(item, str):
            try:
                names.extend(parse_range(item))
            except RangeError as exc:
                raise _err(source, "scenarios", str(exc)) from None
        else:
            raise _err(source, "scenarios", "items must be names, numbers, ranges or paths", item)
    out = []
    for n in names:
        if isinstance(n, Scenario):
            out.append(n)
            continue
        target: Any = n
        if isinstance(n, str) and base_dir is not None and n.endswith(".toml"):
            p = Path(n)
            target = p if p.is_absolute() else base_dir / p
        try:
            out.append(load_scenario(target))
        except FcplanError as exc:
            raise SweepConfigError(f"{source}: scenarios: {exc}") from None
    seen: dict[str, Any] = {}
    for s in out:
        if s.name in seen:
            if s.to_dict() != seen[s.name].to_dict():
                raise _err(source, "scenarios", "two different scenarios share a name", s.name)
            continue
        seen[s.name] = s
    return tuple(seen.values())


def _schedulers(source: str, value: Any, deterministic: bool) -> tuple[SchedulerVariant, ...]:
    from fcplan.scheduling import deterministic_settings, make_scheduler, parse_scheduler_spec

    if value is None:
        raise _err(source, "schedulers", 'is required, e.g. schedulers = ["greedy", "random"]')
    items = value if isinstance(value, list) else [value]
    if not items:
        raise _err(source, "schedulers", "must not be empty")
    variants: list[SchedulerVariant] = []
    for i, item in enumerate(items):
        where = f"schedulers[{i}]"
        if isinstance(item, str):
            try:
                name, settings = parse_scheduler_spec(item)
            except FcplanError as exc:
                raise _err(source, where, str(exc)) from None
            entries = [(item.strip() if settings else name, name, settings)]
        elif isinstance(item, Mapping):
            extra = set(item) - set(_SCHEDULER_KEYS)
            if extra:
                raise _err(
                    source,
                    where,
                    f"unknown key(s) {sorted(extra)}; allowed: " + ", ".join(_SCHEDULER_KEYS),
                )
            given = item.get("name")
            if not isinstance(given, str) or not given:
                raise _err(source, f"{where}.name", "is required (a registered scheduler name)")
            name = given
            settings = item.get("settings", {})
            grid = item.get("grid", {})
            for k, v in (("settings", settings), ("grid", grid)):
                if not isinstance(v, Mapping):
                    raise _err(source, f"{where}.{k}", "must be a table of key = value", v)
            for k, v in grid.items():
                if not isinstance(v, list) or not v:
                    raise _err(source, f"{where}.grid.{k}", "must be a non-empty list of values", v)
            label = item.get("label")
            if label is not None and (not isinstance(label, str) or not label):
                raise _err(source, f"{where}.label", "must be a non-empty string", label)
            entries = []
            keys = list(grid)
            for vals in itertools.product(*(grid[k] for k in keys)):
                s = {**settings, **dict(zip(keys, vals, strict=True))}
                spec = name + "".join(f":{k}={_fmt(v)}" for k, v in s.items())
                lab = spec if label is None else label
                if label is not None and keys:
                    lab = label + "".join(
                        f":{k}={_fmt(v)}" for k, v in zip(keys, vals, strict=True)
                    )
                entries.append((lab, name, s))
        else:
            raise _err(source, where, "must be a name, a name:key=value spec or a table", item)
        for label, name, settings in entries:
            try:  # the one validation path of scheduler specs (unknown names included)
                if deterministic:
                    settings = deterministic_settings(name, settings)
                make_scheduler(name, **settings)
            except FcplanError as exc:
                raise _err(source, where, str(exc)) from None
            if any(v.label == label for v in variants):
                raise _err(source, where, "duplicate scheduler label", label)
            variants.append(SchedulerVariant(label, name, dict(settings)))
    return tuple(variants)


def _fmt(v: Any) -> str:
    return str(v).lower() if isinstance(v, bool) else str(v)


def _overrides(source: str, value: Any) -> dict[str, tuple[Any, ...]]:
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise _err(source, "overrides", "must be a table of dotted.path = value or [values]")
    out: dict[str, tuple[Any, ...]] = {}
    for path, v in _flatten(value):
        values = v if isinstance(v, list) else [v]
        if not values:
            raise _err(source, f"overrides.{path}", "must not be an empty list")
        out[path] = tuple(values)
    return out


def _flatten(d: Mapping[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    """``{"team": {"action": {"count": [1, 2]}}}`` -> ``[("team.action.count", [1, 2])]``
    (TOML may write a dotted key unquoted, which makes nested tables)."""
    out = []
    for k, v in d.items():
        path = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.extend(_flatten(v, path + "."))
        else:
            out.append((path, v))
    return out


def load_sweep_config(
    config: str | os.PathLike[str] | Mapping[str, Any] | SweepConfig,
    *,
    deterministic: bool = True,
) -> SweepConfig:
    """Read and validate a sweep file (TOML path) or the same document as a dict.

    Scenario names, scheduler names and settings, seeds and numbers are all checked here, and
    every override combination is applied to every scenario (so an invalid one fails now, not
    mid-sweep). The file is read as scenario files are (:func:`fcplan.scenario.read.read_text`:
    a regular file of at most 2 MiB, nesting bounded). ``deterministic=False`` chooses the
    wall-time mode whatever the file says (see the module docstring).

    Raises
    ------
    SweepConfigError
        With the file, the field and what is allowed.
    """
    from fcplan.scenario.bounds import check_document
    from fcplan.scenario.read import parse_toml, read_text

    if isinstance(config, SweepConfig):
        if config.deterministic and not deterministic:
            raise SweepConfigError(
                f"{config.source}: this config was loaded in the deterministic mode; load it "
                "with load_sweep_config(..., deterministic=False) for the wall-time mode"
            )
        return config
    base_dir = None
    if isinstance(config, Mapping):
        doc, source = dict(config), "<sweep config>"
    else:
        path = Path(config)
        source = str(path)
        try:
            doc = parse_toml(read_text(path), source)
        except ScenarioError as exc:
            if exc.problem == "no such file":
                raise SweepConfigError(f"{source}: no such sweep file") from None
            raise SweepConfigError(f"{source}: {exc.problem}") from None
        base_dir = path.resolve().parent
    try:
        check_document(doc)
    except ScenarioError as exc:
        raise SweepConfigError(f"{source}: {exc.field}: {exc.problem}") from None
    unknown = set(doc) - set(_TOP_KEYS)
    if unknown:
        raise _err(
            source, ", ".join(sorted(unknown)), "unknown key(s); allowed: " + ", ".join(_TOP_KEYS)
        )
    name = doc.get("name", "")
    if not isinstance(name, str):
        raise _err(source, "name", "must be a string", name)
    if "time_limit" in doc and doc["time_limit"] is None:
        doc.pop("time_limit")
    mode = doc.get("deterministic", True)
    if not isinstance(mode, bool):
        raise _err(source, "deterministic", "must be true or false", mode)
    mode = mode and deterministic
    cfg = SweepConfig(
        scenarios=_scenarios(source, doc.get("scenarios"), base_dir),
        schedulers=_schedulers(source, doc.get("schedulers"), mode),
        seeds=_seeds(source, doc.get("seeds")),
        overrides=_overrides(source, doc.get("overrides")),
        replan_periods=_number_axis(
            source, "replan_period", doc.get("replan_period"), 1.0, allow_none=False
        ),
        time_limits=_number_axis(
            source, "time_limit", doc.get("time_limit"), None, allow_none=True
        ),
        name=name,
        source=source,
        deterministic=mode,
    )
    for scen in cfg.scenarios:  # validate every override combination up front
        for combo in cfg.override_combinations():
            apply_overrides(scen, combo, source=source)
    return cfg


def episode_keys(specs: Sequence[EpisodeSpec]) -> list[str]:
    """The keys of ``specs`` (duplicates would mean two identical episodes)."""
    return [s.key for s in specs]
