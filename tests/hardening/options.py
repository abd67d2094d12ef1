"""Argument abuse generated from the ``fcplan`` parser itself: every command, every option.

:func:`option_cases` walks :func:`fcplan.cli.parser.build_parser` (so a new command or option is
covered the day it is added) and, for every option or positional that takes a value, puts each
of :data:`HOSTILE` in its place in a cheap, valid base command of that command
(:func:`base_commands`: a 3-s scenario, the idle scheduler, a 3-s recording, a two-episode results
folder, a 12-s legacy folder). Each case must end in one line on stderr and exit 2, or run
(exit 0), within bounds: :mod:`tests.hardening.runner` runs and classifies them.

Output options (``--json``, ``--record``, ``--video``, ...) are not given the FIFO: writing into
a named pipe waits for its reader, as it does for every Unix tool (``fcplan compare --json
>(jq .)`` relies on it), so a FIFO without a reader is the caller's hang, not fcplan's. Nor are
they given the system's ``/dev/zero`` and ``/dev/null``: a writer that replaces its target
(write a temporary file, rename it) would replace the device itself when run as root. They get a
private character device instead (``{node}``, a copy of ``/dev/null`` made in the fixtures
folder when ``mknod`` is permitted), which shows the same fault harmlessly.

Examples
--------
>>> import tempfile
>>> fx = Fixtures.make(tempfile.mkdtemp(), build=False)
>>> cases = option_cases(fx)
>>> ["run", fx.scenario, "-s", "idle", "--seed", "nan"] in [c.argv for c in cases]
True
>>> sorted({c.command for c in cases})  # doctest: +NORMALIZE_WHITESPACE
['compare', 'import-legacy', 'play', 'replay', 'report', 'run', 'scenario validate',
 'scenarios', 'sweep']
"""

from __future__ import annotations

import argparse
import os
import stat
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "HOSTILE",
    "NOT_FOR_OUTPUTS",
    "OUTPUTS",
    "Fixtures",
    "OptionCase",
    "base_commands",
    "option_cases",
]

#: Values every option and positional is given: special floats, signs, zero, the tiny and the
#: huge, numbers beyond float and int64, not numbers, empty, special files and folders
#: (placeholders in braces are :class:`Fixtures` fields).
HOSTILE: tuple[str, ...] = (
    "nan", "inf", "-inf", "-1", "0", "1e-300", "1e300", "1e999", "99999999999999999999",
    "0x10", "x", "", " ", "1,", "0-99999999999", "-", "/dev/zero", "/dev/null",
    "/nonexistent/dir/x", "{folder}", "{fifo}", "{big}", "{deep}", "{node}",
)  # fmt: skip
#: Values never given to an output option (see the module docstring).
NOT_FOR_OUTPUTS = frozenset({"{fifo}", "/dev/zero", "/dev/null"})
#: Options naming a file or folder fcplan writes.
OUTPUTS = frozenset(
    {"--json", "--csv", "--record", "--video", "--screenshot", "--out", "--results"}
)


