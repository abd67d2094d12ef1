"""The ``fcplan`` parser and entry point: one sub-command per module of :data:`COMMANDS`.

:func:`main` builds the parser (each command module adds its sub-parser and its ``run``), runs
the chosen command and turns every :class:`~fcplan.errors.FcplanError` into one line on stderr and
exit status 2 (``--debug`` shows the traceback instead); Ctrl-C exits 130, and a closed pipe
(``fcplan scenarios | head``) ends quietly.

Examples
--------
>>> build_parser().parse_args(["run", "3", "--seed", "2"]).seed
2
>>> main(["run", "3", "--seed", "-1"])
2
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

import fcplan.cli.compare as compare
import fcplan.cli.import_legacy as import_legacy
import fcplan.cli.play as play
import fcplan.cli.replay as replay
import fcplan.cli.report as report
import fcplan.cli.run as run
import fcplan.cli.scenario as scenario
import fcplan.cli.scenarios as scenarios
import fcplan.cli.sweep as sweep
from fcplan.cli.util import CliError, Parser
from fcplan.errors import FcplanError

__all__ = ["COMMANDS", "COMMAND_MODULES", "build_parser", "main"]

#: The command modules, in the order ``fcplan --help`` lists them. Each defines
#: ``add_parser(sub)``, which adds its parser to the sub-parsers ``sub`` (built with
#: ``parser_class=fcplan.cli.util.Parser``) and sets ``run=<function(args) -> int>`` as a default.
COMMANDS = (scenarios, scenario, run, compare, play, sweep, report, replay, import_legacy)

#: The names of the :data:`COMMANDS` modules.
COMMAND_MODULES: tuple[str, ...] = tuple(m.__name__ for m in COMMANDS)


def build_parser() -> argparse.ArgumentParser:
    """The ``fcplan`` parser with every command of :data:`COMMANDS`."""
    p = Parser(prog="fcplan", description="FireCommander multi-robot task assignment testbed")
    p.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``fcplan`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        args = build_parser().parse_args(argv)
        if getattr(args, "run", None) is not None:
            return int(args.run(args))
        raise CliError(f"unknown command {args.command!r}")  # pragma: no cover
    except FcplanError as exc:
        if debug:
            raise
        print(f"fcplan: error: {exc}".replace("\n", " "), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fcplan: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `fcplan scenarios | head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
