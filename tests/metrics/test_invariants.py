"""Invariants of fcplan.metrics.compute on random consistent traces (hypothesis): ranges, the
final-score formulas, the penalty rate's integral, scoring a prefix."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.metrics import (
    DEFINITIONS,
    compute_all,
    compute_metrics,
    negative_reward_rate,
)
from fcplan.trace import AgentTrace, Trace


@st.composite
def traces(draw, *, pruning: bool = True, facilities: bool = True) -> Trace:
    """Random consistent traces.

    Cells ever burned grow; sensed_ever grows and is <= ever burned; pruned grows and is <=
    sensed_ever (only sensed cells are pruned); sensed_active = sensed_ever - pruned. Per facility,
    cells ever in the footprint grow, pruned-in-footprint grows and is <= them.
    """
    n = draw(st.integers(1, 40))
    tps = draw(st.sampled_from([1, 2, 5, 10]))
    n_fac = draw(st.integers(0, 6)) if facilities else 0
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    ignite = rng.integers(0, 6, n)
    ignite[0] += draw(st.integers(0, 5))
    ever = np.cumsum(ignite)
    sensed_ever = np.maximum.accumulate(rng.integers(0, ever + 1))
    if pruning:
        pruned = np.maximum.accumulate(rng.integers(0, sensed_ever + 1))
    else:
        pruned = np.zeros(n, np.int64)
    burning = np.zeros((n, n_fac), np.int64)
    fac_pruned = np.zeros((n, n_fac), np.int64)
    for f in range(n_fac):
        if rng.random() < 0.4:
            continue  # this facility never burns
        fac_ever = np.minimum(np.cumsum(rng.integers(0, 3, n)), ever)
        if pruning:
            fac_pruned[:, f] = np.maximum.accumulate(rng.integers(0, fac_ever + 1))
        burning[:, f] = fac_ever - fac_pruned[:, f]
    penalties = rng.choice([0.5, 1.0, 2.0, 5.0], n_fac)
    n_reg = draw(st.integers(1, 4))
    return Trace.from_counts(
        ticks_per_second=tps,
        active=ever - pruned,
        pruned=pruned,
        sensed_active=sensed_ever - pruned,
        sensed_ever=sensed_ever,
        facility_burning=burning,
        facility_pruned=fac_pruned,
        facility_penalties=penalties,
        region_delays_s=rng.uniform(0, n / tps, n_reg) * (rng.random(n_reg) < 0.5),
        fire_mode=draw(st.sampled_from(["uniform", "specific"])),
        propagation_weight=draw(st.sampled_from([0.1, 0.05, 1.0])),
    )


SETTINGS = settings(max_examples=150, deadline=None)


@SETTINGS
@given(traces())
def test_manual_nrr_in_0_100(tr):
    """Manual NRR lies in [0, 100] on any consistent trace."""
    m = compute_metrics(tr)
    assert 0.0 <= m.negative_reward_ratio <= 100.0
    assert 0.0 <= m.total_negative_reward <= m.expected_negative_reward


@SETTINGS
@given(traces())
def test_scores_are_percentages_and_ps_ge_ofs(tr):
    """OFS, PS, AS, FPS lie in [0, 100] and PS >= OFS, in both definitions."""
    for m in compute_all(tr).values():
        for v in (m.overall_firefighting, m.perception, m.action, m.facility_protection):
            assert 0.0 <= v <= 100.0
        assert m.perception >= m.overall_firefighting


@SETTINGS
@given(traces())
def test_final_score_formulas(tr):
    """Manual final = PS + AS + FPS - 3 NRR; reference final = round(OFS + PS + AS + FPS - 3 NRR, 2)."""
    m = compute_metrics(tr)
    assert m.final_score == pytest.approx(
        m.perception + m.action + m.facility_protection - 3 * m.negative_reward_ratio,
        rel=1e-12,
        abs=1e-9,
    )
    r = compute_metrics(tr, "reference2020")
    parts = r.overall_firefighting + r.perception + r.action + r.facility_protection
    assert r.final_score == round(parts - 3 * r.negative_reward_ratio, 2)
    for x in (r.negative_reward_ratio, r.overall_firefighting, r.perception, r.action):
        assert x == round(x, 2)


@SETTINGS
@given(traces())
def test_compute_all_returns_both(tr):
    """compute_all returns one Metrics per definition, equal to compute_metrics for each."""
    out = compute_all(tr)
    assert tuple(out) == DEFINITIONS
    for name, m in out.items():
        assert m.definition == name
        assert m == compute_metrics(tr, name)


@SETTINGS
@given(traces())
def test_metrics_depend_only_on_the_trace(tr):
    """Scores are a pure function of the trace: repeatable, copy-invariant, agents ignored, trace untouched."""
    before = {k: v.copy() for k, v in tr.arrays().items()}
    first = compute_all(tr)
    assert compute_all(tr) == first
    assert compute_all(copy.deepcopy(tr)) == first
    n = tr.n_ticks
    agents = AgentTrace(
        ids=("p0",),
        xyz=np.zeros((n, 1, 3)),
        battery=np.ones((n, 1)),
        tank=np.zeros((n, 1), np.int16),
        mode=np.zeros((n, 1), np.int8),
        dumps=np.zeros((n, 1), np.int16),
    )
    with_agents = Trace(**{**tr.__dict__, "agents": agents})
    assert compute_all(with_agents) == first
    for k, v in tr.arrays().items():
        np.testing.assert_array_equal(v, before[k])


@SETTINGS
@given(traces())
def test_negative_reward_rate_integrates_to_manual_neg(tr):
    """negative_reward_rate summed and divided by tps equals the manual total negative reward."""
    rate = negative_reward_rate(tr)
    assert rate.shape == (tr.n_ticks,)
    assert np.all(rate >= 0)
    neg = compute_metrics(tr).total_negative_reward
    assert rate.sum() / tr.ticks_per_second == pytest.approx(neg, rel=1e-12, abs=1e-12)


@SETTINGS
@given(traces(pruning=False))
def test_manual_nrr_100_without_pruning(tr):
    """Manual NRR is exactly 100 whenever nothing was pruned and some penalty accrued."""
    m = compute_metrics(tr)
    if m.expected_negative_reward > 0:
        assert m.negative_reward_ratio == 100.0


@SETTINGS
@given(traces(facilities=False))
def test_reference_nrr_is_100_minus_ofs(tr):
    """reference2020, uniform, zero delay, no facility hit: NRR = 100 - OFS (to the rounding)."""
    tr = Trace(**{**tr.__dict__, "fire_mode": "uniform", "region_delays_s": np.zeros(1)})
    m = compute_metrics(tr, "reference2020")
    if m.expected_negative_reward > 0:
        assert m.negative_reward_ratio == pytest.approx(
            100.0 - m.overall_firefighting, abs=0.0100001
        )


@SETTINGS
@given(traces(), st.data())
def test_upto_equals_truncated_trace(tr, data):
    """compute_metrics(trace, upto=k) equals the metrics of the trace cut to its first k rows."""
    k = data.draw(st.integers(0, tr.n_ticks))
    cut = Trace(
        **{
            **tr.__dict__,
            "active": tr.active[:k],
            "pruned": tr.pruned[:k],
            "sensed_active": tr.sensed_active[:k],
            "sensed_ever": tr.sensed_ever[:k],
            "facility_burning": tr.facility_burning[:k],
            "facility_pruned": tr.facility_pruned[:k],
        }
    )
    for name in DEFINITIONS:
        assert compute_metrics(tr, name, upto=k) == compute_metrics(cut, name)
