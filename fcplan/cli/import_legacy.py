"""``fcplan import-legacy DIR``: convert a FireCommander 2020 GUI recording (13 ``.pkl`` files).

::

    fcplan import-legacy DIR [--out PATH]

Reads the folder with :func:`fcplan.legacy.import_legacy` (a restricted unpickler: a file that
holds anything but plain data is refused), writes the recording (default ``./<DIR name>.npz``)
and prints its size and both metric definitions.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["import-legacy", "Scenario_Data/Tim", "--out", "old.npz"])
>>> args.folder, args.out
('Scenario_Data/Tim', 'old.npz')
"""

from __future__ import annotations

import argparse
import os

from fcplan.cli.util import SubParsers, check_input, check_output

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan import-legacy`` to the ``fcplan`` sub-parsers ``sub``."""
    p = sub.add_parser(
        "import-legacy", help="convert a FireCommander 2020 GUI recording (13 .pkl files)"
    )
    p.add_argument("folder", help="folder holding Background_Info.pkl, Agent_States.pkl, ...")
    p.add_argument("--out", metavar="PATH", help="recording to write (default ./<folder>.npz)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Convert ``args.folder``, write the recording and print its summary and metrics."""
    from fcplan.legacy import TICKS_PER_SECOND, import_legacy
    from fcplan.metrics import format_metrics

    out = args.out or f"{os.path.basename(os.path.normpath(args.folder)) or 'legacy'}.npz"
    check_output(out, "--out")
    check_input(args.folder, "legacy recording", folder=True)
    rec = import_legacy(args.folder)
    rec.save(out)
    a = rec.arrays
    print(
        f"wrote {out}: {rec.n_ticks} ticks ({rec.n_ticks / TICKS_PER_SECOND:g} s), "
        f"{len(rec.scenario.agents)} agents, {len(a['ignited_cells'])} cells burned, "
        f"{len(a['pruned_cells'])} pruned, {len(rec.inputs)} inputs"
    )
    print()
    print(format_metrics(rec.metrics()))
    return 0
