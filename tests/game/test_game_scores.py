"""The game's online scores (fcplan.game.scores): live metrics and how the game shows them."""

from __future__ import annotations

from fcplan import World, load_scenario
from fcplan.game.scores import ONLINE_METRICS, OnlineScores, shown_text, shown_value
from fcplan.metrics import METRICS, compute_metrics, metric_spec
from fcplan.trace import Trace


def test_online_scores_follow_the_world_tick_by_tick():
    """OnlineScores gives compute_metrics of the trace so far, updated as the world advances."""
    from fcplan.team import Command

    world = World().reset(load_scenario(3), seed=1)
    scores = OnlineScores(world)
    world.step({"P1": Command(route=((300.0, 300.0),)), "A1": Command(route=((320.0, 300.0),))})
    seen = []
    while world.tick < 300:
        world.step()
        if world.tick % 100 == 0:
            assert scores.metrics() == compute_metrics(world.trace())
            seen.append(scores.metrics().total_negative_reward)
    assert seen == sorted(seen) and seen[0] < seen[-1]


def test_online_metrics_come_from_the_metric_table():
    """The panel shows table entries, in display order ending with the final score, and
    OnlineScores.panel keys them by their column labels."""
    assert all(spec in METRICS for spec in ONLINE_METRICS)
    assert ONLINE_METRICS[-1].name == "final_score"
    world = World().reset(load_scenario("practice"), seed=0)
    panel = OnlineScores(world).panel()
    assert list(panel) == [spec.column for spec in ONLINE_METRICS]


def test_shown_values_negate_penalties_and_mark_percentages():
    """The game shows the negative reward negated (its score is -NEG) and percentages with %."""
    m = compute_metrics(
        Trace.from_counts(
            ticks_per_second=1, active=[3, 1], pruned=[0, 2], sensed_active=[1, 1],
            sensed_ever=[1, 3],
        )
    )  # fmt: skip
    neg = metric_spec("total_negative_reward")
    assert shown_value(neg, m) == -m.total_negative_reward
    assert shown_text(neg, m, 2) == f"{-m.total_negative_reward:.2f}"
    assert shown_text(metric_spec("perception"), m, 1) == f"{m.perception:.1f} %"
    assert shown_text(metric_spec("final_score"), m, 1) == f"{m.final_score:.1f}"
