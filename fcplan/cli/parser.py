"""The ``fcplan`` parser and entry point: one sub-command per module of :data:`COMMANDS`.

:func:`main` builds the parser (each command module adds its sub-parser and its ``run``), runs
the chosen command and turns every :class:`~fcplan.errors.FcplanError` into one line on stderr and
exit status 2 (``--debug`` shows the traceback instead); so are the failures the environment
causes rather than a bug (an :class:`OSError` such as a full disk, and :class:`MemoryError`).
Every such line starts with ``fcplan: error:`` (what scripts and the hardening audit match),
then the command a bad argument belongs to, once, and the problem: ``fcplan: error: run:
argument --seed: expected an integer >= 0, got '-1'``; a message is cut to :data:`MAX_MESSAGE`
characters. Ctrl-C exits 130; SIGTERM is handled the
same way (the command stops its workers and keeps what it stored) and exits 143; a closed pipe
(``fcplan scenarios | head``) ends quietly. A bare ``fcplan`` prints the help on stdout and a
one-line hint on stderr (exit 2); ``--help`` and ``--version`` return 0.

Start-up is part of the interface: building the parser imports only the command modules, which
import nothing heavy at module level (numpy, scipy, networkx, pandas, pygame and the solvers load
inside ``run``), so ``fcplan --help`` and ``fcplan scenarios`` start in a fraction of a second
(``bench/bench_startup.py``; ``tests/cli/test_cli_startup.py`` checks the imports).

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
import fcplan.cli.schedulers as schedulers
import fcplan.cli.sweep as sweep
import fcplan.cli.verify as verify
from fcplan.cli.util import CliError, Parser
from fcplan.errors import FcplanError

__all__ = ["COMMANDS", "COMMAND_MODULES", "MAX_MESSAGE", "Terminated", "build_parser", "main"]

#: Longest error message printed (a message quoting a huge value is cut, still on one line).
MAX_MESSAGE = 1000

#: The command modules, in the order ``fcplan --help`` lists them. Each defines
#: ``add_parser(sub)``, which adds its parser to the sub-parsers ``sub`` (built with
#: ``parser_class=fcplan.cli.util.Parser``) and sets ``run=<function(args) -> int>`` as a default.
COMMANDS = (
    scenarios,
    scenario,
    schedulers,
    run,
    compare,
    play,
    sweep,
    report,
    leaderboard,
    verify,
    replay,
    import_legacy,
)

#: The names of the :data:`COMMANDS` modules.
COMMAND_MODULES: tuple[str, ...] = tuple(m.__name__ for m in COMMANDS)


def build_parser() -> argparse.ArgumentParser:
    """The ``fcplan`` parser with every command of :data:`COMMANDS`."""
    from fcplan import __version__

    p = Parser(
        prog="fcplan",
        description="FireCommander multi-robot task assignment testbed",
        epilog="fcplan COMMAND --help describes a command; start with: fcplan run 12",
    )
    p.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    p.add_argument(
        "--version",
        action="version",
        version=f"fcplan {__version__} (Python {sys.version.split()[0]})",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
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


def _unrecognized(
    parser: argparse.ArgumentParser, args: argparse.Namespace, extras: list[str]
) -> CliError:
    """The error for arguments no parser took, naming the command and the closest options
    (``fcplan: error: compare: unrecognized arguments: --seed 3 (did you mean --seeds?)``)."""
    import difflib

    command = parser
    sub = getattr(parser, "_subparsers", None)
    if sub is not None and getattr(args, "command", None):
        command = sub._group_actions[0].choices.get(args.command, parser)
    options = [o for a in command._actions for o in a.option_strings if o.startswith("--")]
    hints = {
        extra: difflib.get_close_matches(extra.split("=")[0], options, n=1, cutoff=0.6)
        for extra in extras
        if extra.startswith("-")
    }
    close = {e.split("=")[0]: m[0] for e, m in hints.items() if m}
    if len(close) == 1:
        hint = f" (did you mean {next(iter(close.values()))}?)"
    else:
        hint = f" (did you mean {', '.join(f'{m} for {e}' for e, m in close.items())}?)"
    hint = hint if close else ""
    return CliError(f"unrecognized arguments: {' '.join(extras)}{hint}", prog=command.prog)


def _error(message: str, prog: str = "fcplan") -> int:
    """Print ``fcplan: error: [COMMAND: ]MESSAGE`` on one line of stderr; return 2."""
    command = prog.removeprefix("fcplan").strip()
    text = " ".join(f"fcplan: error: {command + ': ' if command else ''}{message}".split())
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
            parser = build_parser()
            try:
                args, extras = parser.parse_known_args(argv)
            except SystemExit as exc:  # --help, --version
                return exc.code if isinstance(exc.code, int) else 0
            if extras:
                raise _unrecognized(parser, args, extras)
            if getattr(args, "run", None) is None:  # a bare `fcplan` (or only --debug)
                print(parser.format_help(), end="")
                raise CliError("a command is needed (see above, or: fcplan run 12)", prog="fcplan")
            return int(args.run(args))
    except CliError as exc:
        if debug:
            raise
        return _error(exc.message, exc.prog or "fcplan")
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
