"""Tests of fcplan.metrics.compute: both score definitions, hand-computed and as invariants.

Equation numbers follow fcplan.metrics: the manual's score section in order, (1) total negative
reward ... (8) expected negative reward.
"""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.errors import FcplanError, UnknownNameError
from fcplan.metrics import (
    DEFINITIONS,
    GRADES,
    Metrics,
    compute_all,
    compute_metrics,
    format_metrics,
    grade,
    negative_reward_rate,
)
from fcplan.trace import Trace

KINDS5 = ("house", "house", "hospital", "power_station", "depot")
PC5 = (1.0, 1.0, 2.0, 5.0, 5.0)


# --------------------------------------------------------------------------------------------------
# Hand-built traces
# --------------------------------------------------------------------------------------------------


def small_trace() -> Trace:
    """4 ticks at 2 ticks/s (rows at 0.5, 1.0, 1.5, 2.0 s); house PC 1, hospital PC 2, depot PC 5.

    A+P = 2, 4, 5, 6 cells ever burned; pruned cells were all sensed (P <= sensed_ever), and
    sensed_active = sensed_ever - P.
    """
    return Trace.from_counts(
        ticks_per_second=2,
        active=[2, 4, 3, 2],
        pruned=[0, 0, 2, 4],
        sensed_active=[1, 2, 1, 1],
        sensed_ever=[1, 2, 3, 5],
        #                house hosp depot
        facility_burning=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        facility_pruned=[[0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 0, 0]],
        facility_kinds=("house", "hospital", "depot"),
        facility_penalties=[1.0, 2.0, 5.0],
        region_delays_s=[0.5],
    )


def steady_trace(
    *,
    tps: int = 4,
    seconds: int = 16,
    active: int = 30,
    pruned: int = 10,
    sensed_active: int = 15,
    sensed_ever: int = 25,
    burning=(1, 0, 1, 0, 0),
    fac_pruned=(0, 1, 0, 0, 0),
    kinds=KINDS5,
    penalties=PC5,
    delays=(0.0,),
    fire_mode: str = "uniform",
) -> Trace:
    """Every row equal (so both the integral and the final frame are easy by hand).

    Default: 16 s at 4 ticks/s, so T = 16 and T**1.25 = 32; A = 30, P = 10, |S∩A| = 15, E = 25;
    facilities house, house, hospital, power station, depot (PC 1, 1, 2, 5, 5); house 1 and the
    hospital each have 1 burning cell, house 2 had 1 cell pruned.
    """
    n = tps * seconds
    f = len(burning)
    return Trace.from_counts(
        ticks_per_second=tps,
        active=[active] * n,
        pruned=[pruned] * n,
        sensed_active=[sensed_active] * n,
        sensed_ever=[sensed_ever] * n,
        facility_burning=np.tile(np.asarray(burning, np.int64), (n, 1)).reshape(n, f),
        facility_pruned=np.tile(np.asarray(fac_pruned, np.int64), (n, 1)).reshape(n, f),
        facility_kinds=kinds,
        facility_penalties=penalties,
        region_delays_s=delays,
        fire_mode=fire_mode,
    )


# --------------------------------------------------------------------------------------------------
# manual definition, by hand
# --------------------------------------------------------------------------------------------------


def test_manual_every_equation_small_trace():
    """Manual Eqs. (1)-(8) on a time-varying trace with two facilities hit and the depot safe."""
    m = compute_metrics(small_trace())
    assert m.definition == "manual"
    # Eq. (1): rate = 0.1*A + 1*n_house + 2*n_hosp + 5*n_depot
    #   = [0.2+0, 0.4+1, 0.3+1+2, 0.2+2] = [0.2, 1.4, 3.3, 2.2]; sum 7.1; / 2 ticks/s = 3.55
    assert m.total_negative_reward == pytest.approx(3.55)
    # Eq. (8): 0.1*(A+P) + 1*(n+p)_house + 2*(n+p)_hosp
    #   = [0.2+0, 0.4+1, 0.5+1+2, 0.6+1+2] = [0.2, 1.4, 3.5, 3.6]; sum 8.7; / 2 = 4.35
    assert m.expected_negative_reward == pytest.approx(4.35)
    # Eq. (7): 100 * 3.55 / 4.35 = 81.6091954...
    assert m.negative_reward_ratio == pytest.approx(100 * 3.55 / 4.35)
    assert m.negative_reward_ratio == pytest.approx(81.60919540229885)
    # Eq. (2): 100 * P / (A+P) = 100 * 4/6
    assert m.overall_firefighting == pytest.approx(200 / 3)
    # Eq. (3): 100 * sensed_ever / (A+P) = 100 * 5/6
    assert m.perception == pytest.approx(250 / 3)
    # Eq. (4): 100 * P / sensed_ever = 100 * 4/5
    assert m.action == pytest.approx(80.0)
    # Eq. (5): house (burned then pruned) and hospital hit, depot safe: 100 * 1/3
    assert m.facility_protection == pytest.approx(100 / 3)
    # Eq. (6): PS + AS + FPS - 3 NRR = 83.333 + 80 + 33.333 - 244.828 = -48.161
    assert m.final_score == pytest.approx(250 / 3 + 80 + 100 / 3 - 3 * 100 * 3.55 / 4.35)
    assert m.final_score == pytest.approx(-48.16092, abs=1e-5)
    assert m.grade == "Failed"


