"""The ``fcplan`` parser and entry point: one sub-command per module of :data:`COMMANDS`.

:func:`main` builds the parser (each command module adds its sub-parser and its ``run``), runs
the chosen command and turns every :class:`~fcplan.errors.FcplanError` into one line on stderr and
exit status 2 (``--debug`` shows the traceback instead); so are the failures the environment
causes rather than a bug (an :class:`OSError` such as a full disk, and :class:`MemoryError`).
A message is cut to :data:`MAX_MESSAGE` characters. Ctrl-C exits 130; SIGTERM is handled the same
way (the command stops its workers and keeps what it stored) and exits 143; a closed pipe
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
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator, Sequence
from types import FrameType

import fcplan.cli.compare as compare
import fcplan.cli.import_legacy as import_legacy
import fcplan.cli.leaderboard as leaderboard
import fcplan.cli.play as play
import fcplan.cli.replay as replay
import fcplan.cli.report as report
import fcplan.cli.run as run
import fcplan.cli.scenario as scenario
import fcplan.cli.scenarios as scenarios
import fcplan.cli.sweep as sweep
from fcplan.cli.util import CliError, Parser
from fcplan.errors import FcplanError

__all__ = ["COMMANDS", "COMMAND_MODULES", "MAX_MESSAGE", "Terminated", "build_parser", "main"]

#: Longest error message printed (a message quoting a huge value is cut, still on one line).
MAX_MESSAGE = 1000

#: The command modules, in the order ``fcplan --help`` lists them. Each defines
#: ``add_parser(sub)``, which adds its parser to the sub-parsers ``sub`` (built with
#: ``parser_class=fcplan.cli.util.Parser``) and sets ``run=<function(args) -> int>`` as a default.
COMMANDS = (
    scenarios, scenario, run, compare, play, sweep, report, leaderboard, replay, import_legacy,
)  # fmt: skip

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


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread like Ctrl-C so that commands clean up the same way."""


def _terminate(signum: int, frame: FrameType | None) -> None:
    raise Terminated()


@contextlib.contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """Turn SIGTERM into :class:`Terminated` while a command runs (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _error(message: str) -> int:
    text = " ".join(f"fcplan: error: {message}".split())
    if len(text) > MAX_MESSAGE:
        text = text[: MAX_MESSAGE - 3] + "..."
    print(text, file=sys.stderr)
    return 2


def _os_error(exc: OSError) -> str:
    where = f"{exc.filename}: " if exc.filename else ""
    return f"{where}{exc.strerror or exc}" + (f" (errno {exc.errno})" if exc.errno else "")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``fcplan`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        with _sigterm_as_interrupt():
            args = build_parser().parse_args(argv)
            if getattr(args, "run", None) is not None:
                return int(args.run(args))
            raise CliError(f"unknown command {args.command!r}")  # pragma: no cover
    except FcplanError as exc:
        if debug:
            raise
        return _error(str(exc))
    except MemoryError:
        if debug:
            raise
        return _error("out of memory")
    except Terminated:
        print("fcplan: terminated", file=sys.stderr)
        return 143
    except KeyboardInterrupt:
        print("fcplan: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `fcplan scenarios | head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # the environment (a full disk, a permission), not a bug
        if debug:
            raise
        return _error(_os_error(exc))
