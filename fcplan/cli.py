"""The ``fcplan`` command line.

Commands::

    fcplan scenarios                         list the shipped scenarios
    fcplan scenario validate FILE [FILE...]  check scenario files; list manual limits exceeded
    fcplan run SCENARIO [--scheduler NAME] [--seed N] [--replan-period S] [--time-limit S] [--json]
    fcplan compare --schedulers A,B [--scenarios 1-24] [--seeds 0-4] [--jobs N] [--time-limit S]
                   [--replan-period S] [--json PATH] [--csv PATH] [--by-difficulty] [--quiet]
    fcplan sweep CONFIG.toml [--results DIR] [--jobs N] [--dask ADDRESS|local] [--retry-failed]
    fcplan report RESULTS [--out DIR] [--html] [--metric NAME]
    fcplan replay PATH [--video out.mp4|out.gif] [--fps N] [--speed X] [--size PX] [--truth]
    fcplan play [--scenario NAME] [--seed N] [--record PATH] [--speed X] [--fast]
    fcplan import-legacy DIR [--out PATH]

``fcplan run`` also takes ``--record PATH``. The commands after ``compare`` live in the modules of
:data:`COMMAND_MODULES`; ``fcplan COMMAND --help`` lists every option.

Bad input (an unknown scenario or scheduler, a malformed file, an out-of-range argument) prints one
line naming the problem and exits with status 2; ``--debug`` shows the traceback instead.

Examples
--------
>>> from fcplan.cli import main
>>> main(["scenarios"])  # doctest: +ELLIPSIS
name ...
0
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from fcplan.cliutil import (
    CliError,
    Parser,
    check_output,
    name_list,
    positive_float,
    positive_int,
    scenario_list,
    seed,
    seed_list,
)
from fcplan.errors import FcplanError

__all__ = ["COMMAND_MODULES", "main"]

#: Modules that add a sub-command. Each defines ``add_parser(sub)``, which adds its parser to the
#: ``argparse`` sub-parsers object ``sub`` (built with ``parser_class=fcplan.cliutil.Parser``) and
#: sets ``run=<function(args) -> int>`` as a default; heavy imports stay inside ``run``.
COMMAND_MODULES: tuple[str, ...] = (
    "fcplan.game.cli",
    "fcplan.experiments.commands",
    "fcplan.replay",
    "fcplan.legacy",
)


def _build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="fcplan", description="FireCommander multi-robot task assignment testbed")
    p.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)

    sub.add_parser("scenarios", help="list the shipped scenarios")

    sc = sub.add_parser("scenario", help="scenario file tools")
    scs = sc.add_subparsers(dest="scenario_command", required=True, parser_class=Parser)
    v = scs.add_parser("validate", help="validate scenario files and list manual limits exceeded")
    v.add_argument("files", nargs="+", help="TOML files or shipped scenario names")

    r = sub.add_parser("run", help="run one episode and print the manual's metrics")
    r.add_argument("scenario", help="practice, 1..24, or a TOML file")
    r.add_argument("--scheduler", "-s", default="greedy", help="registered scheduler name")
    r.add_argument("--seed", type=seed, default=0, help="random seed (integer >= 0)")
    r.add_argument(
        "--replan-period",
        type=positive_float,
        default=1.0,
        help="simulated seconds between replans (default 1.0)",
    )
    r.add_argument(
        "--time-limit",
        type=positive_float,
        default=None,
        help="seconds per scheduler call (default: the scheduler's own)",
    )
    r.add_argument("--json", action="store_true", help="print the results as JSON")
    r.add_argument(
        "--record", metavar="PATH", help="write a recording of the episode (.npz) for fcplan replay"
    )

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
        "--seeds", type=seed_list, default="0-4", help="seeds, e.g. 0-4 or 0,7 (default 0-4)"
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
    c.add_argument("--csv", metavar="PATH", help="also write the table as CSV")
    c.add_argument("--by-difficulty", action="store_true", help="also print a table per difficulty")
    c.add_argument("--quiet", "-q", action="store_true", help="no progress lines on stderr")

    import importlib

    for name in COMMAND_MODULES:
        importlib.import_module(name).add_parser(sub)
    return p


def _cmd_scenarios() -> int:
    from fcplan.scenario import list_scenarios, load_scenario

    rows = []
    for name in list_scenarios():
        s = load_scenario(name)
        team = "/".join(f"{n}{r[0].upper()}" for r, n in s.team_counts.items() if n)
        regions = ", ".join(
            f"{r.cell or tuple(int(c) for c in r.center)}({r.fronts}f"
            + (f", +{r.delay_s:g}s)" if r.delay_s else ")")
            for r in s.regions
        )
        rows.append((name if s.number is None else s.name, s.difficulty, team, regions))
    widths = [max(len(r[k]) for r in rows + [("name", "difficulty", "team", "")]) for k in range(3)]
    header = ("name", "difficulty", "team", "fire regions (fronts, delay)")
    for row in [header, *rows]:
        print("  ".join(c.ljust(w) for c, w in zip(row[:3], widths, strict=True)) + "  " + row[3])
    return 0


def _cmd_validate(files: Sequence[str]) -> int:
    from fcplan.scenario import load_scenario

    for f in files:
        s = load_scenario(f)
        over = s.manual_limit_violations()
        if over:
            print(f"{f}: valid; exceeds {len(over)} manual limit(s):")
            for line in over:
                print(f"  - {line}")
        else:
            print(f"{f}: valid, within the manual's limits")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from fcplan.episode import run_episode
    from fcplan.metrics import format_metrics
    from fcplan.scenario import load_scenario
    from fcplan.scheduling import make_scheduler

    check_output(args.record, "--record")
    scenario = load_scenario(args.scenario)
    scheduler = make_scheduler(args.scheduler)
    res = run_episode(
        scenario,
        scheduler,
        seed=args.seed,
        replan_period=args.replan_period,
        time_limit=args.time_limit,
        record=args.record,
    )
    if args.json:
        out = {
            "scenario": res.scenario,
            "scheduler": res.scheduler,
            "seed": res.seed,
            "metrics": {k: m.as_dict() for k, m in res.metrics.items()},
            "ticks": res.ticks,
            "simulated_s": res.trace.duration_s,
            "wall_time_s": res.wall_time_s,
            "replans": len(res.solves),
            "fallbacks": res.fallbacks,
        }
        print(json.dumps(out, indent=2))
        return 0
    st = res.solve_times_s * 1e3
    print(
        f"scenario {res.scenario} ({scenario.difficulty}), scheduler {res.scheduler}, "
        f"seed {res.seed}"
    )
    print(
        f"{res.ticks} ticks = {res.trace.duration_s:g} s simulated at "
        f"{scenario.ticks_per_second} Hz; wall time {res.wall_time_s:.2f} s; "
        f"{len(res.solves)} replans (solve p50 {_pct(st, 50):.2f} ms, p95 {_pct(st, 95):.2f} ms), "
        f"{res.fallbacks} fallbacks"
    )
    print()
    print(format_metrics(res.metrics))
    if args.record:
        print(f"\nrecording written to {args.record} (fcplan replay {args.record})")
    return 0


def _cmd_compare(args: argparse.Namespace) -> int:
    from fcplan.experiments.compare import ProgressPrinter, compare

    check_output(args.json, "--json")
    check_output(args.csv, "--csv")
    result = compare(
        args.scenarios,
        args.schedulers,
        args.seeds,
        jobs=args.jobs,
        time_limit=args.time_limit,
        replan_period=args.replan_period,
        progress=None if args.quiet else ProgressPrinter(sys.stderr),
    )
    print(result.format())
    if args.by_difficulty:
        print()
        print(result.format(by_difficulty=True))
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


def _pct(a, q) -> float:
    import numpy as np

    return float(np.percentile(a, q)) if len(a) else 0.0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``fcplan`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    try:
        args = _build_parser().parse_args(argv)
        if args.command == "scenarios":
            return _cmd_scenarios()
        if args.command == "scenario":
            return _cmd_validate(args.files)
        if args.command == "run":
            return _cmd_run(args)
        if args.command == "compare":
            return _cmd_compare(args)
        if getattr(args, "run", None) is not None:
            return int(args.run(args))
        raise CliError(f"unknown command {args.command!r}")  # pragma: no cover
    except FcplanError as exc:
        if debug:
            raise
        print(f"fcplan: error: {exc}".replace("\n", " "), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fcplan: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `fcplan scenarios | head`
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