def test_manual_multi_facility_penalties_steady():
    """Manual NEG/EXP weight each facility's burning (and, for EXP, pruned) cells by its PC."""
    m = compute_metrics(steady_trace())
    # rate: 0.1*30 + 1*1 (house 1) + 1*0 (house 2) + 2*1 (hospital) = 3 + 3 = 6 per s; 16 s -> 96
    assert m.total_negative_reward == pytest.approx(96.0)
    # expected rate: 0.1*40 + 1*1 + 1*(0+1) + 2*1 = 4 + 4 = 8 per s; 16 s -> 128
    assert m.expected_negative_reward == pytest.approx(128.0)
    assert m.negative_reward_ratio == pytest.approx(75.0)  # 100 * 96/128
    assert m.overall_firefighting == pytest.approx(25.0)  # 100 * 10/40
    assert m.perception == pytest.approx(62.5)  # 100 * 25/40
    assert m.action == pytest.approx(40.0)  # 100 * 10/25
    assert m.facility_protection == pytest.approx(40.0)  # power station + depot safe: 2/5
    assert m.final_score == pytest.approx(62.5 + 40 + 40 - 3 * 75)  # -82.5, no OFS
    assert m.grade == "Failed"


def test_manual_power_station_and_depot_penalty_5():
    """Manual NEG charges 5 per burning cell per second in a power station and in the depot."""
    tr = steady_trace(tps=1, seconds=2, burning=(0, 0, 0, 1, 2), fac_pruned=(0, 0, 0, 0, 0))
    # rate = 0.1*30 + 5*1 + 5*2 = 18 per s; 2 s -> 36
    assert compute_metrics(tr).total_negative_reward == pytest.approx(36.0)


def burning_depot_trace() -> Trace:
    """A steady trace at 1 tick/s: 5 active cells, nothing pruned or sensed, a house untouched and
    2 cells of the depot burning."""
    return steady_trace(
        tps=1,
        active=5,
        pruned=0,
        sensed_active=0,
        sensed_ever=0,
        burning=(0, 2),
        fac_pruned=(0, 0),
        kinds=("house", "depot"),
        penalties=(1.0, 5.0),
    )


def test_manual_depot_counted_in_fps():
    """FPS counts the depot as a facility: only the depot burning gives FPS = 100 * 1/2."""
    tr = burning_depot_trace()
    m = compute_metrics(tr)
    assert m.facility_protection == pytest.approx(50.0)
    # rate = 0.1*5 + 5*2 = 10.5 per s, 16 s -> 168; nothing pruned -> EXP = NEG, NRR = 100
    assert m.total_negative_reward == pytest.approx(168.0)
    assert m.negative_reward_ratio == 100.0
    # zero denominators: E = 0 -> PS = AS = 0; P = 0 -> OFS = 0; final = 0 + 0 + 50 - 300
    assert (m.overall_firefighting, m.perception, m.action) == (0.0, 0.0, 0.0)
    assert m.final_score == pytest.approx(-250.0)


def test_manual_nrr_is_exactly_100_when_nothing_pruned():
    """Manual NRR == 100 exactly when nothing (inside or outside facilities) was ever pruned."""
    tr = Trace.from_counts(
        ticks_per_second=10,
        active=[1, 3, 7, 12, 20],
        pruned=[0] * 5,
        sensed_active=[0, 1, 2, 5, 9],
        sensed_ever=[0, 1, 2, 5, 9],
        facility_burning=[[0, 0], [0, 1], [1, 2], [3, 2], [3, 4]],
        facility_pruned=[[0, 0]] * 5,
        facility_penalties=[2.0, 5.0],
    )
    m = compute_metrics(tr)
    assert m.total_negative_reward > 0
    assert m.negative_reward_ratio == 100.0
    assert m.total_negative_reward == m.expected_negative_reward


