"""The layout shared by experiment tables: the columns they summarise, and their row order.

An experiment table (:meth:`~fcplan.experiments.ComparisonResult.table`, the sweep report) has a
``mean ± ci`` cell per scheduler for a fixed list of columns. A *score column* is one metric of
:data:`fcplan.metrics.METRICS` under one definition (the manual's final score, OFS, PS, AS, FPS,
NRR and total negative reward, and the reference2020 final score); its header, decimals and
direction come from the metric's :class:`~fcplan.metrics.MetricSpec`, so no label is written here
again. A *run column* is a measurement of the episode run (solve time per replan, fallbacks, wall
time), which the sweep report tabulates as well.

* :data:`SCORE_COLUMNS`: what :func:`~fcplan.experiments.compare` tabulates; each has the short
  ``key`` of its ``<key>_mean`` / ``<key>_ci`` fields in comparison tables and CSV files.
* :data:`OUTCOME_COLUMNS`: the outcome metrics (time to containment, contained, burned area,
  facility damage), which separate schedulers where the manual's scores saturate;
  :data:`RANKING_COLUMNS`: the metrics schedulers are ranked on (final score, NRR, outcomes).
* :data:`REPORT_COLUMNS`: what :func:`~fcplan.experiments.report` tabulates (scores, outcomes,
  then runs).
* :func:`higher_is_better`: the direction of any result column, for paired verdicts.
* :func:`difficulty_key`: rows by difficulty group come in the order of
  :data:`fcplan.scenario.model.DIFFICULTIES` (practice, easy, moderate, hard, custom).
* :func:`fallback_majority`: the flag of an episode whose scheduler fell back to greedy on more
  than half of its replans (its scores are mostly greedy's), from its ``fallbacks`` and
  ``replans`` columns.

Examples
--------
>>> [c.key for c in SCORE_COLUMNS][:3]
['final_score', 'ofs', 'ps']
>>> SCORE_COLUMNS[1].name, SCORE_COLUMNS[1].label, SCORE_COLUMNS[1].decimals
('manual.overall_firefighting', 'OFS %', 1)
>>> higher_is_better("manual.negative_reward_ratio"), higher_is_better("solve_p95_ms")
(False, False)
>>> sorted(["hard", "mine", "easy"], key=difficulty_key)
['easy', 'hard', 'mine']
"""

from __future__ import annotations

from dataclasses import dataclass

from fcplan.errors import FcplanError, UnknownNameError
from fcplan.metrics import DEFINITIONS, METRICS, OUTCOMES, MetricSpec, metric_spec
from fcplan.scenario.model import DIFFICULTIES

__all__ = [
    "Column",
    "OUTCOME_COLUMNS",
    "RANKING_COLUMNS",
    "REPORT_COLUMNS",
    "RUN_COLUMNS",
    "SCORE_COLUMNS",
    "check_metric",
    "difficulty_key",
    "fallback_majority",
    "higher_is_better",
    "metric_columns",
]


@dataclass(frozen=True)
class Column:
    """One summarised column of an experiment table.

    Attributes
    ----------
    name : str
        The column of episode rows and sweep results (``"manual.overall_firefighting"``).
    label : str
        Its header in text, Markdown and HTML tables (``"OFS %"``).
    decimals : int
        Decimals of its ``mean ± ci`` cells.
    higher_is_better : bool
        Which way a difference between two schedulers counts as better.
    key : str
        Short name in comparison tables (``"ofs"`` gives ``ofs_mean`` and ``ofs_ci``); ``""`` for
        columns that only the sweep report shows.
    """

    name: str
    label: str
    decimals: int
    higher_is_better: bool
    key: str = ""


def _score(key: str, metric: str, definition: str = "manual", label: str = "") -> Column:
    """The column of ``metric`` under ``definition``, described by its metric-table entry."""
    spec = metric_spec(metric)
    return Column(
        spec.key(definition), label or spec.column, spec.decimals, spec.higher_is_better, key
    )


def _outcome(key: str, spec: MetricSpec) -> Column:
    """The episode-summary column ``outcome.<name>`` of an outcome metric."""
    return Column(f"outcome.{spec.name}", spec.column, spec.decimals, spec.higher_is_better, key)


