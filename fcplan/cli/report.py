"""``fcplan report RESULTS``: tables, paired Wilcoxon comparisons and plots from a sweep's results.

::

    fcplan report RESULTS [--out DIR] [--html] [--metric NAME]

Runs :func:`fcplan.experiments.report.report` and prints the Markdown report; the files written
(default folder ``RESULTS/report``) are listed on stderr.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["report", "results/study"]).metric
'manual.final_score'
"""

from __future__ import annotations

import argparse
import sys

from fcplan.cli.util import SubParsers

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan report`` to the ``fcplan`` sub-parsers ``sub``."""
    r = sub.add_parser(
        "report", help="tables, paired Wilcoxon comparisons and plots from a sweep's results"
    )
    r.add_argument("results", help="results folder written by fcplan sweep")
    r.add_argument(
        "--out", metavar="DIR", default=None, help="output folder (default RESULTS/report)"
    )
    r.add_argument("--html", action="store_true", help="also write report.html")
    r.add_argument(
        "--metric",
        default="manual.final_score",
        help="metric for the paired comparisons and plots (default manual.final_score)",
    )
    r.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Write the report and print its Markdown."""
    from fcplan.experiments.report import report

    rep = report(args.results, out=args.out, html=args.html, metric=args.metric)
    print(rep.markdown, end="")
    print(f"written: {', '.join(str(p) for p in rep.files)}", file=sys.stderr)
    return 0
