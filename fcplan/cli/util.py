"""Argument types and errors shared by the ``fcplan`` sub-commands.

Every command module of :mod:`fcplan.cli` uses these so that bad arguments read the same
everywhere: one line naming the argument and the allowed range, exit status 2. A command module
defines ``add_parser(sub: SubParsers) -> None``, which adds its parser to the sub-parsers of the
``fcplan`` parser and sets ``run=<function(args) -> int>`` as a default; heavy imports stay inside
``run``.

:class:`Parser` never abbreviates options (``--seed`` is not taken for ``--seeds``), raises
:class:`CliError` instead of exiting, and can compute its epilog only when help is shown
(``epilog_fn``: ``fcplan run --help`` lists the registered schedulers without every other
command paying for the entry-point scan).

Examples
--------
>>> positive_int("3")
3
>>> seed_list("0-2")
[0, 1, 2]
>>> Parser(prog="fcplan x").parse_args(["--nope"])
Traceback (most recent call last):
...
fcplan.cli.util.CliError: fcplan x: unrecognized arguments: --nope
>>> p = Parser(prog="fcplan x")
>>> _ = p.add_argument("--seeds")
>>> p.parse_args(["--seed", "3"])
Traceback (most recent call last):
...
fcplan.cli.util.CliError: fcplan x: unrecognized arguments: --seed 3
>>> scenario_name("0")
Traceback (most recent call last):
...
argparse.ArgumentTypeError: no scenario '0': the shipped scenarios are practice and 1..24 (plus the names fcplan scenarios lists) or a .toml file
"""

from __future__ import annotations

import argparse
import math
import os
import re
import stat
from collections.abc import Callable
from typing import Any, NoReturn, TypeAlias

from fcplan.errors import FcplanError

__all__ = [
    "CliError",
    "Parser",
    "SubParsers",
    "check_input",
    "check_output",
    "name_list",
    "positive_float",
    "positive_int",
    "scenario_list",
    "scenario_name",
    "seed",
    "seed_list",
]


class CliError(FcplanError):
    """A bad command-line argument; ``fcplan`` prints it on one line and exits 2.

    Parameters
    ----------
    message : str
        What is wrong and what is allowed.
    prog : str, optional
        The command the argument belongs to (``"fcplan run"``); the printed line then reads
        ``fcplan: error: run: MESSAGE`` and ``str()`` is ``"fcplan run: MESSAGE"``.
    """

    def __init__(self, message: str, *, prog: str | None = None) -> None:
        self.message, self.prog = message, prog
        super().__init__(f"{prog}: {message}" if prog else message)


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors raise :class:`CliError` instead of exiting, which never
    abbreviates long options, and whose epilog may be computed when help is shown.

    Parameters
    ----------
    *args, **kwargs
        As :class:`argparse.ArgumentParser` (``allow_abbrev`` defaults to False).
    epilog_fn : callable, optional
        Returns the epilog; called only by :meth:`format_help`.
    """

    def __init__(
        self, *args: Any, epilog_fn: Callable[[], str] | None = None, **kwargs: Any
    ) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self.epilog_fn = epilog_fn

    def error(self, message: str) -> NoReturn:  # one line, exit 2 (handled in fcplan.cli.main)
        raise CliError(message, prog=self.prog)

    def format_help(self) -> str:
        """The help text, with the epilog from ``epilog_fn`` when there is one."""
        if self.epilog_fn is not None:
            self.epilog = self.epilog_fn()
        return super().format_help()


#: The sub-parsers object (``Parser.add_subparsers(parser_class=Parser)``) a command adds to.
SubParsers: TypeAlias = "argparse._SubParsersAction[Parser]"


def positive_float(text: str) -> float:
    """A number > 0 (finite)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}")
    return v


def seed(text: str) -> int:
    """A random seed: an integer >= 0."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return v


def positive_int(text: str) -> int:
    """An integer >= 1."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}")
    return v


_SCENARIO_ZERO = re.compile(r"#?0+")


def _no_scenario_zero(text: str) -> argparse.ArgumentTypeError:
    return argparse.ArgumentTypeError(
        f"no scenario {text!r}: the shipped scenarios are practice and 1..24 (plus the names "
        "fcplan scenarios lists) or a .toml file"
    )


def scenario_name(text: str) -> str:
    """A scenario as the user wrote it (a name, a number, a path), refusing ``0``: the practice
    scenario is given by name, so that a typo such as ``fcplan run 0`` does not quietly play it
    (the library's :func:`fcplan.load_scenario` keeps accepting ``0``, the practice's number in
    the scenario files)."""
    if _SCENARIO_ZERO.fullmatch(text.strip()):
        raise _no_scenario_zero(text)
    return text


def scenario_list(text: str) -> list[int | str]:
    """Scenarios as numbers, ranges and names (:func:`fcplan.experiments.parse_range`); no ``0``
    (see :func:`scenario_name`)."""
    from fcplan.experiments.compare import RangeError, parse_range

    try:
        items = parse_range(text)
    except RangeError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    for item in items:
        if item == 0 or (isinstance(item, str) and _SCENARIO_ZERO.fullmatch(item.strip())):
            raise _no_scenario_zero(str(item))
    return items


def seed_list(text: str) -> list[int | str]:
    """Seeds as numbers and ranges, e.g. ``0-4`` or ``0,7``."""
    from fcplan.experiments.compare import RangeError, parse_range

    try:
        return parse_range(text, names=False)
    except RangeError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def name_list(text: str) -> list[str]:
    """Comma-separated names, duplicates dropped (first kept)."""
    names = [t.strip() for t in text.split(",")]
    if not text.strip() or any(not t for t in names):
        raise argparse.ArgumentTypeError(f"expected comma-separated names, got {text!r}")
    return list(dict.fromkeys(names))


def check_output(path: str | None, option: str) -> None:
    """Fail before a long run, not after it, when an output file cannot be written."""
    if path is None:
        return
    from pathlib import Path

    p = Path(path)
    if p.is_dir():
        raise CliError(f"{option} {path}: is a directory")
    if not p.parent.is_dir():
        raise CliError(f"{option} {path}: no such directory {str(p.parent)!r}")


def check_input(path: str, what: str, *, folder: bool = False) -> None:
    """Fail at once, without opening it, unless ``path`` is a regular file (or a folder if
    ``folder``): a FIFO would block a reader, a device such as ``/dev/zero`` never ends.

    Examples
    --------
    >>> check_input("/dev/zero", "recording")
    Traceback (most recent call last):
    ...
    fcplan.cli.util.CliError: recording /dev/zero: not a regular file
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise CliError(f"{what} {path}: no such {'folder' if folder else 'file'}") from None
    except OSError as exc:
        raise CliError(f"{what} {path}: {exc.strerror or exc}") from None
    if folder and not stat.S_ISDIR(mode):
        raise CliError(f"{what} {path}: not a folder")
    if not folder and not stat.S_ISREG(mode):
        raise CliError(f"{what} {path}: not a regular file")
