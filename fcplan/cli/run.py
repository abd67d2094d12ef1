"""``fcplan run SCENARIO``: run one episode and print the manual's metrics.

::

    fcplan run SCENARIO [--scheduler NAME] [--seed N] [--replan-period S] [--time-limit S] [--json]
                        [--record PATH]

Prints the scenario, scheduler and seed, the ticks and simulated time, the wall time, the number of
replans with the median and 95th-percentile solve times and the fallbacks, then both metric
definitions (:func:`fcplan.metrics.format_metrics`). ``--json`` prints the same as one JSON
document instead; ``--record`` also writes a recording for ``fcplan replay``. An episode that
takes more than two seconds shows a progress bar in simulated seconds on stderr
(:mod:`fcplan.cli.progress`). ``fcplan run --help`` lists the registered schedulers;
``fcplan schedulers`` describes them and their settings.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["run", "practice", "-s", "idle", "--seed", "3"])
>>> args.scenario, args.scheduler, args.seed, args.replan_period
('practice', 'idle', 3, 1.0)
"""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

from fcplan.cli.util import SubParsers, check_output, positive_float, scenario_name, seed

if TYPE_CHECKING:
    import numpy as np

__all__ = ["add_parser", "run", "schedulers_epilog"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan run`` to the ``fcplan`` sub-parsers ``sub``."""
    r = sub.add_parser(
        "run",
        help="run one episode and print the manual's metrics",
        description="Play one episode and print both metric definitions.",
        epilog_fn=schedulers_epilog,
    )
    r.add_argument(
        "scenario",
        type=scenario_name,
        help="practice, 1..24, another name fcplan scenarios lists, or a .toml file",
    )
    r.add_argument(
        "--scheduler",
        "-s",
        default="greedy",
        metavar="SPEC",
        help="a registered scheduler, with settings as NAME:KEY=VALUE[:KEY=VALUE] "
        "(default greedy; listed below)",
    )
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
    r.set_defaults(run=run)


def schedulers_epilog() -> str:
    """The registered schedulers, for ``fcplan run --help`` (computed only when help is shown)."""
    from fcplan.scheduling import available_schedulers

    return (
        f"schedulers: {', '.join(available_schedulers())}. fcplan schedulers describes each "
        "and its settings; e.g. -s milp:slots=3"
    )


def run(args: argparse.Namespace) -> int:
    """Run the episode and print its results."""
    from fcplan.cli.progress import EpisodeProgress, progress_bar
    from fcplan.episode import run_episode
    from fcplan.metrics import format_metrics
    from fcplan.scenario import load_scenario
    from fcplan.scheduling import make_scheduler

    check_output(args.record, "--record")
    scenario = load_scenario(args.scenario)
    scheduler = make_scheduler(args.scheduler)
    label = f"{scenario.name} {getattr(scheduler, 'name', args.scheduler)}"
    with progress_bar(scenario.duration_s, desc=label, unit="s") as bar:
        res = run_episode(
            scenario,
            scheduler,
            seed=args.seed,
            replan_period=args.replan_period,
            time_limit=args.time_limit,
            record=args.record,
            observers=[EpisodeProgress(bar, scenario.ticks_per_second)],
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


def _pct(a: np.ndarray, q: float) -> float:
    """The ``q``-th percentile of ``a``, 0 for an empty array."""
    import numpy as np

    return float(np.percentile(a, q)) if len(a) else 0.0
