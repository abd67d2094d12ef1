"""The ``fcplan`` command line: one module per command.

Commands::

    fcplan --help | --version
    fcplan scenarios                         list the shipped scenarios
    fcplan scenario validate FILE [FILE...]  check scenario files; list manual limits exceeded
    fcplan schedulers [NAME...] [--json]     the registered schedulers, their settings and defaults
    fcplan run SCENARIO [--scheduler NAME] [--seed N] [--replan-period S] [--time-limit S] [--json]
    fcplan compare --schedulers A,B [--scenarios 1-24] [--seeds 0-4] [--jobs N] [--time-limit S]
                   [--replan-period S] [--json PATH] [--csv PATH] [--by-difficulty] [--quiet]
    fcplan sweep CONFIG.toml [--results DIR] [--jobs N] [--dask ADDRESS|local] [--retry-failed]
    fcplan report RESULTS [--out DIR] [--html] [--metric NAME]
    fcplan replay PATH [--video out.mp4|out.gif] [--fps N] [--speed X] [--size PX] [--truth]
    fcplan play [--scenario NAME] [--seed N] [--record PATH] [--speed X] [--fast]
    fcplan import-legacy DIR [--out PATH]

``fcplan run`` also takes ``--record PATH``; ``fcplan COMMAND --help`` lists every option. Long
single commands (``run``, ``replay --video``) show a progress bar on stderr in a terminal
(:mod:`~fcplan.cli.progress`).

Modules: :mod:`~fcplan.cli.parser` (the parser and :func:`main`), :mod:`~fcplan.cli.util` (the
argument types and :class:`~fcplan.cli.util.CliError` every command shares),
:mod:`~fcplan.cli.progress` (the progress bars), then one module per command:
:mod:`~fcplan.cli.scenarios`, :mod:`~fcplan.cli.scenario` (``scenario validate``),
:mod:`~fcplan.cli.schedulers`, :mod:`~fcplan.cli.run`, :mod:`~fcplan.cli.compare`,
:mod:`~fcplan.cli.play`, :mod:`~fcplan.cli.sweep`, :mod:`~fcplan.cli.report`,
:mod:`~fcplan.cli.replay` and :mod:`~fcplan.cli.import_legacy`. Each defines ``add_parser(sub)``
and ``run(args) -> int``; its heavy imports stay inside ``run``, so ``fcplan --help`` imports no
numpy and ``fcplan scenarios`` no scipy, networkx or solver (``tests/cli/test_cli_startup.py``).

Bad input (an unknown scenario or scheduler, a malformed file, an out-of-range argument, an
unknown or misspelt option: options are never abbreviated) prints one line naming the problem
and exits with status 2; ``--debug`` shows the traceback instead.

Examples
--------
>>> from fcplan.cli import main
>>> main(["scenarios"])  # doctest: +ELLIPSIS
name ...
0
"""

from __future__ import annotations

from fcplan.cli.parser import COMMAND_MODULES, main

__all__ = ["COMMAND_MODULES", "main"]
