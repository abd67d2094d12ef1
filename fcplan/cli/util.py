"""Argument types and errors shared by the ``fcplan`` sub-commands.

Every command module of :mod:`fcplan.cli` uses these so that bad arguments read the same
everywhere: one line naming the argument and the allowed range, exit status 2. A command module
defines ``add_parser(sub: SubParsers) -> None``, which adds its parser to the sub-parsers of the
``fcplan`` parser and sets ``run=<function(args) -> int>`` as a default; heavy imports stay inside
``run``.

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
"""

from __future__ import annotations

import argparse
import math
import os
import stat
from pathlib import Path
from typing import NoReturn, TypeAlias

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
    "seed",
    "seed_list",
]


class CliError(FcplanError):
    """A bad command-line argument; ``fcplan`` prints it on one line and exits 2."""


class Parser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors raise :class:`CliError` instead of exiting."""

    def error(self, message: str) -> NoReturn:  # one line, exit 2 (handled in fcplan.cli.main)
        raise CliError(f"{self.prog}: {message}")


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


def scenario_list(text: str) -> list[int | str]:
    """Scenarios as numbers, ranges and names (:func:`fcplan.experiments.parse_range`)."""
    from fcplan.experiments.compare import RangeError, parse_range

    try:
        return parse_range(text)
    except RangeError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


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
