"""Experiments: running many episodes and comparing them.

A single :func:`fcplan.run_episode` call plays one scenario with one scheduler and one seed. An
experiment runs a grid of them (scenarios x schedulers x seeds), in parallel over the machine's
cores, and summarises the outcomes with confidence intervals.

* :mod:`~fcplan.experiments.compare`: :func:`compare` runs the grid and returns a
  :class:`ComparisonResult` (per-episode rows, a per-scheduler table, JSON/CSV output, a text
  table); :func:`parse_range` reads the CLI's ``1-24``/``1,3,5-7``/``practice`` lists. The
  ``fcplan compare`` command is a thin layer over them.
* :mod:`~fcplan.experiments.stats`: the mean and Student-t confidence interval of the mean, and
  paired differences.

More is planned here: sweeps over scheduler settings, result stores and reports.

Examples
--------
>>> from fcplan.experiments import compare, parse_range
>>> parse_range("1,3,5-7")
[1, 3, 5, 6, 7]
"""

from fcplan.experiments.compare import ComparisonResult, RangeError, compare, parse_range
from fcplan.experiments.stats import MeanCI, mean_ci, paired_mean_ci

__all__ = [
    "compare",
    "ComparisonResult",
    "parse_range",
    "RangeError",
    "MeanCI",
    "mean_ci",
    "paired_mean_ci",
]
