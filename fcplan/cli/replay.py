"""``fcplan replay PATH``: watch a recording in a window, or write it as an MP4 or GIF video.

::

    fcplan replay PATH [--video out.mp4|out.gif] [--fps N] [--speed X] [--size PX] [--truth]
                       [--start S] [--end S]

The options and the player are those of :mod:`fcplan.replay`; this module adds the command to
``fcplan``.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["replay", "run.npz", "--video", "run.gif", "--speed", "4"])
>>> args.path, args.video, args.speed, args.fps
('run.npz', 'run.gif', 4.0, 10.0)
"""

from __future__ import annotations

import argparse

from fcplan.cli.util import SubParsers, check_input

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan replay`` to the ``fcplan`` sub-parsers ``sub``."""
    from fcplan.replay import add_parser as add_replay

    add_replay(sub)
    sub.choices["replay"].set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Play or write the recording ``args.path`` (a regular file: checked before it is opened)."""
    from fcplan.replay import run as run_replay

    check_input(args.path, "recording")
    return run_replay(args)
