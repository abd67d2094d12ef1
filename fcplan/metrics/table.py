"""The metric table: every metric's name, labels, unit, decimals and direction, written once.

:data:`METRICS` holds one :class:`MetricSpec` per field of :class:`~fcplan.metrics.Metrics`, in
field order. Everything that shows or compares metrics iterates it instead of spelling names and
labels out again: :func:`format_metrics` (the CLI's text table), the experiment tables and reports
(:mod:`fcplan.experiments.columns`), and the game's score panels and evaluation page. A spec gives
each place its own wording of the same metric: ``label`` for the text table, ``column`` for compact
headers, ``title`` for the evaluation page, ``heading`` for the online panel.

Examples
--------
>>> [s.symbol for s in METRICS if s.unit == "%"]
['NRR', 'OFS', 'PS', 'AS', 'FPS']
>>> metric_spec("negative_reward_ratio").higher_is_better
False
"""

from __future__ import annotations

from dataclasses import dataclass

from fcplan.errors import UnknownNameError
from fcplan.metrics.compute import Metrics

__all__ = ["METRICS", "OUTCOMES", "MetricSpec", "format_metrics", "metric_spec"]


@dataclass(frozen=True)
class MetricSpec:
    """How one field of :class:`Metrics` is named, shown and compared (a row of :data:`METRICS`).

    Attributes
    ----------
    name : str
        The :class:`Metrics` field; ``"<definition>.<name>"`` is its column in episode summaries.
    label : str
        Row label of :func:`format_metrics` (``"overall firefighting (OFS)"``).
    unit : str
        ``"%"``, ``"penalty"`` (a positive penalty magnitude), ``"points"``, ``"s"``, ``"cells"``,
        ``"cell s"`` or ``""``.
    decimals : int
        Decimals of a ``mean ± ci`` cell in experiment tables.
    higher_is_better : bool
        Which way a difference between two schedulers counts as better.
    description : str
        What the metric measures, with its equation.
    symbol, column, title : str
        The manual's symbol (``"OFS"`` or ``""``), the short column header of experiment tables
        and the game's panels (``"OFS %"``), the full name on the game's evaluation page
        (``"Overall firefighting score (OFS)"``).
    """

    name: str
    label: str
    unit: str
    decimals: int
    higher_is_better: bool
    description: str
    symbol: str = ""
    column: str = ""
    title: str = ""

    @property
    def heading(self) -> str:
        """The label without its symbol, capitalised (``"Overall firefighting"``)."""
        text = self.label.split(" (")[0]
        return text[:1].upper() + text[1:]

    def key(self, definition: str = "manual") -> str:
        """The metric's column in episode summaries and sweep results (``"manual.perception"``)."""
        return f"{definition}.{self.name}"


METRICS: tuple[MetricSpec, ...] = (
    MetricSpec(
        name="total_negative_reward",
        label="total negative reward",
        unit="penalty",
        decimals=0,
        higher_is_better=False,
        description="NEG, Eq. (1): the fire's penalty over the episode",
        symbol="NEG",
        column="neg. reward",
        title="Total negative reward",
    ),
    MetricSpec(
        name="expected_negative_reward",
        label="expected negative reward",
        unit="penalty",
        decimals=0,
        higher_is_better=False,
        description="EXP, Eq. (8): the same penalty had nothing been pruned",
        symbol="EXP",
        column="exp. reward",
        title="Expected negative reward",
    ),
    MetricSpec(
        name="negative_reward_ratio",
        label="negative reward ratio",
        unit="%",
        decimals=1,
        higher_is_better=False,
        description="NRR, Eq. (7): 100 NEG / EXP",
        symbol="NRR",
        column="NRR %",
        title="Negative reward ratio (NRR)",
    ),
    MetricSpec(
        name="overall_firefighting",
        label="overall firefighting (OFS)",
        unit="%",
        decimals=1,
        higher_is_better=True,
        description="OFS, Eq. (2): percent of the cells that ever burned that were pruned",
        symbol="OFS",
        column="OFS %",
        title="Overall firefighting score (OFS)",
    ),
    MetricSpec(
        name="perception",
        label="perception (PS)",
        unit="%",
        decimals=1,
        higher_is_better=True,
        description="PS, Eq. (3): percent of the cells that ever burned that were sensed",
        symbol="PS",
        column="PS %",
        title="Perception score (PS)",
    ),
    MetricSpec(
        name="action",
        label="action (AS)",
        unit="%",
        decimals=1,
        higher_is_better=True,
        description="AS, Eq. (4): percent of the sensed cells that were pruned",
        symbol="AS",
        column="AS %",
        title="Action score (AS)",
    ),
    MetricSpec(
        name="facility_protection",
        label="facility protection (FPS)",
        unit="%",
        decimals=1,
        higher_is_better=True,
        description="FPS, Eq. (5): percent of facilities (depot included) never on fire",
        symbol="FPS",
        column="FPS %",
        title="Facility protection score (FPS)",
    ),
    MetricSpec(
        name="final_score",
        label="final score",
        unit="points",
        decimals=1,
        higher_is_better=True,
        description="Eq. (6): PS + AS + FPS - 3 NRR (reference2020 adds OFS)",
        symbol="",
        column="final score",
        title="Final score",
    ),
    MetricSpec(
        name="grade",
        label="grade",
        unit="",
        decimals=0,
        higher_is_better=True,
        description="verbal grade of the final score (grade())",
        symbol="",
        column="grade",
        title="Grade",
    ),
)
"""Every metric, in :class:`Metrics` field order: the one table of names, labels and units."""