def test_manual_ignores_fire_mode_and_delays():
    """The manual definition does not depend on the fire mode or region delays."""
    a = compute_metrics(steady_trace(delays=(0.0,)))
    b = compute_metrics(steady_trace(delays=(0.0, 15.0, 20.0), fire_mode="specific"))
    assert a == b


def test_manual_neg_independent_of_tick_rate():
    """Manual NEG is an integral in simulated seconds: the same history at 2x tick rate scores the same."""
    slow = Trace.from_counts(
        ticks_per_second=1,
        active=[2, 6, 4],
        pruned=[0, 1, 4],
        sensed_active=[1, 3, 2],
        sensed_ever=[1, 4, 6],
        facility_burning=[1, 2, 0],
        facility_pruned=[0, 0, 2],
        facility_penalties=[2.0],
    )
    fast = Trace.from_counts(
        ticks_per_second=2,
        active=np.repeat(slow.active, 2),
        pruned=np.repeat(slow.pruned, 2),
        sensed_active=np.repeat(slow.sensed_active, 2),
        sensed_ever=np.repeat(slow.sensed_ever, 2),
        facility_burning=np.repeat(slow.facility_burning, 2, axis=0),
        facility_pruned=np.repeat(slow.facility_pruned, 2, axis=0),
        facility_penalties=[2.0],
    )
    ms, mf = compute_metrics(slow), compute_metrics(fast)
    # slow: rate = [0.2+2, 0.6+4, 0.4+0] = [2.2, 4.6, 0.4] -> 7.2
    assert ms.total_negative_reward == pytest.approx(7.2)
    assert mf.total_negative_reward == pytest.approx(7.2)
    assert mf.negative_reward_ratio == pytest.approx(ms.negative_reward_ratio)


def test_manual_facility_burned_then_pruned_counts_as_on_fire():
    """A facility whose fire was fully pruned was still on fire (FPS uses cumulative pruned cells)."""
    tr = Trace.from_counts(
        ticks_per_second=1,
        active=[1, 0],
        pruned=[0, 1],
        sensed_active=[1, 0],
        sensed_ever=[1, 1],
        facility_burning=[[1, 0], [0, 0]],
        facility_pruned=[[0, 0], [1, 0]],
        facility_penalties=[1.0, 5.0],
    )
    assert compute_metrics(tr).facility_protection == pytest.approx(50.0)
    assert compute_metrics(tr, "reference2020").facility_protection == 50.0


# --------------------------------------------------------------------------------------------------
# reference2020 definition, by hand
# --------------------------------------------------------------------------------------------------


def test_reference_every_equation_multi_facility():
    """reference2020 spec 5.1-5.4 on the final frame: instantaneous T**p penalty, rounding, OFS in final."""
    m = compute_metrics(steady_trace(), "reference2020")
    assert m.definition == "reference2020"
    # T = 64 ticks / 4 = 16 s, 16**1.25 = 32
    # NEG = 1*1 (house 1) + 2*1 (hospital) + 30 * 0.1 * 32 = 3 + 96 = 99 (house 2's cell is pruned)
    assert m.total_negative_reward == pytest.approx(99.0)
    # EXP = (30 + 10) * 0.1 * (16 - 0)**1.25 = 4 * 32 = 128
    assert m.expected_negative_reward == pytest.approx(128.0)
    assert m.negative_reward_ratio == 77.34  # round(100 * 99/128 = 77.34375, 2)
    assert m.overall_firefighting == 25.0  # round(100 * 10/40, 2)
    assert m.perception == 62.5  # round(100 * (15 + 10)/40, 2)
    assert m.action == 40.0  # round(100 * 10/(15 + 10), 2)
    assert m.facility_protection == 40.0  # safe: power station, depot -> round(100 * 2/5, 2)
    assert m.final_score == -64.52  # round(25 + 62.5 + 40 + 40 - 3*77.34 = 167.5 - 232.02, 2)
    assert m.grade == "Failed"


