"""Reading scenarios: from a parsed TOML document, a file, or a shipped scenario's name.

:func:`load_scenario` finds the file (:func:`~fcplan.scenario.catalogue.scenario_path`), parses
it as TOML and builds the :class:`~fcplan.scenario.model.Scenario` with
:func:`scenario_from_dict`; the format is documented in :mod:`fcplan.scenario.document`. Every
problem is one :class:`~fcplan.errors.ScenarioError` line naming the file and the field.

Reading is bounded before anything is parsed: only a regular file is opened (a FIFO, a device
such as ``/dev/zero`` or a folder is refused without reading), at most :data:`MAX_FILE_BYTES`
(2 MiB) of it, and TOML nesting deeper than :data:`~fcplan.scenario.bounds.MAX_DEPTH` levels is
refused by a linear scan of the text before the recursive TOML parser sees it. The parsed
document then goes through :func:`fcplan.scenario.bounds.check_document` (sizes, team counts)
before it is read. :func:`read_text` is the same bounded reader for other small TOML files
(sweep configurations).

Examples
--------
>>> s = load_scenario("#7")
>>> load_scenario(7) == load_scenario("07") == s
True
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from collections.abc import Mapping
from typing import Any

from fcplan.errors import ScenarioError
from fcplan.scenario.bounds import MAX_DEPTH, check_document, format_bytes
from fcplan.scenario.catalogue import scenario_path
from fcplan.scenario.model import Scenario

__all__ = ["load_scenario", "scenario_from_dict", "read_text", "parse_toml", "MAX_FILE_BYTES"]

MAX_FILE_BYTES = 2 * 2**20
"""Largest scenario (or sweep) file read, in bytes: a 10,000-agent team with per-agent values
is about 1 MiB, and parsing 2 MiB of TOML takes at most a few seconds."""

# Strings and key parts of TOML, and the tokens that open or close a nesting level. Dotted keys
# (``a.b.c = 1``, ``[a."b".c]``) nest too, and the TOML parser takes time quadratic in their
# length, so they are counted like brackets.
_BASIC = r'"(?:[^"\\\n]|\\.)*"'
_LITERAL = r"'[^'\n]*'"
_PART = rf"(?:[A-Za-z0-9_-]+|{_BASIC}|{_LITERAL})"
_TOKENS = re.compile(
    r'"""(?:[^\\]|\\[\s\S])*?"""{1,3}'  # multi-line basic string (with escapes)
    r"|'''[\s\S]*?'''{1,3}"  # multi-line literal string
    rf"|(?P<dotted>{_PART}(?:[ \t]*\.[ \t]*{_PART})+)"  # a dotted key (or a float: 2 parts)
    rf"|{_BASIC}|{_LITERAL}"
    r"|#[^\n]*"  # comment
    r"|[\[\]{}]"
)
_PARTS = re.compile(_PART)


def read_text(path: str | os.PathLike[str], max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes`` bytes.

    The file is opened without blocking and checked with ``fstat`` before a byte is read, so a
    FIFO, a device (``/dev/zero``), a folder or a file larger than ``max_bytes`` is refused at
    once, whatever it is named.

    Raises
    ------
    ScenarioError
        Field ``file``, the source set to ``path``: no such file, not a regular file, too large,
        unreadable, not UTF-8.

    Examples
    --------
    >>> read_text("/dev/zero")
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: /dev/zero: file: is not a regular file (a character device)
    """
    source = str(path)

    def fail(problem: str) -> ScenarioError:
        return ScenarioError("file", problem, source=source)

    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise fail("no such file") from None
    except OSError as err:
        raise fail(f"cannot be opened: {err.strerror or err}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise fail(f"is not a regular file ({_kind(mode)})")
        data = os.read(fd, max_bytes + 1)
        while len(data) <= max_bytes:
            more = os.read(fd, max_bytes + 1 - len(data))
            if not more:
                break
            data += more
    except OSError as err:
        raise fail(f"cannot be read: {err.strerror or err}") from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise fail(f"is larger than {format_bytes(max_bytes)}; not a scenario file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise fail(f"cannot be read as UTF-8 text: {err}") from None


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a plain file"


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """Parse TOML ``text`` after checking, in one linear scan, that arrays, inline tables and
    dotted keys nest at most :data:`~fcplan.scenario.bounds.MAX_DEPTH` levels (the parser
    recurses on the first two and is quadratic in the length of the third).

    Raises
    ------
    ScenarioError
        Field ``toml``: too deep, or not valid TOML.

    Examples
    --------
    >>> parse_toml("x = " + "[" * 100_000, "deep.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: deep.toml: toml: arrays, inline tables and dotted keys nest more ...
    """
    depth = 0
    for m in _TOKENS.finditer(text):
        c = m.group()
        levels = depth + 1 if c in "[{" else 0
        if m.group("dotted") is not None:
            levels = depth + len(_PARTS.findall(c))
        if levels > MAX_DEPTH:
            line = text.count("\n", 0, m.start()) + 1
            raise ScenarioError(
                "toml",
                f"arrays, inline tables and dotted keys nest more than {MAX_DEPTH} levels deep "
                f"(line {line}); a scenario needs at most 5",
                source=source,
            )
        if c in "[{":
            depth += 1
        elif c in "]}":
            depth = max(depth - 1, 0)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ScenarioError("toml", f"not valid TOML: {err}", source=source) from None
    except RecursionError:  # the scan above should make this unreachable
        raise ScenarioError("toml", "nested too deeply to parse", source=source) from None


def scenario_from_dict(doc: Mapping[str, Any], source: str | None = None) -> Scenario:
    """Build and validate a :class:`Scenario` from a TOML document (:mod:`fcplan.scenario.document`).

    The same as :meth:`Scenario.from_dict <fcplan.scenario.model.Scenario.from_dict>`: ``doc`` is
    the parsed TOML document, ``source`` the file name for error messages and
    :attr:`Scenario.source`; a :class:`~fcplan.errors.ScenarioError` names the field.

    Examples
    --------
    >>> doc = load_scenario("practice").to_dict()
    >>> scenario_from_dict(doc, "copy.toml").source
    'copy.toml'
    >>> doc["duration_s"] = 0
    >>> scenario_from_dict(doc, "copy.toml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.errors.ScenarioError: copy.toml: duration_s: must be a number > 0 ...
    """
    label = source or (
        doc.get("name") if isinstance(doc, Mapping) and isinstance(doc.get("name"), str) else None
    )
    try:
        check_document(doc)
    except ScenarioError as err:
        raise (err.with_source(label) if label else err) from None
    return Scenario.from_dict(doc, source)


def load_scenario(name_or_path: str | int | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario by name or from a TOML file.

    Parameters
    ----------
    name_or_path : str, int or path-like
        A shipped scenario (``12``, ``"12"``, ``"#12"``, ``"01"``, ``"practice"``, ``0``) or a
        ``.toml`` file.

    Raises
    ------
    UnknownNameError
        For an unknown name.
    ScenarioError
        If the file is missing, is not a regular file of at most :data:`MAX_FILE_BYTES`, is not
        valid TOML (or nests too deeply) or describes an invalid scenario. The one-line message
        names the file and the field.

    Examples
    --------
    >>> load_scenario("#24").regions[2].cell
    'A-12'
    """
    path = scenario_path(name_or_path)
    source = str(path)
    try:
        text = read_text(path)
    except ScenarioError as err:
        if err.problem == "no such file":
            raise ScenarioError("file", "no such scenario file", source=source) from None
        raise
    return scenario_from_dict(parse_toml(text, source), source)
