"""``fcplan scenarios``: list the shipped scenarios with difficulty, team and fire regions.

One row per scenario (practice, #1..#24, the open-world examples, then the benchmark suites'
scenarios such as ``fcplan-bench-v1/hard-01``): its name, difficulty, team (``2P/2A``: perception,
action and hybrid counts) and fire regions (cell or centre, fronts and delay; counts only beyond
six regions).

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["scenarios"]).run is run
True
"""

from __future__ import annotations

import argparse

from fcplan.cli.util import SubParsers

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan scenarios`` to the ``fcplan`` sub-parsers ``sub``."""
    p = sub.add_parser("scenarios", help="list the shipped scenarios")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print the table of shipped scenarios."""
    from fcplan.scenario import list_scenarios, load_scenario

    rows = []
    for name in list_scenarios(suites=True):
        s = load_scenario(name)
        team = "/".join(f"{n}{r[0].upper()}" for r, n in s.team_counts.items() if n)
        regions = ", ".join(
            f"{r.cell or tuple(int(c) for c in r.center)}({r.fronts}f"
            + (f", +{r.delay_s:g}s)" if r.delay_s else ")")
            for r in s.regions
        )
        if len(s.regions) > 6:
            late = sum(r.delay_s > 0 for r in s.regions)
            fronts = sum(r.fronts for r in s.regions)
            regions = f"{len(s.regions)} regions, {fronts} fronts, {late} late"
        rows.append((name if s.number is None else s.name, s.difficulty, team, regions))
    widths = [max(len(r[k]) for r in rows + [("name", "difficulty", "team", "")]) for k in range(3)]
    header = ("name", "difficulty", "team", "fire regions (fronts, delay)")
    for row in [header, *rows]:
        print("  ".join(c.ljust(w) for c, w in zip(row[:3], widths, strict=True)) + "  " + row[3])
    return 0
