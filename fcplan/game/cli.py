"""The ``fcplan play`` command under its first import path: see :mod:`fcplan.cli.play`.

Examples
--------
>>> import fcplan.cli.play
>>> add_parser is fcplan.cli.play.add_parser and run is fcplan.cli.play.run
True
"""

from __future__ import annotations

from fcplan.cli.play import add_parser, run

__all__ = ["add_parser", "run"]
