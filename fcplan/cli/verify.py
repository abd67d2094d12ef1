"""``fcplan verify RESULTS``: does today's code still reproduce a results folder's episodes?

::

    fcplan verify RESULTS [--per-scheduler N] [--scheduler LABEL ...] [--seed N] [--jobs N]
                          [--json PATH]

Plays ``N`` stored episodes of each scheduler again (a seeded draw; default 1) and compares
every metric with the stored one (:func:`fcplan.experiments.verify.verify_results`). Prints one
line per episode and a verdict; exits 0 when every checked episode is reproduced exactly, 1 when
one differs (the scheduler's stored episodes are stale: its behaviour changed since they were
played), 2 on bad input. Run it before regenerating a leaderboard from a study that spans code
changes.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["verify", "bench/results/bench-v2", "--per-scheduler", "2"])
>>> args.results, args.per_scheduler, args.scheduler
('bench/results/bench-v2', 2, None)
"""

from __future__ import annotations

import argparse

from fcplan.cli.util import CliError, SubParsers, check_input, check_output, positive_int, seed

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan verify`` to the ``fcplan`` sub-parsers ``sub``."""
    v = sub.add_parser(
        "verify",
        help="play stored episodes of a results folder again: are they still reproduced?",
    )
    v.add_argument("results", help="a results folder of fcplan sweep")
    v.add_argument(
        "--per-scheduler",
        type=positive_int,
        default=1,
        metavar="N",
        help="episodes checked per scheduler (default 1)",
    )
    v.add_argument(
        "--scheduler",
        action="append",
        metavar="LABEL",
        help="check only this scheduler label (repeatable; default: all)",
    )
    v.add_argument("--seed", type=seed, default=0, help="seed of the draw (default 0)")
    v.add_argument(
        "--jobs", "-j", type=positive_int, default=1, help="worker processes (default 1)"
    )
    v.add_argument("--json", metavar="PATH", help="also write every check as JSON")
    v.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Verify the folder; exit status 1 when a stored episode is not reproduced."""
    from fcplan.experiments.verify import as_json, verify_results

    check_input(args.results, "results", folder=True)
    check_output(args.json, "--json")
    result = verify_results(
        args.results,
        per_scheduler=args.per_scheduler,
        schedulers=args.scheduler,
        seed=args.seed,
        jobs=args.jobs,
    )
    print(result.format())
    if args.json:
        try:
            with open(args.json, "w", encoding="utf-8") as fh:
                fh.write(as_json(result))
        except OSError as exc:
            raise CliError(f"cannot write {args.json}: {exc.strerror or exc}") from None
    return 0 if result.ok else 1
