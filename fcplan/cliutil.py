"""The ``fcplan`` sub-commands' argument types and errors, under their first import path.

They are defined in :mod:`fcplan.cli.util`; this module exports the same objects.

Examples
--------
>>> from fcplan.cli import util
>>> CliError is util.CliError and seed is util.seed
True
"""

from __future__ import annotations

from fcplan.cli.util import (
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

__all__ = [
    "CliError",
    "Parser",
    "check_output",
    "name_list",
    "positive_float",
    "positive_int",
    "scenario_list",
    "seed",
    "seed_list",
]
