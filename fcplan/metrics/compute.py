"""The two metric definitions computed from a trace: :class:`Metrics`, :func:`compute_metrics`.

:mod:`fcplan.metrics` states every equation of both definitions (``"manual"`` and
``"reference2020"``) and how each ambiguity of the manual was read; this module implements them
with numpy on the trace's per-tick counts (no loop over ticks). :func:`negative_reward_rate` is the
one source of the manual's per-tick penalty rate, which the environments' rewards use too.

Examples
--------
>>> from fcplan.trace import Trace
>>> tr = Trace.from_counts(ticks_per_second=1, active=[3, 2], pruned=[0, 2],
...                        sensed_active=[1, 1], sensed_ever=[1, 3])
>>> m = compute_metrics(tr)
>>> m.overall_firefighting, m.grade
(50.0, 'Failed')
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
    "grade",
    "negative_reward_rate",
]

DEFINITIONS: tuple[str, ...] = ("manual", "reference2020")
"""Names of the metric definitions, the default first."""

GRADES: tuple[str, ...] = ("Excellent", "Well Done", "Almost There!", "Fair", "Failed")
"""Verbal grades, best first."""

# Lower bounds of GRADES[:4]; "manual" bounds are inclusive, "reference2020" bounds strict.
_GRADE_BOUNDS: dict[str, tuple[float, ...]] = {
    "manual": (90.0, 80.0, 60.0, 50.0),
    "reference2020": (90.0, 70.0, 60.0, 50.0),
}


@dataclass(frozen=True)
class Metrics:
    """The scores of one trace under one definition.

    ``definition`` is ``"manual"`` or ``"reference2020"``; then one field per row of the metric
    table :data:`fcplan.metrics.METRICS`, in its order: NEG and EXP (positive penalty magnitudes;
    the game shows ``-NEG``), NRR, OFS, PS, AS, FPS (percent), the final score and the verbal
    ``grade`` (one of :data:`GRADES`). :func:`fcplan.metrics.metric_spec` describes each field.

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


def facility_penalty(in_facility: np.ndarray, penalties: np.ndarray) -> float:
    """``Σ_f PC_f n_f``: the facilities' part of the penalty rate, for active cell counts
    ``in_facility`` ((F,) ints, one tick's or summed over a window of ticks) and penalty
    coefficients ``penalties`` ((F,) floats).

    Examples
    --------
    >>> facility_penalty(np.array([0, 3]), np.array([5.0, 2.0]))
    6.0

    The sum is numpy's over the products, as in the rate of every tick (``_penalty_rate``), not
    a dot product: BLAS's order of additions and fused multiply-adds follow the CPU, so a
    fractional penalty's last bits would differ between machines.
    """
    return float((in_facility * penalties).sum())


def penalty_rate(active: float, facility_term: float, weight: float) -> float:
    """The manual's penalty rate ``w |A| + Σ_f PC_f n_f`` (Eq. (1) integrand) from the active cell
    count and the facility term (:func:`facility_penalty`). The rate is linear in the counts, so
    counts summed over a window of ticks give the rate summed over the window; divided by the
    ticks per second it is the negative reward the window accrues (what the environments'
    reward functions pay, :mod:`fcplan.env.reward`).

    Examples
    --------
    >>> penalty_rate(20, facility_penalty(np.array([3]), np.array([2.0])), 0.1)
    8.0
    """
    return weight * active + facility_term


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
    for bound, name in zip(_GRADE_BOUNDS[definition], GRADES, strict=False):
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

    ``manual`` integrates the penalty rates over the rows and is unrounded; ``reference2020`` gives
    the 2020 code's final-frame values. The module docstring states every equation and how each
    ambiguity of the manual was read.

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
