"""Outcome metrics (:mod:`fcplan.metrics.outcomes`): their definitions hold on any trace, and
they separate an idle team from one that fights the fire."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from fcplan import run_episode
from fcplan.metrics import OUTCOMES, Outcomes, compute_outcomes, metric_spec
from fcplan.trace import Trace


@st.composite
def traces(draw):
    """Count traces a world could write: cumulative prunes, actives, facility counts <= actives."""
    n = draw(st.integers(1, 40))
    active = np.array(draw(st.lists(st.integers(0, 50), min_size=n, max_size=n)))
    pruned = np.cumsum(draw(st.lists(st.integers(0, 5), min_size=n, max_size=n)))
    fac = np.minimum(active, np.array(draw(st.lists(st.integers(0, 9), min_size=n, max_size=n))))
    tps = draw(st.sampled_from([5, 10, 20]))
    return Trace.from_counts(
        ticks_per_second=tps, active=active, pruned=pruned, sensed_active=[0] * n,
        sensed_ever=[0] * n, facility_burning=fac[:, None], facility_penalties=[1.0],
    )  # fmt: skip


@given(traces())
def test_outcome_definitions(tr):
    """Containment: contained iff no cell is active in the last row, and then the fire is out
    from the reported time on; the time lies within the episode; burned area and damage are the
    end counts and the integral of the facility counts."""
    o = compute_outcomes(tr)
    n, tps = tr.active.size, tr.ticks_per_second
    assert 0.0 <= o.time_to_containment_s <= n / tps
    assert o.burned_area_cells == tr.active[-1] + tr.pruned[-1]
    assert np.isclose(o.facility_damage_cell_s, tr.facility_burning.sum() / tps)
    if o.burned_area_cells and tr.active[-1] > 0:
        assert o.contained == 0 and o.time_to_containment_s == n / tps
    else:
        assert o.contained == 1
        first_out_row = round(o.time_to_containment_s * tps) - 1
        assert (tr.active[max(first_out_row, 0) :] == 0).all() or o.burned_area_cells == 0


def test_outcomes_separate_idle_from_greedy():
    """An idle team never contains #24's fire and lets it burn more than greedy does."""
    idle, greedy = (run_episode(24, s, seed=0).outcomes for s in ("idle", "greedy"))
    assert idle.contained == 0 and greedy.contained == 1
    assert greedy.burned_area_cells < idle.burned_area_cells
    assert greedy.time_to_containment_s < idle.time_to_containment_s


def test_outcome_table_and_summary_columns():
    """Every Outcomes field has a row in OUTCOMES (in order) and an ``outcome.*`` summary column."""
    names = [f for f in Outcomes.__dataclass_fields__]
    assert [s.name for s in OUTCOMES] == names
    assert metric_spec("burned_area_cells").higher_is_better is False
    summary = run_episode("practice", "greedy", seed=0).summary()
    assert all(f"outcome.{n}" in summary for n in names)
