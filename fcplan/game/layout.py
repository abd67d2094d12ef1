"""Where everything sits in the game's window: its size, the map and panel areas, the buttons.

The window is :data:`WINDOW` px; the game screen draws the map in :data:`MAP_RECT` and the
information panel from :data:`PANEL_X` to the right edge, one row per agent
(:func:`agent_row_rect`); the designer previews its scenario in :data:`PREVIEW_RECT`. Every screen
(:data:`SCREENS`) has its buttons (:class:`Button`, window pixels), laid out by one function per
screen from the state it depends on. Nothing here imports pygame: the layout is what both the
drawing (:mod:`fcplan.game.view`) and the hit tests of clicks (:mod:`fcplan.game.screens`) use.

Examples
--------
>>> [b.id for b in welcome_buttons()]
['scenario_mode', 'open_world', 'tutorial', 'quit']
>>> agent_row_rect(0)
(760, 112, 364, 28)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

__all__ = [
    "MAP_RECT",
    "PANEL_X",
    "PREVIEW_RECT",
    "SCREENS",
    "WINDOW",
    "Button",
    "agent_row_rect",
    "designer_buttons",
    "evaluation_buttons",
    "field_rows",
    "game_buttons",
    "playback_buttons",
    "preview_buttons",
    "scenario_buttons",
    "scenario_groups",
    "tutorial_buttons",
    "welcome_buttons",
]

SCREENS = ("welcome", "scenarios", "tutorial", "designer", "preview", "game", "evaluation",
           "playback")  # fmt: skip
"""Every screen of the game."""

WINDOW = (1140, 760)
"""Window size (width, height) in px."""

MAP_RECT = (20, 20, 720, 720)
"""Where the map is drawn in the game screen: (x, y, width, height)."""

PANEL_X = MAP_RECT[0] + MAP_RECT[2] + 20
"""Left edge of the game's information panel."""

PREVIEW_RECT = (640, 110, 470, 470)
"""Where the designer draws its preview map."""

Rect = tuple[int, int, int, int]