def test_reference_depot_counted_and_penalised():
    """reference2020 counts the depot in FPS and charges PC 5 per burning depot cell (not times T)."""
    tr = burning_depot_trace()
    m = compute_metrics(tr, "reference2020")
    # NEG = 5*2 + 5 * 0.1 * 16**1.25 = 10 + 16 = 26; EXP = 5 * 0.1 * 32 = 16
    assert m.total_negative_reward == pytest.approx(26.0)
    assert m.expected_negative_reward == pytest.approx(16.0)
    assert m.negative_reward_ratio == 162.5  # 100 * 26/16: can exceed 100
    assert m.facility_protection == 50.0  # house safe, depot hit
    assert (m.overall_firefighting, m.perception, m.action) == (0.0, 0.0, 0.0)  # 0/5, 0/5, 0/0
    assert m.final_score == -437.5  # 0 + 0 + 0 + 50 - 3*162.5


def test_reference_specific_mode_expectation_per_region_with_delays():
    """Specific mode sums (A+P) w max(T - d_i, 0)**p over regions, each with its own delay."""
    base = dict(burning=(0,), fac_pruned=(0,), kinds=("depot",), penalties=(5.0,))
    tr = steady_trace(delays=(0.0, 15.0, 20.0), fire_mode="specific", **base)
    m = compute_metrics(tr, "reference2020")
    # NEG = 30 * 0.1 * 32 = 96
    assert m.total_negative_reward == pytest.approx(96.0)
    # EXP = 40 * 0.1 * (16**1.25 + 1**1.25 + max(16 - 20, 0)**1.25) = 4 * (32 + 1 + 0) = 132
    assert m.expected_negative_reward == pytest.approx(132.0)
    assert m.negative_reward_ratio == 72.73  # round(9600/132 = 72.7272..., 2)
    # two regions with zero delay: EXP = 2 * 128 -> NRR = 37.5 = (100 - OFS) / 2
    two = compute_metrics(
        steady_trace(delays=(0.0, 0.0), fire_mode="specific", **base), "reference2020"
    )
    assert two.expected_negative_reward == pytest.approx(256.0)
    assert two.negative_reward_ratio == 37.5


def test_reference_uniform_mode_uses_the_delay():
    """Uniform mode uses (A+P) w max(T - d, 0)**p with the single delay d (0 once d >= T)."""
    base = dict(burning=(0,), fac_pruned=(0,), kinds=("depot",), penalties=(5.0,))
    m = compute_metrics(steady_trace(delays=(15.0,), **base), "reference2020")
    # EXP = 40 * 0.1 * (16 - 15)**1.25 = 4; NRR = round(100 * 96/4, 2)
    assert m.expected_negative_reward == pytest.approx(4.0)
    assert m.negative_reward_ratio == 2400.0
    late = compute_metrics(steady_trace(delays=(20.0,), **base), "reference2020")
    assert late.expected_negative_reward == 0.0
    assert late.negative_reward_ratio == 0.0  # EXP == 0 -> 0


def test_reference_nrr_is_100_minus_ofs_uniform_no_facility_hit():
    """reference2020, uniform mode, zero delay, no facility hit: NRR = 100 - OFS."""
    base = dict(burning=(0, 0), fac_pruned=(0, 0), kinds=("house", "depot"), penalties=(1.0, 5.0))
    m = compute_metrics(steady_trace(**base), "reference2020")
    # NEG = 30 * 0.1 * 32 = 96, EXP = 40 * 0.1 * 32 = 128, NRR = 75; OFS = 25
    assert m.negative_reward_ratio == 75.0
    assert m.negative_reward_ratio == 100.0 - m.overall_firefighting
    assert m.facility_protection == 100.0


def test_reference_uses_final_row_only():
    """reference2020 NEG is instantaneous: it depends on the final row, not the history."""
    tr = small_trace()
    m = compute_metrics(tr, "reference2020")
    # T = 4/2 = 2 s; NEG = 2*1 (hospital) + 2 * 0.1 * 2**1.25; EXP = 6 * 0.1 * (2 - 0.5)**1.25
    neg = 2.0 + 0.2 * 2.0**1.25
    exp = 0.6 * 1.5**1.25
    assert m.total_negative_reward == pytest.approx(neg)  # 2.4757
    assert m.expected_negative_reward == pytest.approx(exp)  # 0.9960
    assert m.negative_reward_ratio == round(100 * neg / exp, 2)  # 248.56
    assert m.negative_reward_ratio == 248.56
    assert m.overall_firefighting == 66.67  # round(400/6, 2)
    assert m.perception == 83.33  # round(100 * (1 + 4)/6, 2)
    assert m.action == 80.0  # round(100 * 4/(1 + 4), 2)
    assert m.facility_protection == 33.33  # round(100/3, 2)
    assert m.final_score == round(66.67 + 83.33 + 80.0 + 33.33 - 3 * 248.56, 2)  # -482.35
    assert m.final_score == -482.35