OUTCOMES: tuple[MetricSpec, ...] = (
    MetricSpec(
        name="time_to_containment_s",
        label="time to containment",
        unit="s",
        decimals=1,
        higher_is_better=False,
        description="simulated seconds until no cell is active for the rest of the episode "
        "(the duration when fire is still active at the end)",
        column="contain s",
        title="Time to containment",
    ),
    MetricSpec(
        name="contained",
        label="contained",
        unit="",
        decimals=2,
        higher_is_better=True,
        description="1 when the fire was out before the episode ended, else 0",
        column="contained",
        title="Contained",
    ),
    MetricSpec(
        name="burned_area_cells",
        label="burned area",
        unit="cells",
        decimals=0,
        higher_is_better=False,
        description="cells that ever burned (active plus pruned at the end)",
        column="burned",
        title="Burned area",
    ),
    MetricSpec(
        name="facility_damage_cell_s",
        label="facility damage",
        unit="cell s",
        decimals=1,
        higher_is_better=False,
        description="active cells inside facility footprints integrated over simulated seconds",
        column="damage cell s",
        title="Facility damage",
    ),
)
"""The outcome metrics (:mod:`fcplan.metrics.outcomes`), in :class:`Outcomes` field order; their
episode-summary columns are ``"outcome.<name>"``."""


def metric_spec(name: str) -> MetricSpec:
    """The :data:`METRICS` (or :data:`OUTCOMES`) entry of a metric.

    Raises
    ------
    UnknownNameError
        If ``name`` is not a metric (the message lists the metrics).

    Examples
    --------
    >>> spec = metric_spec("overall_firefighting")
    >>> spec.column, spec.heading, spec.key("reference2020"), spec.higher_is_better
    ('OFS %', 'Overall firefighting', 'reference2020.overall_firefighting', True)
    """
    for spec in METRICS + OUTCOMES:
        if spec.name == name:
            return spec
    known = ", ".join(s.name for s in METRICS + OUTCOMES)
    raise UnknownNameError(f"unknown metric {name!r}; known metrics: {known}")


def format_metrics(metrics: dict[str, Metrics]) -> str:
    """A plain-text table of scores, one column per definition (for the CLI).

    Numbers are shown with 2 decimals; negative rewards are penalty magnitudes (the game shows them
    negated).

    Parameters
    ----------
    metrics : dict of str to Metrics
        Column title to scores, e.g. the result of :func:`~fcplan.metrics.compute_all`.

    Returns
    -------
    str
        A header line and one line per metric, no trailing newline.

    Examples
    --------
    >>> from fcplan.metrics import compute_all
    >>> from fcplan.trace import Trace
    >>> tr = Trace.from_counts(ticks_per_second=1, active=[1], pruned=[1],
    ...                        sensed_active=[1], sensed_ever=[2])
    >>> print(format_metrics(compute_all(tr)))
    metric                         unit            manual  reference2020
    total negative reward          penalty           0.10           0.10
    expected negative reward       penalty           0.20           0.20
    negative reward ratio          %                50.00          50.00
    overall firefighting (OFS)     %                50.00          50.00
    perception (PS)                %               100.00         100.00
    action (AS)                    %                50.00          50.00
    facility protection (FPS)      %               100.00         100.00
    final score                    points          100.00         150.00
    grade                                       Excellent      Excellent
    """
    names = list(metrics)

    def cell(v: float | str) -> str:
        return v if isinstance(v, str) else f"{v:.2f}"

    table = [["metric", "unit", *names]]
    for spec in METRICS:
        table.append(
            [spec.label, spec.unit, *(cell(getattr(metrics[k], spec.name)) for k in names)]
        )
    widths = [max(len(row[i]) for row in table) for i in range(len(table[0]))]
    widths[0] = max(widths[0], 30)
    widths[1] = max(widths[1], 7)
    lines = []
    for row in table:
        left = f"{row[0]:<{widths[0]}} {row[1]:<{widths[1]}}"
        right = "".join(f"  {c:>{max(widths[i + 2], 13)}}" for i, c in enumerate(row[2:]))
        lines.append((left + right).rstrip())
    return "\n".join(lines)
