"""``fcplan schedulers``: the registered schedulers, what each does, and its settings.

::

    fcplan schedulers [NAME ...] [--json]

Without a name: one block per registered scheduler (built-ins, plug-ins of the
``fcplan.schedulers`` entry-point group, run-time registrations), its one-line description and
its settings with their defaults. With names: the same plus each setting's documentation. A
setting goes on the command line as a spec, ``fcplan run 12 -s routing:max_visits=3``.

Everything comes from the registry, not from a list kept here: the description is the factory's
``description`` attribute or else the summary line of its docstring (references such as "see the
module docstring" dropped), the settings are the factory's keyword parameters with their defaults
(:func:`inspect.signature`), and their documentation is the numpydoc ``Parameters`` section of its
docstring. A factory that takes ``**settings`` (``milp``'s model settings, ``oracle``'s inner
scheduler's) shows that entry with its documentation; a factory can list them all by setting
``__signature__``. A plug-in that cannot be loaded is listed with the reason instead of failing
the command.

Examples
--------
>>> info = describe("greedy")
>>> info["description"]
'Sequential best-ratio assignment.'
>>> info["settings"]["route_length"]["default"]
3
>>> _summary(":class:`Foo` searched by ``x`` (see the module docstring).")
'Foo searched by x.'
"""

from __future__ import annotations

import argparse
import inspect
import json
import re
import textwrap
from typing import Any

from fcplan.cli.util import SubParsers

__all__ = ["add_parser", "describe", "run"]

_WIDTH = 100
_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
_LITERAL = re.compile(r"``([^`]+)``")
_SEE_DOC = re.compile(r"\s*\((?:see )?(?:the )?module docstring\)", re.IGNORECASE)


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan schedulers`` to the ``fcplan`` sub-parsers ``sub``."""
    p = sub.add_parser(
        "schedulers",
        help="list the registered schedulers, what each does and its settings",
        description="List the registered schedulers with a one-line description and their "
        "settings (defaults); name some to see each setting's documentation. Settings go on "
        "the command line as NAME:KEY=VALUE, e.g. fcplan run 12 -s routing:max_visits=3.",
    )
    p.add_argument("names", nargs="*", metavar="NAME", help="describe only these, in detail")
    p.add_argument("--json", action="store_true", help="print the same as one JSON document")
    p.set_defaults(run=run)


def _plain(text: str) -> str:
    """Docstring markup (roles, literals) as plain text, on one line."""
    return " ".join(_LITERAL.sub(r"\1", _ROLE.sub(r"\1", text)).split())


def _summary(doc: str) -> str:
    """The first paragraph of a docstring as one plain sentence, without "see the module
    docstring"."""
    first = doc.strip().split("\n\n")[0]
    text = _SEE_DOC.sub("", _plain(first)).strip()
    return text if not text or text.endswith(".") else text + "."


_SECTIONS = {"Returns", "Raises", "Examples", "Notes", "Attributes", "See Also", "Yields"}


def _parameter_docs(doc: str) -> dict[str, str]:
    r"""Parameter name -> its description, from a numpydoc ``Parameters`` section.

    Examples
    --------
    >>> _parameter_docs("Parameters\n----------\na, b : int\n    Two ``ints``.\nc : str")
    {'a': 'Two ints.', 'b': 'Two ints.', 'c': ''}
    """
    lines = doc.splitlines()
    heads = [
        i
        for i, ln in enumerate(lines[:-1])
        if ln.strip() == "Parameters" and set(lines[i + 1].strip()) == {"-"}
    ]
    out: dict[str, str] = {}
    if not heads:
        return out
    names: list[str] = []
    body: list[str] = []
    for line in [*lines[heads[0] + 2 :], "Returns"]:
        if line and not line[0].isspace():  # "name : type", or the next section's title
            out.update((name, _plain(" ".join(body))) for name in names)
            if line.strip() in _SECTIONS:
                break
            names = [n.strip() for n in line.split(" : ")[0].split(",") if n.strip()]
            body = []
        elif line.strip():
            body.append(line.strip())
    return out


def describe(name: str) -> dict[str, Any]:
    """What the registry knows about the scheduler ``name``.

    Returns
    -------
    dict
        ``name``, ``description``, ``deterministic`` (whether it offers a ``deterministic``
        mode), ``settings`` (setting -> ``{"default": ..., "doc": ...}``; a ``**settings``
        entry has no default) and, for a plug-in that fails to load, ``error``.
    """
    from fcplan.errors import FcplanError
    from fcplan.scheduling import scheduler_factory, supports_deterministic

    try:
        factory = scheduler_factory(name)
    except FcplanError as exc:
        return {"name": name, "description": "", "settings": {}, "error": str(exc)}
    doc = inspect.getdoc(factory) or ""
    given = getattr(factory, "description", None)
    description = given if isinstance(given, str) else _summary(doc)
    docs = _parameter_docs(doc)
    settings: dict[str, dict[str, Any]] = {}
    try:
        params = list(inspect.signature(factory).parameters.values())
    except (TypeError, ValueError):
        params = []
    for p in params:
        if p.kind is p.VAR_KEYWORD:
            settings[f"**{p.name}"] = {"default": None, "doc": docs.get(f"**{p.name}", "")}
        elif p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY):
            default = None if p.default is p.empty else p.default
            settings[p.name] = {"default": default, "doc": docs.get(p.name, "")}
    return {
        "name": name,
        "description": description,
        "deterministic": supports_deterministic(name),
        "settings": settings,
    }


def _setting_line(key: str, info: dict[str, Any]) -> str:
    return key if key.startswith("**") else f"{key}={info['default']!r}"


def _format(info: dict[str, Any], detail: bool) -> list[str]:
    """The lines of one scheduler's block."""
    head = f"{info['name']:<14} "
    if "error" in info:
        return [head + f"(cannot be loaded: {info['error']})"]
    mode = " Has a deterministic mode (deterministic=true)." if info["deterministic"] else ""
    lines = textwrap.wrap(
        info["description"] + mode,
        _WIDTH,
        initial_indent=head,
        subsequent_indent=" " * len(head),
    )
    settings = info["settings"]
    if not settings:
        return [*lines, " " * len(head) + "settings: none"]
    if not detail:
        text = "settings: " + ", ".join(_setting_line(k, v) for k, v in settings.items())
        indent = " " * len(head)
        return lines + textwrap.wrap(
            text, _WIDTH, initial_indent=indent, subsequent_indent=indent + "  "
        )
    for key, value in settings.items():
        lines.append("  " + _setting_line(key, value))
        if value["doc"]:
            lines += textwrap.wrap(
                value["doc"], _WIDTH, initial_indent=" " * 6, subsequent_indent=" " * 6
            )
    return lines


def run(args: argparse.Namespace) -> int:
    """Print the registered schedulers (or the named ones, in detail)."""
    from fcplan.scheduling import available_schedulers, scheduler_factory

    names = args.names or available_schedulers()
    for name in args.names:
        scheduler_factory(name)  # an unknown name: one line listing the known ones
    infos = [describe(n) for n in names]
    if args.json:
        print(json.dumps(infos, indent=2, default=repr))
        return 0
    for k, info in enumerate(infos):
        if k and args.names:
            print()
        print("\n".join(_format(info, detail=bool(args.names))))
    return 0
