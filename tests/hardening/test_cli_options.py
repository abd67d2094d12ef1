"""Every option of every command given hostile values (issue 17, argument abuse): generated from
the parser (:mod:`tests.hardening.options`), each case ends in one line and exit 2, or runs
(exit 0), within a time and a memory bound, leaving no process behind.

The default run gives each option and positional one of the hostile values (rotating through
them, so every value is used); ``pytest -m slow`` gives every option every value."""

from __future__ import annotations

import os
import stat

import pytest

from tests.hardening.options import HOSTILE, Fixtures, option_cases
from tests.hardening.runner import Outcome, run_in_process

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc for processes")

TIME_BOUND_S = 120
MEMORY_BOUND_MB = 1024  # traced Python and numpy allocations of one case
_KEYS = [(c.command, c.option, c.value) for c in option_cases(Fixtures.make("/fx", build=False))]
_PAIRS = list(dict.fromkeys((c, o) for c, o, _ in _KEYS))


def _rotation() -> list[tuple[str, str, str]]:
    """One hostile value per (command, option), rotating through HOSTILE and skipping the values
    an option does not take (outputs are never given a FIFO or a device), so every value is used
    whatever the number of options."""
    keys, out, k = set(_KEYS), [], 0
    for command, option in _PAIRS:
        for _ in range(len(HOSTILE)):
            value, k = HOSTILE[k % len(HOSTILE)], k + 1
            if (command, option, value) in keys:
                out.append((command, option, value))
                break
    return out


DEFAULT = _rotation()


#: Cases whose fix belongs to another branch, expected to fail here until the lead merges it.
ELSEWHERE: dict[tuple[str, str, str], str] = {}


def _params(keys: list[tuple[str, str, str]]) -> list:
    return [
        pytest.param(k, marks=pytest.mark.xfail(reason=ELSEWHERE[k], strict=False))
        if k in ELSEWHERE
        else k
        for k in keys
    ]


def _check(fx: Fixtures, key: tuple[str, str, str]) -> None:
    case = {(c.command, c.option, c.value): c for c in option_cases(fx)}[key]
    result = run_in_process(case.argv, timeout=TIME_BOUND_S)
    assert result.outcome in (Outcome.CLEAN, Outcome.RAN), (case.argv, result.stderr[-2000:])
    assert result.peak_mb < MEMORY_BOUND_MB, (case.argv, result.peak_mb)
    for dev in ("/dev/null", "/dev/zero"):  # never replaced by a file (see tests.hardening.options)
        assert stat.S_ISCHR(os.stat(dev).st_mode), dev


def test_every_command_and_option_is_covered():
    """The generated cases reach every command and every value-taking option of the parser."""
    from fcplan.cli.parser import build_parser

    commands = {c for c, _, _ in _KEYS}
    assert {"run", "compare", "sweep", "report", "replay", "play", "import-legacy"} <= commands
    assert len(_PAIRS) >= 35 and {v for _, _, v in DEFAULT} == set(HOSTILE)
    assert build_parser() is not None


@pytest.mark.parametrize("key", _params(DEFAULT), ids=lambda k: f"{k[0]} {k[1]}={k[2]!r}")
def test_a_hostile_option_value_is_one_line_or_runs(fx, scratch, key):
    """An option or positional given a hostile value: exit 2 with one 'fcplan: error:' line, or
    exit 0, within the time and memory bounds, no process left behind."""
    _check(fx, key)


@pytest.mark.slow
@pytest.mark.parametrize("key", _params(_KEYS), ids=lambda k: f"{k[0]} {k[1]}={k[2]!r}")
def test_every_hostile_option_value_is_one_line_or_runs(fx, scratch, key):
    """The same property for every option and every hostile value."""
    _check(fx, key)
