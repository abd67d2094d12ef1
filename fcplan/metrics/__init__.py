"""Episode scores: FireCommander's performance metrics, under two named definitions.

A FireCommander episode is scored on how much of the fire the team put out, how much of it the team
saw, how well it acted on what it saw, which facilities it kept from burning, and how much penalty
the burning fire cost over time. Every score here is a pure function of a :class:`~fcplan.trace.Trace`
(per-tick counts), so a live episode, a replay and a hand-written test array score identically.

Every metric is described once, in :data:`METRICS` (a :class:`MetricSpec` per field of
:class:`Metrics`: name, labels, unit, decimals, whether higher is better, what it measures); the
CLI's text table, the experiment tables and reports, and the game's score panels all iterate it.
The scores are computed in :mod:`fcplan.metrics.compute` and the table lives in
:mod:`fcplan.metrics.table`; everything is imported from ``fcplan.metrics``.

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

from fcplan.metrics.compute import (
    DEFINITIONS,
    GRADES,
    Metrics,
    compute_all,
    compute_metrics,
    facility_penalty,
    grade,
    negative_reward_rate,
    penalty_rate,
)
from fcplan.metrics.outcomes import Outcomes, compute_outcomes
from fcplan.metrics.table import METRICS, OUTCOMES, MetricSpec, format_metrics, metric_spec

__all__ = [
    "DEFINITIONS",
    "GRADES",
    "METRICS",
    "OUTCOMES",
    "MetricSpec",
    "Metrics",
    "compute_all",
    "compute_metrics",
    "format_metrics",
    "grade",
    "metric_spec",
    "facility_penalty",
    "negative_reward_rate",
    "penalty_rate",
    "Outcomes",
    "compute_outcomes",
]