@dataclass(frozen=True)
class Button:
    """A clickable rectangle: ``id`` names the action, ``rect`` is (x, y, width, height)."""

    id: str
    label: str
    rect: Rect
    style: str = "normal"  #: normal | primary | small | selected | danger

    def contains(self, x: float, y: float) -> bool:
        """Whether window pixel (x, y) is inside the button."""
        bx, by, bw, bh = self.rect
        return bx <= x < bx + bw and by <= y < by + bh

    @property
    def center(self) -> tuple[int, int]:
        """The button's centre pixel."""
        bx, by, bw, bh = self.rect
        return (bx + bw // 2, by + bh // 2)


def _grid_buttons(
    items: Sequence[tuple[str, str]],
    x0: int,
    y0: int,
    w: int,
    h: int,
    gap: int,
    per_row: int,
    style: str = "normal",
) -> list[Button]:
    out = []
    for k, (bid, label) in enumerate(items):
        r, c = divmod(k, per_row)
        out.append(Button(bid, label, (x0 + c * (w + gap), y0 + r * (h + gap), w, h), style))
    return out


def welcome_buttons() -> list[Button]:
    """The welcome screen: the two modes, the tutorial, quit."""
    x, w = WINDOW[0] // 2 - 170, 340
    return [
        Button("scenario_mode", "Scenario mode", (x, 300, w, 60), "primary"),
        Button("open_world", "Open-world mode", (x, 380, w, 60), "primary"),
        Button("tutorial", "Tutorial", (x, 460, w, 60)),
        Button("quit", "Quit", (x, 560, w, 44), "small"),
    ]


def scenario_groups() -> list[tuple[str, list[tuple[str, str]]]]:
    """(group title, [(button id, label)]) for the scenario mode, by difficulty."""
    groups = [("Practice", [("play:practice", "Practice")])]
    for title, lo, hi in (("Easy", 1, 6), ("Moderate", 7, 18), ("Hard", 19, 24)):
        groups.append((title, [(f"play:{n}", f"#{n}") for n in range(lo, hi + 1)]))
    return groups


def scenario_buttons() -> list[Button]:
    """The scenario mode: a button per scenario, by difficulty group; the seed; back."""
    out = []
    y = 140
    for _title, items in scenario_groups():
        out += _grid_buttons(items, 220, y, 100 if len(items) > 1 else 160, 44, 12, 6)
        y += 56 * ((len(items) + 5) // 6) + 24
    out += [
        Button("seed:-1", "-", (220, y + 10, 44, 40), "small"),
        Button("seed:+1", "+", (380, y + 10, 44, 40), "small"),
        Button("back", "Back", (40, WINDOW[1] - 70, 140, 44), "small"),
    ]
    return out


def tutorial_buttons(page: int, n_pages: int, before_game: bool) -> list[Button]:
    """Tutorial page ``page`` of ``n_pages``; ``before_game`` adds the button that starts the
    open-world game waiting behind it."""
    out = [Button("back", "Back", (40, WINDOW[1] - 70, 140, 44), "small")]
    if before_game:  # open-world: preview -> tutorial -> game
        out.append(Button("tutorial:start", "Start the game", (WINDOW[0] // 2 - 120,
                                                              WINDOW[1] - 70, 240, 44),
                          "primary"))  # fmt: skip
    if page > 0:
        out.append(Button("tutorial:prev", "Previous", (WINDOW[0] - 360, WINDOW[1] - 70,
                                                           150, 44), "small"))  # fmt: skip
    if page < n_pages - 1:
        out.append(Button("tutorial:next", "Next", (WINDOW[0] - 190, WINDOW[1] - 70, 150, 44)))
    return out


def field_rows(design: Any) -> list[tuple[Any, Rect]]:
    """(field, value box rect) of the designer's current page (a :class:`~fcplan.game.Design`)."""
    fields = design.fields()
    h = min(40, 560 // max(len(fields), 1))
    return [(f, (330, 110 + k * h, 150, h - 6)) for k, f in enumerate(fields)]


def designer_buttons(design: Any, pages: Sequence[str], file_text: str) -> list[Button]:
    """The designer: page tabs, a value box and -/+ per field, reset, the file box, next."""
    out = []
    for k, page in enumerate(pages):
        style = "selected" if page == design.page else "small"
        out.append(Button(f"page:{page}", page.title(), (40 + k * 130, 50, 120, 40), style))
    for f, (x, y, w, h) in field_rows(design):
        out.append(Button(f"focus:{f.key}", design.text(f.key), (x, y, w, h), "field"))
        out.append(Button(f"nudge:{f.key}:-1", "-", (x + w + 8, y, h, h), "small"))
        out.append(Button(f"nudge:{f.key}:+1", "+", (x + w + 14 + h, y, h, h), "small"))
    bottom = WINDOW[1] - 70
    out += [
        Button("back", "Back", (40, bottom, 120, 44), "small"),
        Button("design:reset", "Reset", (170, bottom, 120, 44), "small"),
        Button("focus:__file__", file_text or "scenario.toml", (640, 600, 330, 40),
               "field"),
        Button("design:load", "Load file", (980, 600, 130, 40), "small"),
        Button("design:next", "Next" if design.page != pages[-1] else "Preview",
               (WINDOW[0] - 170, bottom, 140, 44), "primary"),
    ]  # fmt: skip
    return out


def preview_buttons() -> list[Button]:
    """The preview: back to the design, or play it."""
    bottom = WINDOW[1] - 70
    return [
        Button("preview:back", "Back to design", (40, bottom, 200, 44), "small"),
        Button("preview:start", "Proceed: play", (WINDOW[0] - 240, bottom, 200, 44), "primary"),
    ]


def agent_row_rect(i: int) -> Rect:
    """Panel row of agent ``i`` in the game screen."""
    return (PANEL_X, 112 + 30 * i, WINDOW[0] - PANEL_X - 16, 28)


def game_buttons(agent_ids: Sequence[str]) -> list[Button]:
    """The game: a row per agent in the panel (clicking selects it), end the game."""
    out = [Button(f"select:{i}", aid, agent_row_rect(i), "row") for i, aid in enumerate(agent_ids)]
    out.append(Button("game:end", "End game (Esc)", (WINDOW[0] - 190, WINDOW[1] - 56, 170, 40),
                      "small"))  # fmt: skip
    return out


def evaluation_buttons() -> list[Button]:
    """The evaluation page: playback, play again, menus, quit."""
    y = WINDOW[1] - 80
    return [
        Button("save_playback", "Save playback", (60, y, 200, 48), "primary"),
        Button("play_again", "Play again", (280, y, 180, 48)),
        Button("scenario_mode", "Scenario mode", (480, y, 200, 48)),
        Button("main_menu", "Main menu", (700, y, 180, 48)),
        Button("quit", "Quit", (900, y, 160, 48), "small"),
    ]


def playback_buttons() -> list[Button]:
    """The playback page: back, write a GIF, main menu."""
    y = WINDOW[1] - 80
    out = [Button("back_to_evaluation", "Back", (60, y, 160, 48), "small")]
    out.append(Button("write_video", "Write GIF video", (240, y, 240, 48), "primary"))
    out.append(Button("main_menu", "Main menu", (500, y, 180, 48)))
    return out
