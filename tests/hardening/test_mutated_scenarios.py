"""Mutated shipped scenarios (issue 17's audit): every file either fails to load with one line
naming the problem, or loads and runs, within a time and a memory bound."""

from __future__ import annotations

import random
from collections.abc import Callable
from typing import Any, TypeVar

import pytest
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from fcplan import run_episode
from fcplan.errors import FcplanError
from fcplan.scenario import load_scenario
from fcplan.scenario.bounds import MEMORY_LIMIT_BYTES, estimate_bytes
from fcplan.scenario.read import scenario_from_dict
from tests.deadline import deadline
from tests.hardening.mutate import mutant, to_toml
from tests.traced import traced_call

T = TypeVar("T")

TIME_BOUND_S = 120
MEMORY_BOUND = 2 * 2**30  # bytes traced (numpy included) while loading and running one mutant,
# or the validator's own estimate for a scenario that loads, if larger (up to MEMORY_LIMIT_BYTES)
RUN_S = 5.0  # simulated seconds played of a mutant that loads


class HangError(Exception):
    """A mutant took longer than the time bound."""


def bounded(seconds: int, fn: Callable[..., tuple[T, int]], *args: Any) -> T:
    """``fn(*args)`` in the traced helper (:mod:`tests.traced`) under a ``seconds`` alarm
    (HangError) and a memory bound. ``fn`` returns ``(value, bound)``: the bound its run may
    use (:data:`MEMORY_BOUND`, or a loaded scenario's larger estimate). Fails if the traced peak
    reached the bound; returns the value."""
    (value, bound), peak = traced_call(_alarmed, seconds, fn, *args)
    assert peak < max(bound, MEMORY_BOUND), f"peak traced memory {peak / 2**20:.0f} MiB"
    return value


def _alarmed(seconds: int, fn: Callable[..., T], *args: Any) -> T:
    """``fn(*args)`` under an alarm (run in the helper's main thread)."""

    with deadline(seconds, lambda: HangError(f"over {seconds} s")):
        return fn(*args)


def _load_and_play(path: str) -> tuple[str | None, int]:
    """The one-line message of a mutant that fails to load, or None once it loaded, validated
    within the cap and played its first seconds; with the memory bound it may use."""
    try:
        s = load_scenario(path)
    except FcplanError as exc:
        return str(exc), MEMORY_BOUND
    assert estimate_bytes(s) <= MEMORY_LIMIT_BYTES
    short = s.replace(duration_s=min(s.duration_s, RUN_S))
    res = run_episode(short, "greedy", seed=0)
    assert res.ticks == short.n_ticks
    # a valid big map may use what validation estimated for it, and no more
    return None, max(MEMORY_BOUND, estimate_bytes(s))


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(seed=st.integers(0, 2**32 - 1))
def test_a_mutated_file_fails_in_one_line_or_runs(seed, tmp_path_factory):
    """Load a mutated shipped scenario: either a one-line FcplanError (no other exception, no
    traceback-worthy crash), or a valid scenario whose memory estimate is within the cap and
    whose first seconds play to the end, all within the time and memory bounds."""
    what, doc = mutant(random.Random(seed))
    note(what)
    path = tmp_path_factory.mktemp("mutant") / "mutant.toml"
    path.write_text(to_toml(doc), encoding="utf-8")
    message = bounded(TIME_BOUND_S, _load_and_play, str(path))
    assert message is None or "\n" not in message


@pytest.mark.parametrize(
    "path, value",
    [
        ("scoring.temporal_exponent", 1000),
        ("fire.regions.0.half_width", 1e-300),
        ("duration_s", 1e12),
        ("world_size", 10_000_000),
        ("fire.regions.0.fronts", 1_000_000_000),
        ("ticks_per_second", 1_000_000),
    ],
)
def test_the_audits_crashing_files_are_one_line_errors(path, value, tmp_path):
    """The six files of the issue that validated and then crashed or ran out of memory are now
    refused by load_scenario with one line naming the field."""
    doc = load_scenario(12).to_dict()
    node = doc
    keys = path.split(".")
    for k in keys[:-1]:
        node = node[int(k)] if k.isdigit() else node[k]
    node[keys[-1]] = value
    f = tmp_path / "crash.toml"
    f.write_text(to_toml(doc), encoding="utf-8")
    with pytest.raises(FcplanError) as exc:
        load_scenario(f)
    msg = str(exc.value)
    assert "\n" not in msg and keys[-1] in msg


def test_deeply_nested_arrays_are_refused_before_the_parser_recurses(tmp_path):
    """A file nesting arrays 100,000 deep (the audit's RecursionError) is a one-line error."""
    f = tmp_path / "deep.toml"
    f.write_text('name = "x"\nnotes = ' + "[" * 100_000 + "]" * 100_000 + "\n", encoding="utf-8")
    with pytest.raises(FcplanError, match="nest more than 16 levels"):
        load_scenario(f)


def _team_size(doc: dict[str, Any]) -> tuple[int, int]:
    return len(scenario_from_dict(doc, "team.toml").agents), MEMORY_BOUND


def test_a_team_of_10000_agents_validates_within_the_bound():
    """Validation is linear in the team: 10,000 agents with per-agent batteries and speeds load
    within the time bound (the quadratic check of issue 17 took 4.45 s for 1,002 agents, so
    minutes for 10,000); one agent more is refused in one line."""
    doc = load_scenario(12).to_dict()
    doc["world_size"] = 2_000
    for role in ("perception", "action"):
        team = doc["team"][role]
        team["count"] = 5_000
        team["battery"] = [400.0 + k % 200 for k in range(5_000)]
        team["speed"] = [15.0 + k % 10 for k in range(5_000)]
    assert bounded(30, _team_size, doc) == 10_000
    doc["team"]["action"]["count"] = 5_001
    doc["team"]["action"]["battery"].append(500.0)
    doc["team"]["action"]["speed"].append(20.0)
    with pytest.raises(FcplanError, match="10,000 agents"):
        scenario_from_dict(doc, "team.toml")
