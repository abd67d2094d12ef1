"""``fcplan leaderboard RESULTS``: the benchmark suite's leaderboard page from results.

::

    fcplan leaderboard RESULTS [RESULTS...] [-o FILE] [--metric NAME] [--json PATH]

``RESULTS`` are results folders written by ``fcplan sweep`` (or ``.json`` files of ``fcplan
compare --json``); their episodes are grouped by suite and tier from the scenario names
(``fcplan-bench-v1/hard-01``). The page (:func:`fcplan.experiments.leaderboard_page.markdown`)
ranks every scheduler on every tier by the headline metric (default the manual's final score),
with its interval, the fraction of the oracle, scenarios cleared, solve times, fallbacks, the
paired comparisons and the tier check, and records the suite version, seeds, library versions,
date and the wall time of producing the results. It is printed, or written to ``-o FILE``
(``docs/leaderboard.md``); ``--json`` also writes every number.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["leaderboard", "results/bench-v1", "-o", "docs/leaderboard.md"])
>>> args.results, args.output, args.metric
(['results/bench-v1'], 'docs/leaderboard.md', 'manual.final_score')
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys

from fcplan.cli.util import CliError, SubParsers, check_input, check_output

__all__ = ["add_parser", "run"]

_HEADLINE = "manual.final_score"


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan leaderboard`` to the ``fcplan`` sub-parsers ``sub``."""
    lb = sub.add_parser(
        "leaderboard",
        help="the benchmark suite's leaderboard (Markdown) from results folders",
    )
    lb.add_argument(
        "results", nargs="+", help="results folders of fcplan sweep (or fcplan compare --json)"
    )
    lb.add_argument("-o", "--output", metavar="FILE", help="write the page here ('-': print)")
    lb.add_argument(
        "--metric",
        default=_HEADLINE,
        help=f"headline metric column (default {_HEADLINE})",
    )
    lb.add_argument("--json", metavar="PATH", help="also write every number as JSON")
    lb.set_defaults(run=run)


def _command(args: argparse.Namespace) -> str:
    words = ["fcplan", "leaderboard", *args.results]
    if args.output not in (None, "-"):
        words += ["-o", args.output]
    if args.metric != _HEADLINE:
        words += ["--metric", args.metric]
    return shlex.join(words)


def run(args: argparse.Namespace) -> int:
    """Build the leaderboard and print or write its page."""
    from fcplan.experiments.leaderboard import leaderboard
    from fcplan.experiments.leaderboard_page import markdown

    out = None if args.output in (None, "-") else args.output
    check_output(out, "-o")
    check_output(args.json, "--json")
    for path in args.results:
        check_input(path, "results", folder=not path.endswith(".json"))
    board = leaderboard(args.results, metric=args.metric)
    page = markdown(board, _command(args))
    for path, text in ((out, page), (args.json, None)):
        if path is None:
            continue
        try:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text if text is not None else json.dumps(board.to_dict(), indent=1))
        except OSError as exc:
            raise CliError(f"cannot write {path}: {exc.strerror or exc}") from None
    if out is None:
        print(page, end="")
    else:
        tiers = ", ".join(f"{t.suite}/{t.tier}" if t.suite else t.tier for t in board.tiers)
        print(f"{out}: {len(board.tiers)} tier(s) ({tiers})", file=sys.stderr)
    return 0
