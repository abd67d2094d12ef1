"""``fcplan compare``: run schedulers over scenarios x seeds in parallel; print a comparison table.

::

    fcplan compare --schedulers A,B [--scenarios 1-24] [--seeds 0-4 | --seeds auto
                   [--max-seeds 50] [--seed-batch 5]] [--metric NAME ...] [--jobs N]
                   [--time-limit S] [--replan-period S] [--json PATH [--resume]] [--csv PATH]
                   [--by-difficulty] [--quiet] [--wall-time]

Runs :func:`fcplan.experiments.compare.compare` and prints its table (and one per difficulty with
``--by-difficulty``), then for every pair of schedulers the paired difference of each
``--metric`` (default the manual's final score) with its 95 % interval, Wilcoxon and
Holm-adjusted p-values and a verdict in words, the fraction of the ``oracle``'s score when it is
compared, and a ranking per metric. A progress bar (in episodes) goes to stderr unless
``--quiet``, and one warning line per failed episode follows the tables. Schedulers with a
deterministic mode run in it, so the tables do not depend on ``--jobs`` or machine load;
``--wall-time`` runs them with wall-clock limits instead (the table's ``mode`` column says which).

``--seeds auto`` adds seeds in batches of ``--seed-batch`` until every pair's interval excludes 0
or ``--max-seeds`` is reached, and says why it stopped
(:mod:`fcplan.experiments.autoseeds`); with ``--json PATH`` the comparison so far is written
after each batch, and ``--resume`` reuses the episodes of ``PATH`` (same study only) instead of
playing them again.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["compare", "--schedulers", "greedy,idle", "--scenarios", "1-3"])
>>> args.schedulers, args.scenarios, args.seeds, args.metric
(['greedy', 'idle'], [1, 2, 3], [0, 1, 2, 3, 4], None)
>>> p.parse_args(["compare", "--schedulers", "greedy,idle", "--seeds", "auto"]).seeds
'auto'
"""

from __future__ import annotations

import argparse
import sys

from fcplan.cli.util import (
    CliError,
    SubParsers,
    check_output,
    name_list,
    positive_float,
    positive_int,
    scenario_list,
    seed_list,
)

__all__ = ["add_parser", "run"]


def _seeds(text: str) -> list[int | str] | str:
    """``auto`` or seeds as numbers and ranges (:func:`fcplan.cli.util.seed_list`)."""
    return "auto" if text.strip().lower() == "auto" else seed_list(text)


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan compare`` to the ``fcplan`` sub-parsers ``sub``."""
    c = sub.add_parser(
        "compare",
        help="run schedulers over scenarios x seeds in parallel and print a comparison table",
    )
    c.add_argument(
        "--schedulers",
        type=name_list,
        required=True,
        help="comma-separated registered scheduler names, e.g. greedy,idle",
    )
    c.add_argument(
        "--scenarios",
        type=scenario_list,
        default="1-24",
        help="scenarios as numbers, ranges and names, e.g. 1-24 or practice,1,3,5-7 (default 1-24)",
    )
    c.add_argument(
        "--seeds",
        type=_seeds,
        default="0-4",
        help="seeds, e.g. 0-4 or 0,7 (default 0-4), or 'auto': add seeds in batches until every "
        "pair of schedulers is resolved or --max-seeds",
    )
    c.add_argument(
        "--max-seeds",
        type=positive_int,
        default=50,
        help="--seeds auto: the most seeds to play (default 50)",
    )
    c.add_argument(
        "--seed-batch",
        type=positive_int,
        default=5,
        help="--seeds auto: seeds added per batch (default 5)",
    )
    c.add_argument(
        "--metric",
        action="append",
        metavar="NAME",
        help="metric of the paired comparisons (repeatable; the first is the headline; "
        "default manual.final_score), e.g. outcome.burned_area_cells",
    )
    c.add_argument(
        "--jobs", "-j", type=positive_int, default=None, help="worker processes (default: CPUs)"
    )
    c.add_argument(
        "--time-limit",
        type=positive_float,
        default=None,
        help="seconds per scheduler call (default: each scheduler's own)",
    )
    c.add_argument(
        "--replan-period",
        type=positive_float,
        default=1.0,
        help="simulated seconds between replans (default 1.0)",
    )
    c.add_argument("--json", metavar="PATH", help="also write the table and every episode as JSON")
    c.add_argument(
        "--resume",
        action="store_true",
        help="reuse the episodes stored in --json PATH by an earlier run of the same comparison",
    )
    c.add_argument("--csv", metavar="PATH", help="also write the table as CSV")
    c.add_argument("--by-difficulty", action="store_true", help="also print a table per difficulty")
    c.add_argument("--quiet", "-q", action="store_true", help="no progress bar on stderr")
    c.add_argument(
        "--wall-time",
        action="store_true",
        help="let time limits bind on the wall clock (results depend on machine load); default: "
        "schedulers with a deterministic mode run in it",
    )
    c.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run the comparison, print its tables and write the requested files."""
    from fcplan.experiments.compare import compare

    check_output(args.json, "--json")
    check_output(args.csv, "--csv")
    if args.resume and args.json is None:
        raise CliError("--resume: give --json PATH, the comparison to resume from")
    result = compare(
        args.scenarios,
        args.schedulers,
        args.seeds,
        jobs=args.jobs,
        time_limit=args.time_limit,
        replan_period=args.replan_period,
        progress=not args.quiet,
        deterministic=not args.wall_time,
        metrics=args.metric or ["manual.final_score"],
        max_seeds=args.max_seeds,
        seed_batch=args.seed_batch,
        resume=args.json if args.resume else None,
        checkpoint=args.json if args.seeds == "auto" else None,
    )
    print(result.format())
    if args.by_difficulty:
        print()
        print(result.format(by_difficulty=True, statistics=False))
    for path, write in ((args.json, result.to_json), (args.csv, result.to_csv)):
        if path is not None:
            try:
                write(path)
            except OSError as exc:
                raise CliError(f"cannot write {path}: {exc.strerror or exc}") from None
    for e in result.errors:
        print(
            f"fcplan: warning: episode {e['scenario']} {e['scheduler']} seed {e['seed']} "
            f"failed: {e['error']}",
            file=sys.stderr,
        )
    return 0