# --------------------------------------------------------------------------------------------------
# Zero denominators, empty traces, no facilities
# --------------------------------------------------------------------------------------------------


def test_zero_denominators_no_fire():
    """No fire at all: OFS, PS, AS, NRR are 0 (zero denominators); FPS 100; final 100 in both."""
    tr = steady_trace(
        tps=1,
        active=0,
        pruned=0,
        sensed_active=0,
        sensed_ever=0,
        burning=(0, 0),
        fac_pruned=(0, 0),
        kinds=("house", "depot"),
        penalties=(1.0, 5.0),
    )
    for name in DEFINITIONS:
        m = compute_metrics(tr, name)
        assert m.total_negative_reward == 0.0
        assert m.expected_negative_reward == 0.0
        assert m.negative_reward_ratio == 0.0
        assert (m.overall_firefighting, m.perception, m.action) == (0.0, 0.0, 0.0)
        assert m.facility_protection == 100.0
        assert m.final_score == 100.0  # manual: 0+0+100-0; reference: 0+0+0+100-0
        assert m.grade == "Excellent"


def test_zero_denominator_nothing_sensed():
    """Fire burning but never sensed: PS = 0 and AS = 0 (0/0) in both definitions."""
    tr = Trace.from_counts(
        ticks_per_second=1, active=[2, 3], pruned=[0, 0], sensed_active=[0, 0], sensed_ever=[0, 0]
    )
    for name in DEFINITIONS:
        m = compute_metrics(tr, name)
        assert (m.overall_firefighting, m.perception, m.action) == (0.0, 0.0, 0.0)


def test_no_facilities_gives_fps_100():
    """A trace without facility columns has FPS = 100 (no facility was ever on fire)."""
    tr = Trace.from_counts(
        ticks_per_second=1, active=[2], pruned=[1], sensed_active=[0], sensed_ever=[1]
    )
    assert compute_metrics(tr).facility_protection == 100.0
    assert compute_metrics(tr, "reference2020").facility_protection == 100.0


# --------------------------------------------------------------------------------------------------
# upto
# --------------------------------------------------------------------------------------------------


def test_upto_hand_computed():
    """upto=k scores rows [:k]: the online manual score after tick 2 of the small trace."""
    m = compute_metrics(small_trace(), upto=2)
    # rates [0.2, 1.4] -> NEG = 1.6/2 = 0.8; nothing pruned yet -> EXP = 0.8, NRR = 100
    assert m.total_negative_reward == pytest.approx(0.8)
    assert m.negative_reward_ratio == 100.0
    assert m.overall_firefighting == 0.0  # P = 0
    assert m.perception == pytest.approx(50.0)  # 100 * 2/4
    assert m.action == 0.0  # 0/2
    assert m.facility_protection == pytest.approx(200 / 3)  # only the house hit so far
    r = compute_metrics(small_trace(), "reference2020", upto=2)
    # T = 1 s: NEG = 1*1 + 4*0.1*1 = 1.4; EXP = 4*0.1*(1 - 0.5)**1.25
    assert r.total_negative_reward == pytest.approx(1.4)
    assert r.expected_negative_reward == pytest.approx(0.4 * 0.5**1.25)


def test_upto_none_and_full_are_the_same():
    """upto=None is the whole trace, equal to upto=n_ticks."""
    tr = small_trace()
    for name in DEFINITIONS:
        assert compute_metrics(tr, name) == compute_metrics(tr, name, upto=tr.n_ticks)


def test_upto_zero_is_an_empty_world():
    """upto=0 scores no rows: every count 0, T = 0, FPS 100."""
    for name in DEFINITIONS:
        m = compute_metrics(small_trace(), name, upto=0)
        assert m.total_negative_reward == 0.0
        assert m.negative_reward_ratio == 0.0
        assert m.facility_protection == 100.0


@pytest.mark.parametrize("upto", [-1, 5, 100])
def test_upto_out_of_range_raises(upto):
    """upto outside 0..n_ticks raises ValueError."""
    with pytest.raises(ValueError, match="upto"):
        compute_metrics(small_trace(), upto=upto)


