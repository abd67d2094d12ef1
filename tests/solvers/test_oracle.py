"""The ``oracle`` reference: clairvoyant graphs, a label that says what it is, better scores."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan import make_scheduler, run_episode
from fcplan.errors import FcplanError
from fcplan.mission import Mission


def test_clairvoyant_graph_holds_fire_the_team_has_not_sensed():
    """With an idle team nothing is sensed, so the belief's graph has no fire task while the
    clairvoyant graph has the true fire; both keep the team's sensing state (never seen)."""
    mission = Mission(1, seed=0)
    mission.advance(100)
    assert mission.world.fire.n_burning > 0 and mission.belief.known.size == 0
    plain = mission.task_graph()
    seen = mission.task_graph(clairvoyant=True)
    assert plain.fire_tasks.size == 0 and seen.fire_tasks.size > 0
    assert int(seen.task_cells[seen.fire_tasks].sum()) == mission.world.fire.n_burning
    assert mission.belief.known.size == 0  # the view changed nothing


def test_oracle_plans_on_clairvoyant_graphs_and_is_labelled():
    """The mission gives the oracle the clairvoyant graph; its results carry its name."""
    mission = Mission(1, seed=0)
    mission.advance(100)
    graph, plan = mission.replan(make_scheduler("oracle"))
    assert graph.fire_tasks.size > 0 and plan.stats.status != "fallback"
    assert make_scheduler("oracle:inner=cbba").name == "oracle[cbba]"


@pytest.mark.parametrize("scenario", [12, 24])
def test_oracle_beats_greedy_on_mean(scenario):
    """Knowing the true fire helps: over seeds 0-2 the oracle's mean manual final score is
    higher than greedy's on the same (scenario, seed) pairs."""
    diffs = [
        run_episode(scenario, "oracle", seed=s).metrics["manual"].final_score
        - run_episode(scenario, "greedy", seed=s).metrics["manual"].final_score
        for s in range(3)
    ]
    assert np.mean(diffs) > 0


def test_oracle_refuses_itself_as_inner():
    """An oracle inside an oracle is refused with a one-line error naming the setting."""
    with pytest.raises(FcplanError, match="inner must name another scheduler"):
        make_scheduler("oracle:inner=oracle")
