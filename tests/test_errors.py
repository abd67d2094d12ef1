"""Tests of fcplan.errors: one-line messages, sources, and the errors other modules re-export."""

from __future__ import annotations

import pytest

import fcplan.env
import fcplan.legacy
from fcplan.errors import EnvError, FcplanError, LegacyError, ScenarioError


def test_scenario_error_with_source_keeps_the_field_and_value():
    """with_source prefixes the source once, keeps field, problem and value, and leaves an error
    that already has a source as it is."""
    err = ScenarioError("fire.fuel", "must be a number > 0", got=-1)
    sourced = err.with_source("a.toml")
    assert str(sourced) == "a.toml: fire.fuel: must be a number > 0 (got -1)"
    assert (sourced.field, sourced.problem, sourced.got, sourced.source) == (
        "fire.fuel",
        "must be a number > 0",
        -1,
        "a.toml",
    )
    assert sourced.with_source("b.toml") is sourced
    bare = ScenarioError("depot", "is required").with_source("x")
    assert str(bare) == "x: depot: is required" and bare.got is None


def test_env_and_legacy_errors_are_defined_once():
    """EnvError and LegacyError are fcplan.errors classes (FcplanError and ValueError), the same
    objects as fcplan.env.EnvError and fcplan.legacy.LegacyError."""
    assert fcplan.env.EnvError is EnvError and fcplan.legacy.LegacyError is LegacyError
    for cls in (EnvError, LegacyError):
        assert issubclass(cls, FcplanError) and issubclass(cls, ValueError)
    with pytest.raises(EnvError, match="mode"):
        fcplan.env.parallel_env("practice", mode="nope")
