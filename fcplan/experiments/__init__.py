"""Experiments: running many episodes and comparing them.

A single :func:`fcplan.run_episode` call plays one scenario with one scheduler and one seed. An
experiment runs a grid of them (scenarios x schedulers x seeds), in parallel over the machine's
cores, and summarises the outcomes with confidence intervals.

* :mod:`~fcplan.experiments.compare`: :func:`compare` runs the grid and returns a
  :class:`ComparisonResult` (:mod:`~fcplan.experiments.comparison`: per-episode rows, a
  per-scheduler table, JSON/CSV output, a text table); :func:`parse_range`
  (:mod:`~fcplan.experiments.ranges`) reads the CLI's ``1-24``/``1,3,5-7``/``practice`` lists.
  The ``fcplan compare`` command is a thin layer over them.
* :mod:`~fcplan.experiments.stats`: the mean and Student-t confidence interval of the mean,
  paired differences, the Wilcoxon signed-rank test, Holm's adjustment, the pairs an 80 %-power
  study needs, Friedman's test; :mod:`~fcplan.experiments.tables`: the columns every experiment
  table summarises, taken from the metric table :data:`fcplan.metrics.METRICS`.
* :mod:`~fcplan.experiments.analysis`: the statistics of a study, one implementation for
  ``compare`` and ``report``: paired tables with verdicts in words, fractions of the ``oracle``,
  rankings per metric and which metric separates the schedulers
  (:mod:`~fcplan.experiments.statblocks` turns them into tables);
  :mod:`~fcplan.experiments.autoseeds`: ``seeds="auto"``, seeds added in batches until every pair
  is resolved, with a stopping rule corrected for the repeated looks;
  :mod:`~fcplan.experiments.progress`: one ``tqdm`` bar counted in episodes.

* :mod:`~fcplan.experiments.sweep`: :func:`sweep` runs a TOML grid (scenarios x schedulers and
  their settings x seeds x scenario overrides, :mod:`~fcplan.experiments.config`) on a local
  process pool or a Dask cluster (:mod:`~fcplan.experiments.backends`), storing each finished
  episode at once in a Parquet results folder (:mod:`~fcplan.experiments.results`);
  :func:`load_results` reads it back as a pandas DataFrame. Re-running resumes.
* :mod:`~fcplan.experiments.report`: :func:`report` turns a results folder into Markdown, PNG and
  HTML: tables with confidence intervals, the statistics of the study, plots
  (:mod:`~fcplan.experiments.plots`); it refuses to pool different studies written into one
  folder (:mod:`~fcplan.experiments.studies`).
* :mod:`~fcplan.experiments.verify`: :func:`verify_results` plays a sample of a folder's stored
  episodes again and says which schedulers' results today's code no longer reproduces (stale
  after a change of behaviour); every row also names its code (:mod:`fcplan.provenance`).

Sweeps and comparisons run their episodes on the same backends
(:mod:`~fcplan.experiments.backends`: in-process, a local process pool restarted when a worker
dies, or Dask).

pandas/pyarrow (``fcplan[parquet]``), dask (``fcplan[dask]``) and matplotlib (``fcplan[plot]``)
are imported only when needed.

Examples
--------
>>> from fcplan.experiments import compare, parse_range
>>> parse_range("1,3,5-7")
[1, 3, 5, 6, 7]
"""

from fcplan.experiments.compare import ComparisonResult, RangeError, compare, parse_range
from fcplan.experiments.config import SweepConfigError, load_sweep_config
from fcplan.experiments.report import report
from fcplan.experiments.results import ResultsError, load_results
from fcplan.experiments.stats import MeanCI, mean_ci, paired_mean_ci
from fcplan.experiments.sweep import SweepSummary, sweep
from fcplan.experiments.verify import Verification, verify_results

__all__ = [
    "compare",
    "ComparisonResult",
    "parse_range",
    "RangeError",
    "MeanCI",
    "mean_ci",
    "paired_mean_ci",
    "sweep",
    "SweepSummary",
    "SweepConfigError",
    "load_sweep_config",
    "load_results",
    "ResultsError",
    "report",
    "verify_results",
    "Verification",
]
