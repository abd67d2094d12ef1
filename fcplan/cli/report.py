"""``fcplan report RESULTS``: tables, paired comparisons, rankings and plots from sweep results.

::

    fcplan report RESULTS [--out DIR] [--html] [--metric NAME ...] [--study HASH | --allow-mixed]

Runs :func:`fcplan.experiments.report.report` and prints the Markdown report; the files written
(default folder ``RESULTS/report``) are listed on stderr. A folder holding the episodes of
several studies (different sweep grids) is refused with one line naming them: choose one with
``--study HASH``, or pool them with ``--allow-mixed`` (the report then says so).

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["report", "results/study"]).metric is None
True
"""

from __future__ import annotations

import argparse
import sys

from fcplan.cli.util import SubParsers

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan report`` to the ``fcplan`` sub-parsers ``sub``."""
    r = sub.add_parser(
        "report", help="tables, paired comparisons, rankings and plots from a sweep's results"
    )
    r.add_argument("results", help="results folder written by fcplan sweep")
    r.add_argument(
        "--out", metavar="DIR", default=None, help="output folder (default RESULTS/report)"
    )
    r.add_argument("--html", action="store_true", help="also write report.html")
    r.add_argument(
        "--metric",
        action="append",
        metavar="NAME",
        help="metric of the paired comparisons (repeatable; the first is the headline of the "
        "plots and the fraction of the oracle; default manual.final_score)",
    )
    r.add_argument(
        "--study", metavar="HASH", default=None, help="report only this study of the folder"
    )
    r.add_argument(
        "--allow-mixed",
        action="store_true",
        help="pool the episodes of several studies in the folder (the report says so)",
    )
    r.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Write the report and print its Markdown."""
    from fcplan.experiments.report import report

    rep = report(
        args.results,
        out=args.out,
        html=args.html,
        metric=args.metric or ["manual.final_score"],
        study=args.study,
        allow_mixed=args.allow_mixed,
    )
    print(rep.markdown, end="")
    print(f"written: {', '.join(str(p) for p in rep.files)}", file=sys.stderr)
    return 0
