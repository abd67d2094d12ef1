"""``--seeds auto`` (:mod:`fcplan.experiments.autoseeds`): the plan of seeds, the stopping rule,
and its false-stop rate under optional stopping."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from fcplan.errors import FcplanError
from fcplan.experiments.autoseeds import AutoSeeds
from fcplan.experiments.stats import paired_comparisons


def test_seed_plan_is_fixed_and_capped():
    """Looks add ``batch`` seeds in order 0, 1, 2, ...; the last look stops at the cap; the
    per-look level is Bonferroni over the planned looks."""
    plan = AutoSeeds(batch=4, max_seeds=10)
    assert [plan.seeds(k) for k in (1, 2, 3)] == [
        [0, 1, 2, 3],
        list(range(8)),
        list(range(10)),
    ]
    assert plan.looks == 3
    assert plan.look_alpha == pytest.approx(0.05 / 3)
    assert plan.look_confidence == pytest.approx(1 - 0.05 / 3)


@pytest.mark.parametrize(
    "kwargs, text",
    [
        ({"batch": 1}, "batch must be an integer >= 2"),
        ({"max_seeds": 3, "batch": 5}, "max_seeds (3) must be >= the batch (5)"),
        ({"batch": True}, "batch"),
        ({"confidence": 1.0}, "confidence"),
    ],
)
def test_bad_settings_are_one_line_errors(kwargs, text):
    """Each bad setting is refused with one line naming it."""
    with pytest.raises(FcplanError) as info:
        AutoSeeds(**kwargs)
    assert text in str(info.value) and "\n" not in str(info.value)


def test_decision_names_why_it_stopped():
    """Clear differences stop at the first look and say so; a pair with no difference runs to
    the cap and is named; no pairs stop at once."""
    plan = AutoSeeds(batch=12, max_seeds=24)
    rng = np.random.default_rng(0)
    base = rng.normal(0, 1, 12)
    clear = paired_comparisons(
        {"a": base + 5, "b": base}, plan.look_confidence, alpha=plan.look_alpha
    )
    d = plan.decide(clear, 1)
    assert d.stop and d.reason.startswith("stopped at 12 seeds: every pair's")
    null = paired_comparisons(
        {"a": base + rng.normal(0, 1, 12), "b": base}, plan.look_confidence, alpha=plan.look_alpha
    )
    assert not plan.decide(null, 1).stop and plan.decide(null, 1).unresolved == ("a vs b",)
    capped = plan.decide(null, 2)
    assert capped.stop and "cap of 24 seeds" in capped.reason and "a vs b" in capped.reason
    assert plan.decide([], 1).stop


def test_corrected_rule_keeps_false_stops_under_five_percent():
    """Under no true difference, stopping at the first look where the corrected rule resolves
    the pair happens in at most 5% of simulated studies (10 looks of 5 pairs), while a naive
    95% interval checked at every look stops falsely far more often (optional stopping)."""
    plan = AutoSeeds(batch=5, max_seeds=50)
    rng = np.random.default_rng(2024)
    trials = 400
    diffs = rng.normal(0.0, 1.0, (trials, plan.max_seeds))
    false_stops = 0
    for d in diffs:
        for look in range(1, plan.looks + 1):
            n = len(plan.seeds(look))
            pairs = paired_comparisons(
                {"a": d[:n], "b": np.zeros(n)}, plan.look_confidence, alpha=plan.look_alpha
            )
            decision = plan.decide(pairs, look)
            if decision.stop:
                false_stops += not decision.unresolved
                break
    assert false_stops / trials <= 0.05 + 3 * (0.05 * 0.95 / trials) ** 0.5
    naive = np.zeros(trials, bool)
    for look in range(1, plan.looks + 1):
        n = look * plan.batch
        x = diffs[:, :n]
        half = stats.t.ppf(0.975, n - 1) * x.std(axis=1, ddof=1) / np.sqrt(n)
        naive |= np.abs(x.mean(axis=1)) > half
    assert naive.mean() > 0.12
