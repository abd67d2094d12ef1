"""Tests of fcplan.cli.parser: the command table, one-line errors with exit status 2, and the
entry points (console script, python -m fcplan, python -m fcplan.cli)."""

from __future__ import annotations

import argparse
import ast
import inspect
import json
import subprocess
import sys
from pathlib import Path

import fcplan
import fcplan.cli.parser as parser
from fcplan.cli import COMMAND_MODULES, main
from tests.cli.helpers import one_line_error


def test_bad_input_gives_one_line_and_exit_2(tmp_path, capsys):
    """Unknown scenario/scheduler, bad numbers and bad files print one line and exit 2."""
    one_line_error(["run", "99"], capsys, "99", "practice")
    one_line_error(["run", "1", "--scheduler", "nope"], capsys, "nope", "greedy")
    one_line_error(["run", "1", "--seed", "-3"], capsys, "seed", "-3")
    one_line_error(["run", "1", "--replan-period", "0"], capsys, "replan-period")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nworld_size = -5\n')
    one_line_error(["scenario", "validate", str(bad)], capsys, "bad.toml")
    one_line_error(["frobnicate"], capsys, "frobnicate")


def test_console_entry_point_runs_as_module():
    """`python -m fcplan run` works and errors exit 2 without a traceback."""
    ok = subprocess.run(
        [sys.executable, "-m", "fcplan", "run", "3", "-s", "idle", "--json"],
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0 and json.loads(ok.stdout)["scenario"] == "#3"
    bad = subprocess.run(
        [sys.executable, "-m", "fcplan", "run", "nope"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert len(bad.stderr.strip().splitlines()) == 1


def test_every_command_has_its_module_in_help_order(capsys):
    """Each command module adds one sub-command with a run function; `fcplan --help` lists them
    in COMMAND_MODULES order."""
    sub = parser.build_parser()._subparsers._group_actions[0]
    assert list(sub.choices) == [
        "scenarios", "scenario", "schedulers", "run", "compare", "play", "sweep", "report",
        "leaderboard", "verify", "replay", "import-legacy",
    ]  # fmt: skip
    assert tuple(m.__name__ for m in parser.COMMANDS) == COMMAND_MODULES
    for module in parser.COMMANDS:
        assert callable(module.add_parser) and callable(module.run), module.__name__
        assert module.__name__.startswith("fcplan.cli.")


def test_run_defaults_point_at_the_command_modules():
    """Parsing a command line sets ``run`` to the run function of that command's module."""
    p = parser.build_parser()
    cases = {
        ("scenarios",): "fcplan.cli.scenarios",
        ("scenario", "validate", "1"): "fcplan.cli.scenario",
        ("schedulers",): "fcplan.cli.schedulers",
        ("run", "1"): "fcplan.cli.run",
        ("compare", "--schedulers", "greedy"): "fcplan.cli.compare",
        ("play",): "fcplan.cli.play",
        ("sweep", "x.toml"): "fcplan.cli.sweep",
        ("report", "dir"): "fcplan.cli.report",
        ("leaderboard", "dir"): "fcplan.cli.leaderboard",
        ("verify", "dir"): "fcplan.cli.verify",
        ("replay", "x.npz"): "fcplan.cli.replay",
        ("import-legacy", "dir"): "fcplan.cli.import_legacy",
    }
    for argv, module in cases.items():
        assert p.parse_args(list(argv)).run.__module__ == module, argv


def test_python_m_fcplan_cli_runs_main():
    """`python -m fcplan.cli` is the same entry point as `python -m fcplan`."""
    out = subprocess.run(
        [sys.executable, "-m", "fcplan.cli", "scenario", "validate", "nope.toml"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 2
    assert out.stderr == "fcplan: error: nope.toml: file: no such scenario file\n"


def test_old_import_paths_export_the_same_objects():
    """fcplan.cliutil, fcplan.game.cli and fcplan.experiments.commands export the cli objects."""
    import fcplan.cli.play as play
    import fcplan.cli.util as util
    import fcplan.cliutil as cliutil
    import fcplan.experiments.commands as commands
    import fcplan.game.cli as game_cli
    from fcplan.cli.util import Parser

    for name in cliutil.__all__:
        assert getattr(cliutil, name) is getattr(util, name), name
    assert game_cli.add_parser is play.add_parser and game_cli.run is play.run
    p = Parser(prog="fcplan")
    commands.add_parser(p.add_subparsers(dest="command", parser_class=Parser))
    assert p.parse_args(["report", "r"]).run.__module__ == "fcplan.cli.report"


def test_library_modules_hold_no_argparse_code():
    """No module of fcplan.legacy, fcplan.experiments, fcplan.game, nor fcplan.replay and
    fcplan.video, imports argparse or builds an argument parser: the commands live in
    fcplan.cli."""
    root = Path(fcplan.__file__).parent
    files = [*(root / "legacy").glob("*.py"), *(root / "experiments").glob("*.py")]
    files += [*(root / "game").glob("*.py"), root / "replay.py", root / "video.py"]
    for path in files:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        names = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
        assert "argparse" not in names, path
        calls = {ast.unparse(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
        assert not {c for c in calls if c.endswith("add_argument")}, path


def test_fcplan_cli_init_only_exposes_main():
    """fcplan.cli exposes main (the console script fcplan.cli:main) and the command table."""
    import fcplan.cli

    assert fcplan.cli.main is parser.main and inspect.isfunction(main)
    assert set(fcplan.cli.__all__) == {"COMMAND_MODULES", "main"}


def _parsers(p):
    """``p`` and every sub-parser below it."""
    yield p
    for action in p._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                yield from _parsers(child)


def test_no_parser_abbreviates_options(capsys):
    """No parser takes a prefix of an option for the option (``compare --seed 3`` used to fill
    every cell with nan as ``--seeds 3``); the error names the command and the option meant."""
    assert all(not q.allow_abbrev for q in _parsers(parser.build_parser()))
    one_line_error(
        ["compare", "--seed", "3", "--schedulers", "greedy"],
        capsys,
        "fcplan: error: compare: unrecognized arguments: --seed 3",
        "did you mean --seeds?",
    )
    one_line_error(["run", "1", "--sed", "2"], capsys, "fcplan: error: run:", "--seed")


def test_errors_name_the_command_once(capsys):
    """An argument error reads ``fcplan: error: run: argument --seed: ...``: the command, then
    the problem, without a doubled ``fcplan: error: fcplan run:``."""
    assert main(["run", "1", "--seed", "-1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("fcplan: error: run: argument --seed: expected an integer >= 0")
    assert err.count("fcplan") == 1


def test_bare_fcplan_prints_help_and_a_hint(capsys):
    """A bare ``fcplan`` prints the help (every command) on stdout and one hint line on stderr,
    exit 2."""
    assert main([]) == 2
    out, err = capsys.readouterr()
    assert out.startswith("usage: fcplan")
    for command in parser.build_parser()._subparsers._group_actions[0].choices:
        assert command in out
    assert err == "fcplan: error: a command is needed (see above, or: fcplan run 12)\n"


def test_version_matches_the_distribution(capsys):
    """``fcplan --version`` prints fcplan.__version__, the version pyproject.toml declares."""
    import tomllib

    meta = tomllib.loads((Path(fcplan.__file__).parents[1] / "pyproject.toml").read_text())
    assert fcplan.__version__ == meta["project"]["version"]
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith(f"fcplan {fcplan.__version__} (Python ")


def test_help_returns_zero_and_run_help_lists_the_schedulers(capsys):
    """``--help`` returns 0 (no SystemExit out of main); ``fcplan run --help`` names every
    registered scheduler and points at ``fcplan schedulers``."""
    from fcplan.scheduling import available_schedulers

    assert main(["--help"]) == 0
    assert main(["run", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())
    for name in available_schedulers():
        assert name in out, name
    assert "fcplan schedulers" in out


def test_scenario_zero_is_refused(capsys):
    """``fcplan run 0`` (and ``#0``, ``00``, a 0 in --scenarios) is an error naming the allowed
    scenarios instead of quietly playing practice; ``practice`` by name still works."""
    for text in ("0", "#0", "00"):
        one_line_error(["run", text], capsys, f"no scenario '{text}'", "practice and 1..24")
    one_line_error(["compare", "--schedulers", "idle", "--scenarios", "0-2"], capsys, "'0'")
    one_line_error(["play", "--scenario", "0"], capsys, "no scenario '0'")
    assert parser.build_parser().parse_args(["run", "practice"]).scenario == "practice"
