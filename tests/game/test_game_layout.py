"""The game's layout (fcplan.game.layout): every button inside the window, none overlapping."""

from __future__ import annotations

import pytest

from fcplan.game.designer import PAGES, Design
from fcplan.game.layout import (
    MAP_RECT,
    PANEL_X,
    WINDOW,
    agent_row_rect,
    designer_buttons,
    evaluation_buttons,
    game_buttons,
    playback_buttons,
    preview_buttons,
    scenario_buttons,
    tutorial_buttons,
    welcome_buttons,
)


def _design_on(page: str) -> Design:
    d = Design()
    d.page = page
    return d


def _overlap(a, b) -> bool:
    ax, ay, aw, ah = a
    bx, by, bw, bh = b
    return ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah


@pytest.mark.parametrize(
    "buttons",
    [
        welcome_buttons(),
        scenario_buttons(),
        tutorial_buttons(1, 3, True),
        *(designer_buttons(_design_on(p), PAGES, "") for p in PAGES),
        preview_buttons(),
        game_buttons(["P1", "P2", "A1", "A2", "H1"]),
        evaluation_buttons(),
        playback_buttons(),
    ],
)
def test_buttons_fit_the_window_and_do_not_overlap(buttons):
    """Every button of a screen lies inside the window, has a unique id, and overlaps no other."""
    ids = [b.id for b in buttons]
    assert len(set(ids)) == len(ids)
    for b in buttons:
        x, y, w, h = b.rect
        assert x >= 0 and y >= 0 and x + w <= WINDOW[0] and y + h <= WINDOW[1], b
    for i, a in enumerate(buttons):
        for b in buttons[i + 1 :]:
            assert not _overlap(a.rect, b.rect), (a.id, b.id)


def test_panel_rows_sit_right_of_the_map():
    """Agent rows start at the panel's edge, right of the map, one below the other."""
    assert MAP_RECT[0] + MAP_RECT[2] < PANEL_X
    r0, r1 = agent_row_rect(0), agent_row_rect(1)
    assert r0[0] == PANEL_X and r1[1] >= r0[1] + r0[3]
