"""Versioned benchmark suites: generated scenarios frozen as TOML files, loadable by name.

The manual's 24 scenarios saturate: every competent scheduler clears them. A *benchmark suite* is
a fixed set of harder scenarios drawn by :mod:`fcplan.scenario.generate`, frozen under a version
so that published numbers name exactly what was played. fcplan ships ``fcplan-bench-v1``
(:data:`SUITE_VERSION`) with two tiers:

* ``hard-01`` .. ``hard-12``: manual-sized maps and teams with scarce tanks and batteries, late
  ignitions far from the depot, facilities within reach of the fire and 300-s episodes;
* ``scale-01`` .. ``scale-06``: maps of thousands of px with tens of agents and regions.

How a suite is stored
---------------------
A suite is a folder ``fcplan/data/suites/<version>/`` (package data, shipped in the wheel) holding
one TOML file per scenario and ``manifest.json``:

=====================  ==========================================================================
manifest field         meaning
=====================  ==========================================================================
``suite``              the version, e.g. ``"fcplan-bench-v1"``
``generator_version``  :data:`~fcplan.scenario.generate.GENERATOR_VERSION` that drew the files
``description``        what the suite is for and how its tiers were chosen
``scenarios``          one record per file, in order: ``name`` (``"hard-01"``), ``tier``,
                       ``file``, ``seed``, ``preset`` (the preset the call started from),
                       ``overrides`` (knobs changed from that preset), ``knobs`` (every knob's
                       value: the exact call), ``wind_model`` (recorded, so that a change of the
                       format's default cannot change the suite) and
                       ``sha256`` of the file's bytes
=====================  ==========================================================================

A scenario of the suite is named ``<version>/<name>`` (``"fcplan-bench-v1/hard-01"``): that is
the name results and reports carry, so every published row records the suite version. Its notes
hold the generator's recipe (:func:`~fcplan.scenario.generate.recipe_of`) and the suite's note.

:meth:`SuiteEntry.build` draws a scenario again from its recorded call
(``generate(seed, GeneratorConfig(**knobs))``, then renamed) and :meth:`SuiteEntry.text` is its
TOML; the test suite checks that these equal the frozen files byte for byte. The files, not the
generator, are the benchmark: a later generator that draws differently must keep this suite's
files (and bump :data:`~fcplan.scenario.generate.GENERATOR_VERSION`).

Names
-----
:func:`suite_scenario_path` resolves a short name (``"hard-01"``, in the current suite) and a
fully qualified one (``"fcplan-bench-v1/hard-01"``, in any shipped suite);
:func:`fcplan.scenario.load_scenario`, ``fcplan run`` and every command that takes a scenario
accept both through :mod:`fcplan.scenario.catalogue`. :meth:`Suite.names` lists a tier's
scenarios (``load_suite().names("hard")``).

Examples
--------
>>> suite = load_suite()
>>> suite.version, list(suite.tiers()), suite.names("hard")[:2]
('fcplan-bench-v1', ['hard', 'scale'], ['fcplan-bench-v1/hard-01', 'fcplan-bench-v1/hard-02'])
>>> suite_scenario_path("hard-01") == suite_scenario_path("fcplan-bench-v1/hard-01")
True
>>> suite_of("fcplan-bench-v1/scale-03"), suite_of("#12")
('fcplan-bench-v1', None)
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fcplan.errors import ScenarioError, UnknownNameError
from fcplan.scenario.generate import GENERATOR_VERSION, PRESETS, GeneratorConfig, generate
from fcplan.scenario.model import Scenario
from fcplan.scenario.parts import DEFAULT_WIND_MODEL
from fcplan.scenario.write import dump_scenario

__all__ = [
    "SUITE_VERSION",
    "Suite",
    "SuiteEntry",
    "freeze_entry",
    "load_suite",
    "read_suite",
    "suite_of",
    "suite_scenario_path",
    "suite_versions",
    "write_suite",
]

SUITE_VERSION = "fcplan-bench-v1"
"""The current benchmark suite; short names (``"hard-01"``) resolve in it."""

MANIFEST = "manifest.json"
_DATA = Path(__file__).resolve().parents[1] / "data" / "suites"
_NAME = re.compile(r"^[a-z][a-z0-9]*-\d{2}$")
_VERSION = re.compile(r"^[a-z][a-z0-9-]*-v\d+$")


@dataclass(frozen=True)
class SuiteEntry:
    """One frozen scenario of a suite: its name, tier, file and the generator call that drew it.

    Attributes
    ----------
    suite : str
        The suite version, e.g. ``"fcplan-bench-v1"``.
    name : str
        ``"<tier>-<nn>"``, e.g. ``"hard-01"``.
    tier : str
    seed : int
        The generator seed.
    knobs : dict
        Every knob of the call (``GeneratorConfig(**knobs)``).
    preset : str
        The preset the call started from (informative; ``knobs`` is what counts).
    overrides : dict
        The knobs changed from that preset when the suite was frozen (normalised values).
    file : str
        File name inside the suite's folder.
    sha256 : str
        Hex digest of the file's bytes.
    wind_model : str
        The fire's wind model (recorded, so that a change of the format's default cannot change
        how the suite's scenarios are drawn again).
    """

    suite: str
    name: str
    tier: str
    seed: int
    knobs: dict[str, Any]
    preset: str = "default"
    overrides: dict[str, Any] = dataclasses.field(default_factory=dict)
    file: str = ""
    sha256: str = ""
    wind_model: str = DEFAULT_WIND_MODEL

    @property
    def qualified_name(self) -> str:
        """``"<suite>/<name>"``: the scenario's name in results."""
        return f"{self.suite}/{self.name}"

    def config(self) -> GeneratorConfig:
        """The generator's knobs of the recorded call."""
        return GeneratorConfig(**self.knobs)

    def build(self) -> Scenario:
        """Draw the scenario again from the recorded call, named and annotated as in the suite."""
        s = generate(self.seed, self.config())
        note = (
            f"benchmark suite {self.suite}, scenario {self.name} (tier {self.tier}): generator "
            f"seed {self.seed}, preset {self.preset!r} with overrides {_call_text(self.overrides)}"
        )
        return s.replace(
            name=self.qualified_name, notes=(*s.notes, note), wind_model=self.wind_model
        )

    def text(self) -> str:
        """The TOML text of :meth:`build` (what the frozen file holds)."""
        return dump_scenario(self.build())

    def to_dict(self) -> dict[str, Any]:
        """The manifest record (JSON-ready; tuples become lists)."""
        return _jsonable(
            {
                "name": self.name,
                "tier": self.tier,
                "file": self.file,
                "seed": self.seed,
                "preset": self.preset,
                "overrides": self.overrides,
                "knobs": self.knobs,
                "wind_model": self.wind_model,
                "sha256": self.sha256,
            }
        )