SCORE_COLUMNS: tuple[Column, ...] = (
    _score("final_score", "final_score"),
    _score("ofs", "overall_firefighting"),
    _score("ps", "perception"),
    _score("as", "action"),
    _score("fps", "facility_protection"),
    _score("nrr", "negative_reward_ratio"),
    _score("neg_reward", "total_negative_reward"),
    _score("ref2020_final_score", "final_score", "reference2020", "ref2020 final"),
)
"""Scores in experiment tables: the manual's metrics and the reference2020 final score."""

OUTCOME_COLUMNS: tuple[Column, ...] = tuple(
    _outcome(key, spec)
    for key, spec in zip(("contain_s", "contained", "burned", "damage"), OUTCOMES, strict=True)
)
"""The outcome metrics (:mod:`fcplan.metrics.outcomes`: time to containment, contained, burned
area, facility damage), columns ``outcome.<name>`` of episode summaries and sweep results."""

RANKING_COLUMNS: tuple[Column, ...] = (
    SCORE_COLUMNS[0],
    next(c for c in SCORE_COLUMNS if c.key == "nrr"),
    *OUTCOME_COLUMNS,
)
"""The metrics schedulers are ranked on (:mod:`fcplan.experiments.analysis`): the manual's final
score and NRR, and the outcome metrics."""

RUN_COLUMNS: tuple[Column, ...] = (
    Column("solve_p50_ms", "solve p50 ms", 2, False),
    Column("solve_p95_ms", "solve p95 ms", 2, False),
    Column("fallbacks", "fallbacks", 1, False),
    Column("wall_time_s", "wall s", 2, False),
)
"""Measurements of the episode run that the sweep report tabulates after the scores."""

REPORT_COLUMNS: tuple[Column, ...] = SCORE_COLUMNS + OUTCOME_COLUMNS + RUN_COLUMNS
"""Every column of the sweep report's tables, in order."""

# Result columns outside the tables that are better when lower (matched as substrings).
_LOWER_IS_BETTER = ("solve_", "wall_time", "fallbacks")


def higher_is_better(name: str) -> bool:
    """Whether a larger value of result column ``name`` is better.

    A column of :data:`REPORT_COLUMNS` or a metric (``"<definition>.<metric>"``) answers from its
    description; any other column is lower-is-better when its name says it is a solve time, a
    wall time or a fallback count.

    Examples
    --------
    >>> higher_is_better("reference2020.total_negative_reward"), higher_is_better("tasks_mean")
    (False, True)
    >>> higher_is_better("outcome.burned_area_cells"), higher_is_better("outcome.contained")
    (False, True)
    """
    for col in REPORT_COLUMNS:
        if col.name == name:
            return col.higher_is_better
    definition, _, metric = name.partition(".")
    if definition in (*DEFINITIONS, "outcome"):
        try:
            return metric_spec(metric).higher_is_better
        except UnknownNameError:
            pass
    return not any(k in name for k in _LOWER_IS_BETTER)


def difficulty_key(difficulty: str) -> tuple[int, str]:
    """Sort key of a difficulty group: the known groups in order, then any other by name."""
    known = DIFFICULTIES.index(difficulty) if difficulty in DIFFICULTIES else len(DIFFICULTIES)
    return (known, difficulty)


def fallback_majority(row: dict) -> bool:
    """Whether an episode's scheduler fell back (to greedy) on more than half of its replans.

    Examples
    --------
    >>> fallback_majority({"fallbacks": 11, "replans": 20}), fallback_majority({"replans": 0})
    (True, False)
    """
    replans, fallbacks = row.get("replans") or 0, row.get("fallbacks") or 0
    return bool(replans == replans and replans > 0 and fallbacks > replans / 2)


def metric_columns() -> list[str]:
    """Every numeric metric column of episode rows: ``<definition>.<metric>`` for both
    definitions (the verbal grade excluded) and ``outcome.<name>``.

    Examples
    --------
    >>> cols = metric_columns()
    >>> "manual.final_score" in cols, "outcome.burned_area_cells" in cols, "manual.grade" in cols
    (True, True, False)
    """
    out = [s.key(d) for d in DEFINITIONS for s in METRICS if s.name != "grade"]
    return out + [f"outcome.{s.name}" for s in OUTCOMES]


def check_metric(name: str) -> str:
    """``name`` if it is a :func:`metric_columns` entry, else a one-line :class:`FcplanError`.

    Examples
    --------
    >>> check_metric("manual.perception")
    'manual.perception'
    """
    cols = metric_columns()
    if name not in cols:
        raise FcplanError(f"metric {name!r} is not a numeric metric; use one of {', '.join(cols)}")
    return name