@dataclass(frozen=True)
class Fixtures:
    """Valid inputs of every command, and special files, in one folder."""

    folder: str
    scenario: str  # practice, 3 simulated seconds
    study: str  # a sweep file: that scenario, idle, seeds 0-1
    results: str  # the results folder of that sweep
    recording: str  # 3 s of greedy
    legacy: str  # a 12-s synthetic 2020 GUI folder
    fifo: str
    big: str  # a sparse 1 GiB file
    deep: str  # a TOML file nesting arrays 50,000 deep
    node: str  # a character device like /dev/null (a regular empty file where mknod is refused)

    @classmethod
    def make(cls, folder: str | os.PathLike[str], build: bool = True) -> Fixtures:
        """Write the fixtures into ``folder`` (``build=False``: only name them)."""
        d = Path(folder)
        fx = cls(*(str(d / n) for n in ("", "short.toml", "study.toml", "results", "short.npz",
                                        "legacy", "fifo", "big.bin", "deep.toml", "null")))  # fmt: skip
        if build:
            fx._build()
        return fx

    def _build(self) -> None:
        from fcplan import load_scenario
        from fcplan.experiments import sweep
        from fcplan.scenario.write import dump_scenario
        from tests.fuzz.cases import mini_legacy_folder, short_recording

        os.makedirs(self.folder, exist_ok=True)
        dump_scenario(load_scenario("practice").replace(duration_s=3.0), self.scenario)
        Path(self.study).write_text(
            f'scenarios = ["{self.scenario}"]\nschedulers = ["idle"]\nseeds = "0-1"\n',
            encoding="utf-8",
        )
        sweep(self.study, self.results, jobs=1, progress=False)
        short_recording(self.recording)
        mini_legacy_folder(self.legacy)
        os.mkfifo(self.fifo)
        with open(self.big, "wb") as fh:
            fh.truncate(2**30)
        Path(self.deep).write_text('name = "x"\nnotes = ' + "[" * 50_000 + "]" * 50_000 + "\n")
        try:
            os.mknod(self.node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        except (OSError, AttributeError):  # not permitted here
            Path(self.node).write_bytes(b"")

    def fill(self, value: str) -> str:
        """``value`` with its placeholder replaced by the fixture's path."""
        names = ("folder", "fifo", "big", "deep", "node")
        return value.format(**{k: getattr(self, k) for k in names})


def base_commands(fx: Fixtures) -> dict[str, list[str]]:
    """A cheap valid invocation of every command (each runs in about a second)."""
    out = os.path.join(fx.folder, "out")
    return {
        "scenarios": ["scenarios"],
        "scenario validate": ["scenario", "validate", fx.scenario],
        "run": ["run", fx.scenario, "-s", "idle"],
        "compare": [
            "compare",
            "--schedulers",
            "idle",
            "--scenarios",
            fx.scenario,
            "--seeds",
            "0",
            "--jobs",
            "1",
            "-q",
        ],  # fmt: skip
        "play": ["play", "--scenario", fx.scenario, "--screenshot", out + ".png"],
        "sweep": ["sweep", fx.study, "--results", fx.results, "--jobs", "1", "-q"],
        "report": ["report", fx.results, "--out", out + "-report"],
        "replay": ["replay", fx.recording, "--video", out + ".gif", "--size", "64"],
        "import-legacy": ["import-legacy", fx.legacy, "--out", out + "-legacy.npz"],
    }


@dataclass(frozen=True)
class OptionCase:
    """One generated case: the command, the option (or positional) and the hostile value."""

    command: str
    option: str
    value: str
    argv: list[str]


def _commands(p: argparse.ArgumentParser, prefix: tuple[str, ...] = ()) -> Iterator:
    """(command words, its parser) for every leaf command of ``p``."""
    subs = [a for a in p._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield prefix, p
    for a in subs:
        for name, sp in a.choices.items():
            yield from _commands(sp, (*prefix, name))


def _with(base: list[str], action: argparse.Action, n_words: int, value: str) -> list[str]:
    """``base`` with ``action``'s value replaced by ``value`` (or the option added)."""
    argv = list(base)
    if not action.option_strings:  # a positional: the first word after the command words
        argv[n_words] = value
        return argv
    for opt in action.option_strings:
        if opt in argv:
            argv[argv.index(opt) + 1] = value
            return argv
    return [*argv, f"{action.option_strings[0]}={value}"]  # "=": values starting with "-"


def option_cases(fx: Fixtures) -> list[OptionCase]:
    """Every (command, value-taking option or positional, hostile value) case."""
    from fcplan.cli.parser import build_parser

    bases = base_commands(fx)
    cases = []
    for words, parser in _commands(build_parser()):
        command = " ".join(words)
        base = bases[command]
        for action in parser._actions:
            if action.nargs == 0 or isinstance(action, argparse._HelpAction):
                continue
            name = action.option_strings[0] if action.option_strings else action.dest
            for value in HOSTILE:
                if value in NOT_FOR_OUTPUTS and name in OUTPUTS:
                    continue  # see the module docstring
                argv = _with(base, action, len(words), fx.fill(value))
                cases.append(OptionCase(command, name, value, argv))
    return cases