@dataclass(frozen=True)
class Suite:
    """A versioned suite: its folder, description and entries (see the module docstring)."""

    version: str
    folder: Path
    entries: tuple[SuiteEntry, ...]
    description: str = ""
    generator_version: int = GENERATOR_VERSION

    def tiers(self) -> dict[str, list[SuiteEntry]]:
        """Tier name -> its entries, in manifest order."""
        out: dict[str, list[SuiteEntry]] = {}
        for e in self.entries:
            out.setdefault(e.tier, []).append(e)
        return out

    def names(self, tier: str | None = None) -> list[str]:
        """Fully qualified scenario names (of one tier, or all).

        Raises
        ------
        UnknownNameError
            For a tier the suite does not have.
        """
        if tier is not None and tier not in self.tiers():
            known = ", ".join(self.tiers())
            raise UnknownNameError(f"suite {self.version} has no tier {tier!r}; tiers: {known}")
        return [e.qualified_name for e in self.entries if tier is None or e.tier == tier]

    def entry(self, name: str) -> SuiteEntry:
        """The entry of ``"hard-01"`` or ``"<version>/hard-01"``.

        Raises
        ------
        UnknownNameError
            The message lists the suite's scenarios.
        """
        short = name.removeprefix(self.version + "/")
        for e in self.entries:
            if e.name == short:
                return e
        known = ", ".join(e.name for e in self.entries)
        raise UnknownNameError(f"suite {self.version} has no scenario {name!r}; known: {known}")

    def path(self, name: str) -> Path:
        """The frozen file of a scenario of the suite."""
        return self.folder / self.entry(name).file


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return value


def _call_text(knobs: dict[str, Any]) -> str:
    return "{" + ", ".join(f"{k}={v!r}" for k, v in knobs.items()) + "}"


def _manifest_error(folder: Path, problem: str) -> ScenarioError:
    return ScenarioError("manifest", problem, source=str(folder / MANIFEST))


