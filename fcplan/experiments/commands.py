"""The ``fcplan sweep`` and ``fcplan report`` commands under their first import path.

They live in :mod:`fcplan.cli.sweep` and :mod:`fcplan.cli.report`; :func:`add_parser` adds both.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> [p.parse_args([c, "x"]).run.__module__ for c in ("sweep", "report")]
['fcplan.cli.sweep', 'fcplan.cli.report']
"""

from __future__ import annotations

import fcplan.cli.report as report
import fcplan.cli.sweep as sweep
from fcplan.cli.util import SubParsers

__all__ = ["add_parser"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan sweep`` and ``fcplan report`` to the ``fcplan`` sub-parsers ``sub``."""
    sweep.add_parser(sub)
    report.add_parser(sub)
