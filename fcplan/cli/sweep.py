"""``fcplan sweep CONFIG.toml``: run a TOML grid of scenarios x schedulers x seeds x overrides.

::

    fcplan sweep CONFIG.toml [--results DIR] [--jobs N] [--dask ADDRESS|local] [--retry-failed]
                             [--quiet] [--wall-time]
                             [--seeds auto [--max-seeds 50] [--seed-batch 5] [--metric NAME]]

Runs :func:`fcplan.experiments.sweep` (default results folder: ``results/<CONFIG stem>``, so
re-running the same command resumes); it prints a summary, one warning line per failed episode,
and exits 0 when every episode is stored (completed or failed) and 1 when some were lost (a worker
died): re-run to play them. A second sweep into a folder in use, or a full disk, stops with a
one-line error (exit 2; the rows stored so far are kept); so does SIGTERM or Ctrl-C (exit 143 or
130), after stopping the workers. ``--wall-time`` lets time limits bind on the wall clock
(default: schedulers with a deterministic mode run in it). ``--seeds auto`` replaces the file's
seeds by batches of seeds until every pair of schedulers is resolved on ``--metric`` or
``--max-seeds`` are played, and says why it stopped; a progress bar (in episodes) goes to stderr
unless ``--quiet``.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["sweep", "study.toml", "--jobs", "2"]).jobs
2
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fcplan.cli.util import SubParsers, positive_int

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan sweep`` to the ``fcplan`` sub-parsers ``sub``."""
    s = sub.add_parser(
        "sweep",
        help="run a TOML grid of scenarios x schedulers x seeds x overrides; results to Parquet",
    )
    s.add_argument("config", help="sweep file (TOML): scenarios, schedulers, seeds, overrides")
    s.add_argument(
        "--results",
        metavar="DIR",
        default=None,
        help="results folder (default results/<config name>); re-running resumes",
    )
    s.add_argument(
        "--jobs", "-j", type=positive_int, default=None, help="worker processes (default: CPUs)"
    )
    s.add_argument(
        "--dask",
        metavar="ADDRESS",
        default=None,
        help="run on a Dask cluster: a scheduler address (tcp://host:8786) or 'local'",
    )
    s.add_argument(
        "--retry-failed", action="store_true", help="also re-run episodes stored as failed"
    )
    s.add_argument("--quiet", "-q", action="store_true", help="no progress on stderr")
    s.add_argument(
        "--wall-time",
        action="store_true",
        help="let time limits bind on the wall clock (results depend on machine load)",
    )
    s.add_argument(
        "--seeds",
        choices=["auto"],
        default=None,
        help="auto: replace the file's seeds by batches until every pair of schedulers is "
        "resolved or --max-seeds",
    )
    s.add_argument(
        "--max-seeds", type=positive_int, default=50, help="--seeds auto: the cap (default 50)"
    )
    s.add_argument(
        "--seed-batch",
        type=positive_int,
        default=5,
        help="--seeds auto: seeds added per batch (default 5)",
    )
    s.add_argument(
        "--metric",
        default="manual.final_score",
        metavar="NAME",
        help="--seeds auto: the metric that decides (default manual.final_score)",
    )
    s.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run the sweep; exit status 1 when some episodes were lost (re-run to play them)."""
    from fcplan.experiments.sweep import sweep

    results = args.results or str(Path("results") / Path(args.config).stem)
    summary = sweep(
        args.config,
        results,
        jobs=args.jobs,
        dask=args.dask,
        retry_failed=args.retry_failed,
        progress=not args.quiet,
        deterministic=not args.wall_time,
        seeds=args.seeds,
        max_seeds=args.max_seeds,
        seed_batch=args.seed_batch,
        metric=args.metric,
    )
    print(summary.format())
    for e in summary.errors:
        print(f"fcplan: warning: episode failed: {e}", file=sys.stderr)
    if summary.ran or summary.skipped:
        print(f"report: fcplan report {results}")
    return 1 if summary.lost else 0