def read_suite(folder: str | os.PathLike[str]) -> Suite:
    """The suite stored in ``folder`` (named after its version), e.g. one :func:`write_suite`
    wrote.

    Raises
    ------
    ScenarioError
        A missing or malformed manifest (one line naming it).
    """
    folder = Path(folder)
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise _manifest_error(folder, f"cannot be read: {exc}") from None
    version = doc.get("suite")
    if version != folder.name:
        raise _manifest_error(folder, f"suite {version!r} does not match its folder")
    entries = []
    for i, rec in enumerate(doc.get("scenarios", [])):
        try:
            knobs = GeneratorConfig(**rec["knobs"]).as_dict()  # normalised: ranges as tuples
            entries.append(
                SuiteEntry(
                    suite=version,
                    name=rec["name"],
                    tier=rec["tier"],
                    seed=int(rec["seed"]),
                    knobs=knobs,
                    preset=rec.get("preset", "default"),
                    overrides={k: knobs[k] for k in rec.get("overrides", {})},
                    file=rec["file"],
                    sha256=rec.get("sha256", ""),
                    wind_model=rec["wind_model"],
                )
            )
        except (KeyError, TypeError, ValueError) as exc:  # ScenarioError is a ValueError
            raise _manifest_error(folder, f"scenarios[{i}]: bad record ({exc})") from None
    return Suite(
        version=version,
        folder=folder,
        entries=tuple(entries),
        description=str(doc.get("description", "")),
        generator_version=int(doc.get("generator_version", GENERATOR_VERSION)),
    )


def suite_versions() -> list[str]:
    """The versions of the shipped suites, oldest first.

    Examples
    --------
    >>> "fcplan-bench-v1" in suite_versions()
    True
    """
    if not _DATA.is_dir():
        return []
    found = [p.name for p in _DATA.iterdir() if (p / MANIFEST).is_file() and _VERSION.match(p.name)]
    return sorted(found, key=lambda v: int(v.rsplit("-v", 1)[1]))


def load_suite(version: str = SUITE_VERSION) -> Suite:
    """The shipped suite ``version`` (its manifest; the scenarios load by name).

    Raises
    ------
    UnknownNameError
        For a version not shipped (the message lists those that are).
    """
    if version not in suite_versions():
        known = ", ".join(suite_versions()) or "none"
        raise UnknownNameError(f"unknown benchmark suite {version!r}; shipped suites: {known}")
    return read_suite(_DATA / version)


def suite_of(scenario_name: str) -> str | None:
    """The suite version a scenario name belongs to (``"<version>/<name>"``), else None."""
    version, sep, rest = str(scenario_name).partition("/")
    if sep and _VERSION.match(version) and _NAME.match(rest):
        return version
    return None


def suite_scenario_path(name: str) -> Path | None:
    """The frozen file of a suite scenario named ``"hard-01"`` (current suite) or
    ``"<version>/hard-01"``; None when ``name`` does not look like one.

    Raises
    ------
    UnknownNameError
        A qualified name of an unknown suite, or a suite name that the suite does not hold.
    """
    name = name.strip().lower()
    version = suite_of(name)
    if version is not None:
        return load_suite(version).path(name)
    if _NAME.match(name) and SUITE_VERSION in suite_versions():
        suite = load_suite()
        if any(e.name == name for e in suite.entries):
            return suite.path(name)
    return None


def freeze_entry(
    suite: str, name: str, tier: str, seed: int, preset: str = "default", **overrides: Any
) -> SuiteEntry:
    """The entry of a new suite scenario: ``preset`` with ``overrides``, drawn from ``seed``
    (its ``file`` and ``sha256`` are those of :meth:`SuiteEntry.text`).

    Examples
    --------
    >>> e = freeze_entry("my-bench-v1", "tiny-01", "tiny", 4, n_regions=1, duration_s=60)
    >>> e.file, e.overrides, e.build().name
    ('tiny-01.toml', {'n_regions': (1, 1), 'duration_s': 60.0}, 'my-bench-v1/tiny-01')
    """
    if not _VERSION.match(suite) or not _NAME.match(name):
        raise ValueError(f"suite must look like 'name-v1' and name like 'tier-01': {suite}, {name}")
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}")
    knobs = GeneratorConfig.preset(preset, **overrides).as_dict()
    changed = {k: knobs[k] for k in overrides}
    entry = SuiteEntry(suite, name, tier, int(seed), knobs, preset, changed, f"{name}.toml")
    digest = hashlib.sha256(entry.text().encode("utf-8")).hexdigest()
    return dataclasses.replace(entry, sha256=digest)


def write_suite(
    folder: str | os.PathLike[str], entries: list[SuiteEntry], description: str = ""
) -> Path:
    """Write the entries' files and the manifest into ``folder`` (named after the suite version);
    returns the manifest's path."""
    out = Path(folder)
    versions = {e.suite for e in entries}
    if versions != {out.name}:
        raise ValueError(f"entries of suites {sorted(versions)} written into folder {out.name!r}")
    out.mkdir(parents=True, exist_ok=True)
    for e in entries:
        (out / e.file).write_text(e.text(), encoding="utf-8")
    doc = {
        "suite": out.name,
        "generator_version": GENERATOR_VERSION,
        "description": description,
        "scenarios": [e.to_dict() for e in entries],
    }
    path = out / MANIFEST
    path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return path