# --------------------------------------------------------------------------------------------------
# Grades, names, API
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("score", "expected"),
    [
        (100.0, "Excellent"),
        (90.0, "Excellent"),  # boundary takes the higher grade
        (89.99, "Well Done"),
        (80.0, "Well Done"),
        (79.99, "Almost There!"),
        (60.0, "Almost There!"),
        (59.99, "Fair"),
        (50.0, "Fair"),
        (49.99, "Failed"),
        (-500.0, "Failed"),
        (float("nan"), "Failed"),
    ],
)
def test_grade_boundaries_manual(score, expected):
    """Manual grades: >=90 Excellent, >=80 Well Done, >=60 Almost There!, >=50 Fair, else Failed."""
    assert grade(score) == expected
    assert grade(score, "manual") == expected


@pytest.mark.parametrize(
    ("score", "expected"),
    [
        (90.01, "Excellent"),
        (90.0, "Well Done"),  # strict >
        (80.0, "Well Done"),
        (70.01, "Well Done"),
        (70.0, "Almost There!"),
        (60.01, "Almost There!"),
        (60.0, "Fair"),
        (50.01, "Fair"),
        (50.0, "Failed"),
        (-500.0, "Failed"),
    ],
)
def test_grade_boundaries_reference(score, expected):
    """reference2020 grades, strict >: 90 Excellent, 70 Well Done, 60 Almost There!, 50 Fair."""
    assert grade(score, "reference2020") == expected


def test_grade_used_in_metrics():
    """Metrics.grade is grade(final_score, definition)."""
    for m in compute_all(small_trace()).values():
        assert m.grade == grade(m.final_score, m.definition)
        assert m.grade in GRADES


def test_unknown_definition_raises_listing_known_names():
    """An unknown definition raises UnknownNameError whose message lists the known names."""
    for call in (
        lambda: compute_metrics(small_trace(), "paper"),
        lambda: grade(50.0, "paper"),
    ):
        with pytest.raises(UnknownNameError) as info:
            call()
        msg = str(info.value)
        assert "paper" in msg and "manual" in msg and "reference2020" in msg
        assert isinstance(info.value, FcplanError)


def test_reference_unknown_fire_mode_raises():
    """reference2020 rejects a fire mode other than uniform/specific."""
    tr = steady_trace(fire_mode="both")
    with pytest.raises(ValueError, match="fire_mode"):
        compute_metrics(tr, "reference2020")


def test_as_dict_fields_and_types():
    """Metrics.as_dict gives every field in order, floats as Python float."""
    m = compute_metrics(small_trace())
    d = m.as_dict()
    assert list(d) == [
        "definition",
        "total_negative_reward",
        "expected_negative_reward",
        "negative_reward_ratio",
        "overall_firefighting",
        "perception",
        "action",
        "facility_protection",
        "final_score",
        "grade",
    ]
    assert d["definition"] == "manual" and d["grade"] == m.grade
    assert all(type(v) is float for k, v in d.items() if k not in ("definition", "grade"))
    assert Metrics(**d) == m


def test_format_metrics_table():
    """format_metrics prints one column per definition and one line per metric."""
    text = format_metrics(compute_all(small_trace()))
    lines = text.splitlines()
    assert lines[0].split() == ["metric", "unit", "manual", "reference2020"]
    assert len(lines) == 10
    assert "final score" in text and "Failed" in text
    assert "248.56" in text  # reference NRR
    assert "3.55" in text  # manual NEG


def test_negative_reward_rate_hand_computed():
    """negative_reward_rate is w|A| + sum_f PC_f n_f per second; its sum / tps is the manual NEG."""
    tr = small_trace()
    rate = negative_reward_rate(tr)
    np.testing.assert_allclose(rate, [0.2, 1.4, 3.3, 2.2])  # see test_manual_every_equation
    assert rate.dtype == np.float64 and rate.shape == (4,)
    assert rate.sum() / tr.ticks_per_second == pytest.approx(
        compute_metrics(tr).total_negative_reward
    )


@pytest.mark.parametrize("n_fac", [0, 1, 3, 7, 8, 13])
def test_facility_penalty_is_the_rate_s_own_sum(n_fac):
    """``facility_penalty`` of one tick's counts is, bit for bit, the facility term of that
    tick's row of the per-tick rate (``_penalty_rate``), for fractional penalties too: one
    order of additions (numpy's sum, not a BLAS dot whose order follows the CPU)."""
    from fcplan.metrics.compute import _penalty_rate, facility_penalty

    rng = np.random.default_rng(n_fac)
    counts = rng.integers(0, 400, size=(50, n_fac))
    pen = rng.random(n_fac) * 10.0
    rows = _penalty_rate(np.zeros(50), counts, pen, 0.0)
    assert [facility_penalty(c, pen) for c in counts] == rows.tolist()
