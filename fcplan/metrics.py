"""Episode scores: FireCommander's performance metrics, under two named definitions.

A FireCommander episode is scored on how much of the fire the team put out, how much of it the team
saw, how well it acted on what it saw, which facilities it kept from burning, and how much penalty
the burning fire cost over time. Every score here is a pure function of a :class:`~fcplan.trace.Trace`
(per-tick counts), so a live episode, a replay and a hand-written test array score identically.

Two definitions are computed from the same trace (:data:`DEFINITIONS`):

``"manual"`` (default)
    The FireCommander manual's equations read consistently: the penalty is integrated over simulated
    seconds, the expected penalty is the same fire's penalty had nothing been pruned, and the grade
    uses the manual's 50/60/80/90 bands. Values are not rounded. All numpy, no loop over ticks.
``"reference2020"``
    Exactly what the 2020 reference code computed on its final frame: an instantaneous ``T**1.25``
    penalty, a per-region expectation, every score rounded to 2 decimals, a final score that also adds
    OFS, and grade thresholds 50/60/70/90. Use it to compare with data recorded by the original GUI.

Equation numbers
----------------
"Eq. (k)" below counts the eight equations of the manual's score section ("Preview, Tutorial,
Information and Score Display Pages") in the order they appear; the LaTeX label is given too. (The
compiled manual numbers them 7-14, because six equations precede them.)

====  ================================  ===================================================
Eq.   LaTeX label                       quantity
====  ================================  ===================================================
(1)   ``eq:totalnegreward``             total negative reward, NEG
(2)   ``eq:overallfirefightingscore``   overall firefighting score, OFS
(3)   ``eq:perceptionscore``            perception score, PS
(4)   ``eq:actionscore``                action score, AS
(5)   ``eq:facilityprrotectionscore``   facility protection score, FPS
(6)   ``eq:finalscore``                 final score
(7)   ``eq:negativerewardratio``        negative reward ratio, NRR
(8)   ``eq:expectednegativereward``     expected negative reward, EXP
====  ================================  ===================================================

Notation
--------
Per trace row ``t`` (the world after a tick, at ``(k + 1) / tps`` seconds): ``A(t)`` active
(burning, unpruned) cells, ``P(t)`` cumulative pruned cells, ``S∩A(t)`` active cells sensed at least
once, ``E(t)`` cells of ``A ∪ P`` sensed at least once (``sensed_ever``), ``n_f(t)`` active cells
inside facility footprint ``f``, ``p_f(t)`` cumulative pruned cells inside ``f``, ``PC_f`` the penalty
coefficient of ``f`` (house 1, hospital 2, power station 5, depot 5), ``w`` the fire propagation
weight (0.1), ``p`` the temporal exponent (1.25), ``tps`` ticks per second, ``T`` the duration of the
rows used in seconds. ``A + P`` is every cell that ever burned. Unsubscripted counts are the last
row's.

Sign convention
---------------
The negative reward is reported as a **positive magnitude** (a penalty; larger is worse). The game
displays it as ``-NEG`` ("Score: -NEG"), and an RL reward is ``-negative_reward_rate(trace) / tps``.

Definition ``"manual"``
-----------------------
* NEG, Eq. (1): ``NEG = ∫ (w A(t) + Σ_f PC_f n_f(t)) dt = Σ_t (w A(t) + Σ_f PC_f n_f(t)) / tps``.
  The manual prints "0.1 x Active + Penalty Coef + Firespots in Targets"; the "+" between the
  coefficient and the count is read as "x" (the slides say "PC x #firespots in targets"), and since
  the penalties apply "per firespot per time-step" the rate is integrated over simulated seconds (a
  tick contributes ``1 / tps`` of its rate), so the value does not depend on the tick rate.
* EXP, Eq. (8): ``EXP = Σ_t (w (A + P)(t) + Σ_f PC_f (n_f + p_f)(t)) / tps``, the same integral had
  nothing been pruned (pruned cells, also those inside footprints, counted as still burning). The
  manual's ``Σ_t 0.1 N0 t`` assumes linear growth from the initial count; the episode's own fire is
  used instead, so the ratio measures what pruning saved.
* NRR, Eq. (7): ``NRR = 100 NEG / EXP`` (0 when ``EXP = 0``). Every term of NEG is at most the
  matching term of EXP, so ``0 <= NRR <= 100``, and ``NRR = 100`` exactly when nothing was pruned.
* OFS, Eq. (2): ``OFS = 100 P / (A + P)``. The equation (pruned over total) is used; the text's
  "active to total" is a typo.
* PS, Eq. (3): ``PS = 100 E / (A + P)``: "number of sensed firespots" is every cell that ever burned
  and was ever sensed (pruned cells included).
* AS, Eq. (4): ``AS = 100 P / E``. With the default rule that only sensed cells can be pruned,
  ``P <= E`` so ``AS <= 100`` and ``PS >= OFS``; under the reference's looser pruning gate a trace
  can have ``P > E`` and AS above 100 (it is not clipped).
* FPS, Eq. (5): ``FPS = 100 (#facilities never on fire) / (#facilities)``, the depot counted as a
  facility (the manual gives the agent base a penalty coefficient, so it is a target). Facility ``f``
  was on fire iff ``n_f + p_f > 0`` in some row; since ``p_f`` is cumulative this is the last row's
  test for a consistent trace.
* Final score, Eq. (6): ``final = PS + AS + FPS - 3 NRR`` (no OFS).
* Grade (manual's verbal evaluation): Excellent ``>= 90``, Well Done ``[80, 90)``, Almost There!
  ``[60, 80)``, Fair ``[50, 60)``, Failed ``< 50``. The manual writes strict inequalities on both
  sides and so leaves the boundaries ungraded; a boundary takes the higher grade.

Definition ``"reference2020"``
------------------------------
The 2020 code's values at its final frame (specification sections 5.1-5.4), with ``T`` the trace
duration in seconds (the 2020 clock was the wall clock):

* NEG: ``NEG = Σ_f PC_f n_f(T) + A(T) w T**p``, instantaneous (not a sum over time).
* EXP: uniform fire mode ``(A + P) w max(T - d, 0)**p``; specific mode
  ``Σ_i (A + P) w max(T - d_i, 0)**p``, the whole count once per region ``i`` with its own delay.
* ``NRR = round(100 NEG / EXP, 2)``, 0 if ``EXP == 0``. It can exceed 100; with no facility hit and
  zero delay, uniform mode gives ``NRR = 100 - OFS``.
* ``OFS = round(100 P / (A + P), 2)``, ``PS = round(100 (S∩A + P) / (A + P), 2)``,
  ``AS = round(100 P / (S∩A + P), 2)``, ``FPS = round(100 safe / N_fac, 2)`` (depot included).
* ``final = round(OFS + PS + AS + FPS - 3 NRR, 2)`` from the rounded parts; grade thresholds strict
  ``>``: > 90 Excellent, > 70 Well Done, > 60 Almost There!, > 50 Fair, otherwise Failed.

Edge cases (both definitions)
-----------------------------
* A zero denominator gives 0 for OFS, PS, AS and NRR (as the 2020 code did).
* A trace with no facility columns has FPS = 100 (no facility was ever on fire); the 2020 game always
  had at least the depot.
* ``upto=0`` (no rows) scores an empty world: every count 0, ``T = 0``.

Examples
--------
>>> from fcplan.trace import Trace
>>> from fcplan.metrics import compute_all, format_metrics
>>> tr = Trace.from_counts(ticks_per_second=2, active=[2, 4, 3, 2], pruned=[0, 0, 2, 4],
...                        sensed_active=[1, 2, 1, 1], sensed_ever=[1, 2, 3, 5])
>>> m = compute_all(tr)
>>> round(m["manual"].total_negative_reward, 6), m["manual"].overall_firefighting
(0.55, 66.66666666666667)
>>> m["reference2020"].overall_firefighting
66.67
>>> print(format_metrics(m).splitlines()[0])
metric                         unit            manual  reference2020
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, fields

import numpy as np

from fcplan.errors import UnknownNameError
from fcplan.trace import Trace

__all__ = [
    "DEFINITIONS",
    "GRADES",
    "Metrics",
    "compute_all",
    "compute_metrics",
    "format_metrics",
    "grade",
    "negative_reward_rate",
]

DEFINITIONS: tuple[str, ...] = ("manual", "reference2020")
"""Names of the metric definitions, the default first."""

GRADES: tuple[str, ...] = ("Excellent", "Well Done", "Almost There!", "Fair", "Failed")
"""Verbal grades, best first."""

# (lower bound, grade), best first; "manual" bounds are inclusive, "reference2020" bounds strict.
_GRADE_BANDS: dict[str, tuple[tuple[float, str], ...]] = {
    "manual": ((90.0, "Excellent"), (80.0, "Well Done"), (60.0, "Almost There!"), (50.0, "Fair")),
    "reference2020": (
        (90.0, "Excellent"),
        (70.0, "Well Done"),
        (60.0, "Almost There!"),
        (50.0, "Fair"),
    ),
}


@dataclass(frozen=True)
class Metrics:
    """The scores of one trace under one definition.

    Attributes
    ----------
    definition : str
        ``"manual"`` or ``"reference2020"``.
    total_negative_reward : float
        NEG, Eq. (1), as a positive penalty magnitude (the game shows ``-NEG``).
    expected_negative_reward : float
        EXP, Eq. (8), same units as NEG.
    negative_reward_ratio : float
        NRR = 100 NEG / EXP, Eq. (7), percent.
    overall_firefighting : float
        OFS, Eq. (2), percent of the cells that ever burned that were pruned.
    perception : float
        PS, Eq. (3), percent.
    action : float
        AS, Eq. (4), percent.
    facility_protection : float
        FPS, Eq. (5), percent of facilities (depot included) never on fire.
    final_score : float
        Eq. (6) (``reference2020`` also adds OFS).
    grade : str
        One of :data:`GRADES`, by :func:`grade`.

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> tr = Trace.from_counts(ticks_per_second=1, active=[1], pruned=[1],
    ...                        sensed_active=[0], sensed_ever=[2])
    >>> compute_metrics(tr).as_dict()["overall_firefighting"]
    50.0
    """

    definition: str
    total_negative_reward: float
    expected_negative_reward: float
    negative_reward_ratio: float
    overall_firefighting: float
    perception: float
    action: float
    facility_protection: float
    final_score: float
    grade: str

    def as_dict(self) -> dict[str, float | str]:
        """Field name to value, in declaration order (floats as Python ``float``).

        Returns
        -------
        dict of str to float or str
            ``{"definition": ..., "total_negative_reward": ..., ..., "grade": ...}``.

        Examples
        --------
        >>> from fcplan.trace import Trace
        >>> tr = Trace.from_counts(ticks_per_second=1, active=[0], pruned=[0],
        ...                        sensed_active=[0], sensed_ever=[0])
        >>> list(compute_metrics(tr).as_dict())[:2]
        ['definition', 'total_negative_reward']
        """
        out: dict[str, float | str] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = v if isinstance(v, str) else float(v)
        return out


def _check_definition(definition: str) -> None:
    if definition not in DEFINITIONS:
        raise UnknownNameError(
            f"unknown metrics definition {definition!r}; known definitions: {', '.join(DEFINITIONS)}"
        )


def _n_rows(trace: Trace, upto: int | None) -> int:
    n = trace.n_ticks
    if upto is None:
        return n
    k = operator.index(upto)
    if not 0 <= k <= n:
        raise ValueError(f"upto must be an integer in 0..{n} (the trace's ticks), got {upto!r}")
    return k


def _pct(num: float, den: float) -> float:
    """``100 num / den``, 0 on a zero denominator."""
    return 100.0 * num / den if den else 0.0


def _penalty_rate(
    active: np.ndarray, in_facility: np.ndarray, penalties: np.ndarray, w: float
) -> np.ndarray:
    """``w active(t) + Σ_f PC_f in_facility_f(t)`` per row (an empty facility axis sums to 0)."""
    return w * active + (in_facility * penalties).sum(axis=1)


def _facility_protection(burning: np.ndarray, pruned: np.ndarray) -> float:
    """FPS (unrounded): percent of facility columns with no burning or pruned cell in any row."""
    n_fac = burning.shape[1]
    if n_fac == 0:
        return 100.0
    hit = ((burning + pruned) > 0).any(axis=0)
    return 100.0 * float(n_fac - int(hit.sum())) / n_fac


def negative_reward_rate(trace: Trace) -> np.ndarray:
    """Manual penalty rate of each row, per simulated second (Eq. (1) integrand).

    ``rate(t) = w |A(t)| + Σ_f PC_f n_f(t)``: ``w`` per active cell plus each facility's penalty
    coefficient per active cell inside its footprint (the manual's "+" between coefficient and count
    read as "x"). A tick's share is ``rate / tps``, so ``rate.sum() / tps`` is the manual total
    negative reward and ``-rate / tps`` is a per-tick RL reward.

    Parameters
    ----------
    trace : Trace
        The episode trace.

    Returns
    -------
    numpy.ndarray
        ``(T,)`` float64, non-negative for non-negative penalties.

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> tr = Trace.from_counts(ticks_per_second=10, active=[10, 20], pruned=[0, 0],
    ...                        sensed_active=[0, 0], sensed_ever=[0, 0],
    ...                        facility_burning=[[0], [3]], facility_penalties=[2.0])
    >>> negative_reward_rate(tr)   # 0.1*10 + 2*0, 0.1*20 + 2*3
    array([1., 8.])
    """
    return _penalty_rate(
        trace.active,
        trace.facility_burning,
        np.asarray(trace.facility_penalties, dtype=np.float64),
        trace.propagation_weight,
    ).astype(np.float64, copy=False)


def grade(final_score: float, definition: str = "manual") -> str:
    """Verbal grade of a final score.

    ``manual`` (the manual's evaluation, a boundary takes the higher grade): Excellent ``>= 90``,
    Well Done ``>= 80``, Almost There! ``>= 60``, Fair ``>= 50``, otherwise Failed.
    ``reference2020`` (the 2020 code, strict): Excellent ``> 90``, Well Done ``> 70``,
    Almost There! ``> 60``, Fair ``> 50``, otherwise Failed. NaN is Failed.

    Parameters
    ----------
    final_score : float
        A final score (Eq. (6)).
    definition : str, default "manual"
        One of :data:`DEFINITIONS`.

    Returns
    -------
    str
        One of :data:`GRADES`.

    Raises
    ------
    UnknownNameError
        If ``definition`` is not known.

    Examples
    --------
    >>> grade(80.0), grade(80.0, "reference2020"), grade(90.0, "reference2020")
    ('Well Done', 'Well Done', 'Well Done')
    >>> grade(90.0), grade(49.9)
    ('Excellent', 'Failed')
    """
    _check_definition(definition)
    strict = definition == "reference2020"
    x = float(final_score)
    for bound, name in _GRADE_BANDS[definition]:
        if (x > bound) if strict else (x >= bound):
            return name
    return "Failed"


def _manual(trace: Trace, n: int) -> Metrics:
    w = trace.propagation_weight
    pcs = np.asarray(trace.facility_penalties, dtype=np.float64)
    active, pruned = trace.active[:n], trace.pruned[:n]
    burning, fac_pruned = trace.facility_burning[:n], trace.facility_pruned[:n]

    neg = float(_penalty_rate(active, burning, pcs, w).sum()) / trace.ticks_per_second
    exp = float(_penalty_rate(active + pruned, burning + fac_pruned, pcs, w).sum())
    exp /= trace.ticks_per_second
    # 100 * (neg / exp) rather than 100 * neg / exp: neg <= exp term by term, so the quotient is <= 1
    # in floating point too and NRR never exceeds 100 by a rounding error.
    nrr = 100.0 * (neg / exp) if exp else 0.0

    a = int(active[-1]) if n else 0
    p = int(pruned[-1]) if n else 0
    e = int(trace.sensed_ever[n - 1]) if n else 0
    ofs = _pct(p, a + p)
    ps = _pct(e, a + p)
    as_ = _pct(p, e)
    fps = _facility_protection(burning, fac_pruned)
    final = ps + as_ + fps - 3.0 * nrr
    return Metrics(
        definition="manual",
        total_negative_reward=neg,
        expected_negative_reward=exp,
        negative_reward_ratio=nrr,
        overall_firefighting=ofs,
        perception=ps,
        action=as_,
        facility_protection=fps,
        final_score=final,
        grade=grade(final, "manual"),
    )


def _reference2020(trace: Trace, n: int) -> Metrics:
    if trace.fire_mode not in ("uniform", "specific"):
        raise ValueError(
            f"Trace.fire_mode must be 'uniform' or 'specific', got {trace.fire_mode!r}"
        )
    w, p_exp = trace.propagation_weight, trace.temporal_exponent
    pcs = np.asarray(trace.facility_penalties, dtype=np.float64)
    t_s = n / trace.ticks_per_second
    if n:
        a, p = int(trace.active[n - 1]), int(trace.pruned[n - 1])
        sa = int(trace.sensed_active[n - 1])
        in_fac = float((trace.facility_burning[n - 1] * pcs).sum())
    else:
        a = p = sa = 0
        in_fac = 0.0

    neg = in_fac + a * w * t_s**p_exp
    delays = np.asarray(trace.region_delays_s, dtype=np.float64).ravel()
    if trace.fire_mode == "uniform":
        d = float(delays.min()) if delays.size else 0.0
        exp = (a + p) * w * max(t_s - d, 0.0) ** p_exp
    else:
        exp = sum((a + p) * w * max(t_s - float(d), 0.0) ** p_exp for d in delays)
    exp = float(exp)
    nrr = round(100.0 * neg / exp, 2) if exp != 0 else 0.0

    ofs = round(_pct(p, a + p), 2)
    ps = round(_pct(sa + p, a + p), 2)
    as_ = round(_pct(p, sa + p), 2)
    fps = round(_facility_protection(trace.facility_burning[:n], trace.facility_pruned[:n]), 2)
    final = round(ofs + ps + as_ + fps - 3.0 * nrr, 2)
    return Metrics(
        definition="reference2020",
        total_negative_reward=float(neg),
        expected_negative_reward=exp,
        negative_reward_ratio=float(nrr),
        overall_firefighting=float(ofs),
        perception=float(ps),
        action=float(as_),
        facility_protection=float(fps),
        final_score=float(final),
        grade=grade(final, "reference2020"),
    )


def compute_metrics(
    trace: Trace, definition: str = "manual", *, upto: int | None = None
) -> Metrics:
    """Score a trace under one definition.

    ``manual``: NEG and EXP integrate per-second penalty rates over the rows (Eqs. (1), (8)),
    NRR = 100 NEG / EXP (Eq. (7)), OFS = 100 P / (A + P) (Eq. (2)), PS = 100 E / (A + P) (Eq. (3),
    ``E`` = cells ever sensed), AS = 100 P / E (Eq. (4)), FPS = percent of facilities, depot included,
    never on fire (Eq. (5)), final = PS + AS + FPS - 3 NRR (Eq. (6)), unrounded.
    ``reference2020``: the 2020 code's final-frame values (instantaneous ``A w T**p`` penalty,
    per-region expectation, rounding to 2 decimals, final score with OFS). See the module docstring
    for every equation and how each ambiguity was read.

    Parameters
    ----------
    trace : Trace
        The episode trace. It is not modified.
    definition : str, default "manual"
        One of :data:`DEFINITIONS`.
    upto : int, optional
        Score only rows ``[:upto]``, i.e. the online score after tick ``upto`` (``T = upto / tps``).
        Must be in ``0..trace.n_ticks``; default all rows.

    Returns
    -------
    Metrics

    Raises
    ------
    UnknownNameError
        If ``definition`` is not known (the message lists the known names).
    ValueError
        If ``upto`` is out of range, or ``trace.fire_mode`` is unknown (``reference2020``).

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> tr = Trace.from_counts(ticks_per_second=1, active=[4, 4], pruned=[0, 4],
    ...                        sensed_active=[2, 0], sensed_ever=[2, 4])
    >>> m = compute_metrics(tr)   # NEG = 0.1*4 + 0.1*4, EXP = 0.1*4 + 0.1*8
    >>> round(m.total_negative_reward, 9), round(m.negative_reward_ratio, 4)
    (0.8, 66.6667)
    >>> compute_metrics(tr, upto=1).negative_reward_ratio   # nothing pruned yet
    100.0
    """
    _check_definition(definition)
    n = _n_rows(trace, upto)
    if definition == "manual":
        return _manual(trace, n)
    return _reference2020(trace, n)


def compute_all(trace: Trace) -> dict[str, Metrics]:
    """Score a trace under every definition.

    Parameters
    ----------
    trace : Trace
        The episode trace.

    Returns
    -------
    dict of str to Metrics
        Keyed by definition name, in :data:`DEFINITIONS` order.

    Examples
    --------
    >>> from fcplan.trace import Trace
    >>> tr = Trace.from_counts(ticks_per_second=1, active=[1], pruned=[0],
    ...                        sensed_active=[1], sensed_ever=[1])
    >>> list(compute_all(tr))
    ['manual', 'reference2020']
    """
    return {name: compute_metrics(trace, name) for name in DEFINITIONS}


_ROWS: tuple[tuple[str, str, str], ...] = (
    ("total_negative_reward", "total negative reward", "penalty"),
    ("expected_negative_reward", "expected negative reward", "penalty"),
    ("negative_reward_ratio", "negative reward ratio", "%"),
    ("overall_firefighting", "overall firefighting (OFS)", "%"),
    ("perception", "perception (PS)", "%"),
    ("action", "action (AS)", "%"),
    ("facility_protection", "facility protection (FPS)", "%"),
    ("final_score", "final score", "points"),
    ("grade", "grade", ""),
)


def format_metrics(metrics: dict[str, Metrics]) -> str:
    """A plain-text table of scores, one column per definition (for the CLI).

    Numbers are shown with 2 decimals; negative rewards are penalty magnitudes (the game shows them
    negated).

    Parameters
    ----------
    metrics : dict of str to Metrics
        Column title to scores, e.g. the result of :func:`compute_all`.

    Returns
    -------
    str
        A header line and one line per metric, no trailing newline.

    Examples
    --------
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
    for attr, label, unit in _ROWS:
        table.append([label, unit, *(cell(getattr(metrics[k], attr)) for k in names)])
    widths = [max(len(row[i]) for row in table) for i in range(len(table[0]))]
    widths[0] = max(widths[0], 30)
    widths[1] = max(widths[1], 7)
    lines = []
    for row in table:
        left = f"{row[0]:<{widths[0]}} {row[1]:<{widths[1]}}"
        right = "".join(f"  {c:>{max(widths[i + 2], 13)}}" for i, c in enumerate(row[2:]))
        lines.append((left + right).rstrip())
    return "\n".join(lines)
