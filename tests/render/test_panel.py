"""Tests of fcplan.render.panel: the information panel beside the map."""

from __future__ import annotations

from fcplan.render import panel_width, render_frame, snapshot


def test_panel_lists_scores_and_agents(world):
    """The panel draws text for scores and one row per agent (more ink with more scores)."""
    base = render_frame(world.scenario, snapshot(world), size=512)
    more = render_frame(world.scenario, snapshot(world, scores={"a": 1, "b": 2}), size=512)
    panel = slice(512, None)
    assert (more[:, panel] != base[:, panel]).any()


def test_panel_width_follows_the_text_scale():
    """The panel is 252 px beside maps below 960 px, and grows with the text scale above."""
    assert panel_width(64) == panel_width(959) == 252
    assert panel_width(960) == 2 * 252
