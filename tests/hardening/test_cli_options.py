"""Every option of every command given hostile values (issue 17, argument abuse): generated from
the parser (:mod:`tests.hardening.options`), each case ends in one line and exit 2, or runs
(exit 0), within a time and a memory bound, leaving no process behind.

The default run gives each option and positional two of the hostile values (rotating through
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
DEFAULT = [
    key
    for i, (command, option) in enumerate(_PAIRS)
    for j in (0, 1)
    if (key := (command, option, HOSTILE[(2 * i + j) % len(HOSTILE)])) in _KEYS
]


#: Cases whose fix belongs to another branch (fcplan/cli/replay.py and fcplan/video.py are the
#: cli engineer's): expected to fail here until the lead merges it.
ELSEWHERE = {
    **{
        ("replay", opt, v): "--start/--end accept inf on main; the cli branch checks finiteness"
        for opt in ("--start", "--end")
        for v in ("inf", "1e999")
    },
    ("replay", "--size", "99999999999999999999"): "--size has no upper bound: numpy refuses "
    "the frame (ValueError); the cli branch should bound it (e.g. <= 4096)",
    ("replay", "--fps", "1e-300"): "--fps has no lower bound: a GIF frame delay of 1e302 cs "
    "overflows (OverflowError/struct.error); the cli branch should bound it (e.g. >= 0.01)",
}


def _params(keys: list[tuple[str, str, str]]) -> list:
    return [
        pytest.param(k, marks=pytest.mark.xfail(reason=ELSEWHERE[k], strict=False))
        if k in ELSEWHERE
        else k
        for k in keys
    ]


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    """Valid inputs of every command (a 3-s scenario, recording, results and legacy folders)."""
    return Fixtures.make(tmp_path_factory.mktemp("fixtures"))


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """Relative outputs and recorded games land in a scratch folder; the game runs headless."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FCPLAN_DATA_DIR", str(tmp_path))
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    return tmp_path


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
