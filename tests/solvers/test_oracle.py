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


def test_look_for_fire_raises_only_the_blocks_over_unsensed_fire():
    """On a clairvoyant graph with fire nobody has sensed, look_for_fire raises exactly the
    search blocks nearest to an unsensed fire task above every other block (by that fire's
    value) and changes no other value; on the team's own graph it changes nothing."""
    from solvers.oracle import look_for_fire

    mission = Mission(1, seed=0)
    mission.advance(100)
    g = mission.task_graph(clairvoyant=True)
    seen = look_for_fire(g)
    fires, blocks = g.fire_tasks, g.search_tasks
    unsensed = fires[g.task_staleness[fires] > g.time_s]
    assert unsensed.size > 0
    d = np.linalg.norm(g.task_pos[unsensed][:, None] - g.task_pos[blocks][None], axis=2)
    raised = np.zeros(blocks.size, dtype=bool)
    raised[d.argmin(axis=1)] = True
    up = seen.task_value[blocks] != g.task_value[blocks]
    assert np.array_equal(up, raised)
    assert seen.task_value[blocks][up].min() > g.task_value[blocks].max()
    assert np.array_equal(seen.task_value[fires], g.task_value[fires])
    plain = mission.task_graph()
    assert look_for_fire(plain) is plain


def test_oracle_without_look_for_fire_plans_as_its_inner_scheduler():
    """look_for_fire=false gives the inner scheduler's plan on the clairvoyant graph unchanged
    (the former oracle); a non-bool value is a one-line setting error."""
    from fcplan.scheduling import SettingError

    mission = Mission(24, seed=1)
    mission.advance(200)
    g = mission.task_graph(clairvoyant=True)
    rng = np.random.default_rng(0)
    old = make_scheduler("oracle:look_for_fire=false").plan(g, rng=rng)
    inner = make_scheduler("greedy").plan(g, rng=rng)
    assert old.routes == inner.routes and old.altitudes == inner.altitudes
    assert make_scheduler("oracle:look_for_fire=false").name == "oracle"
    with pytest.raises(SettingError, match="look_for_fire"):
        make_scheduler("oracle", look_for_fire="yes")
