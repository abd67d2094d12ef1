"""``fcplan scenario validate FILE [FILE...]``: check scenario files; list manual limits exceeded.

Each argument (a TOML file or a shipped scenario's name) is loaded and validated; an invalid one
stops the command with its one-line error (exit status 2). A valid one prints ``valid, within the
manual's limits`` or the limits of the manual's open-world GUI it exceeds, one per line
(:meth:`fcplan.scenario.Scenario.manual_limit_violations`).

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["scenario", "validate", "12", "my.toml"]).files
['12', 'my.toml']
"""

from __future__ import annotations

import argparse

from fcplan.cli.util import Parser, SubParsers

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan scenario validate`` to the ``fcplan`` sub-parsers ``sub``."""
    sc = sub.add_parser("scenario", help="scenario file tools")
    scs = sc.add_subparsers(dest="scenario_command", required=True, parser_class=Parser)
    v = scs.add_parser("validate", help="validate scenario files and list manual limits exceeded")
    v.add_argument("files", nargs="+", help="TOML files or shipped scenario names")
    v.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Validate ``args.files`` in order and print one report per file."""
    from fcplan.scenario import load_scenario

    for f in args.files:
        s = load_scenario(f)
        over = s.manual_limit_violations()
        if over:
            print(f"{f}: valid; exceeds {len(over)} manual limit(s):")
            for line in over:
                print(f"  - {line}")
        else:
            print(f"{f}: valid, within the manual's limits")
    return 0
