"""Drawing the game's screens with pygame (the only module besides :mod:`fcplan.game.app` that
imports it).

:func:`draw` paints whatever screen an :class:`~fcplan.game.screens.App` is on into a pygame
surface: buttons and text with pygame's default font, and the map with the shared numpy renderer
(:func:`fcplan.render.render_frame`, blitted through ``pygame.surfarray``). The map shows only what
the team knows (sensed fire, pruned cells), every agent with its field of view and planned route,
the selected agent ringed; patrol loops are drawn closed and, while the selected agent has two or
more goals, a dashed circle marks where a click closes the loop. The panel on the right is the
manual's information display: per agent its mode, battery now and at its last planned goal,
altitude and tank, then the online scores.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from fcplan.game.controls import PATROL_RADIUS_STEPS
from fcplan.game.layout import MAP_RECT, PANEL_X, PREVIEW_RECT, WINDOW, Button
from fcplan.game.scores import ONLINE_METRICS, shown_text
from fcplan.game.screens import App
from fcplan.game.session import GameSession
from fcplan.game.tutorial import TUTORIAL
from fcplan.metrics import METRICS
from fcplan.render import COLORS, FrameData, render_frame, snapshot

Surface = Any  # a pygame.Surface (pygame is imported only when drawing)
Color = tuple[int, int, int]
Point = tuple[float, float]

__all__ = ["draw", "reset_fonts", "THEME"]

THEME = {
    "bg": (22, 25, 31),
    "panel": (30, 34, 42),
    "line": (60, 64, 76),
    "text": (230, 232, 238),
    "dim": (146, 152, 166),
    "accent": (255, 150, 70),
    "error": (255, 110, 90),
    "ok": (110, 210, 120),
    "button": (52, 58, 72),
    "button_edge": (88, 96, 116),
    "primary": (196, 84, 36),
    "primary_edge": (255, 150, 70),
    "field": (16, 18, 24),
    "selected": (70, 80, 104),
}
_MODE = {0: "idle", 1: "active", 2: "return", 3: "homing"}
_ROLE_NAME = {"P": "perception", "A": "action", "H": "hybrid"}
_GRADE_COLOR = {
    "Excellent": (110, 210, 120),
    "Well Done": (160, 210, 100),
    "Almost There!": (240, 200, 80),
    "Fair": (255, 150, 70),
    "Failed": (255, 90, 70),
}

_FINAL_SCORE = "PS + AS + FPS - 3 NRR"  # the manual's Eq. (6), beside the final score

_fonts: dict[tuple[int, bool], Any] = {}


def reset_fonts() -> None:
    """Forget cached fonts (call after ``pygame.quit()``: fonts made before it are unusable)."""
    _fonts.clear()


def _font(size: int, bold: bool = False) -> Any:
    import pygame

    if not pygame.font.get_init():  # pygame was shut down since: old fonts are invalid
        pygame.font.init()
        _fonts.clear()
    key = (size, bold)
    if key not in _fonts:
        f = pygame.font.Font(None, size)
        f.set_bold(bold)
        _fonts[key] = f
    return _fonts[key]


def _text(
    surf: Surface,
    text: object,
    pos: Point,
    size: int = 22,
    color: Color = THEME["text"],
    bold: bool = False,
    anchor: str = "topleft",
) -> Any:
    img = _font(size, bold).render(str(text), True, color)
    rect = img.get_rect(**{anchor: pos})
    surf.blit(img, rect)
    return rect


def _button(surf: Surface, b: Button, app: App) -> None:
    import pygame

    x, y, w, h = b.rect
    rect = pygame.Rect(x, y, w, h)
    if b.style == "field":
        focused = app.focus is not None and b.id == f"focus:{app.focus}"
        pygame.draw.rect(surf, THEME["field"], rect, border_radius=4)
        edge = THEME["accent"] if focused else THEME["button_edge"]
        pygame.draw.rect(surf, edge, rect, width=2 if focused else 1, border_radius=4)
        label = app.typed + "|" if focused else b.label
        size = min(22, h - 4)
        _text(surf, _fit(label, w - 12, size), (x + 8, y + h // 2), size, anchor="midleft")
        return
    if b.style == "row":
        return  # agent rows are drawn by the panel
    fill = {"primary": THEME["primary"], "selected": THEME["selected"]}.get(
        b.style, THEME["button"]
    )
    edge = THEME["primary_edge"] if b.style == "primary" else THEME["button_edge"]
    pygame.draw.rect(surf, fill, rect, border_radius=8)
    pygame.draw.rect(surf, edge, rect, width=1, border_radius=8)
    size = 30 if b.style == "primary" and h >= 56 else (22 if h < 40 else 26)
    _text(surf, b.label, rect.center, size, anchor="center")


def _fit(text: str, width: int, size: int) -> str:
    f = _font(size)
    if f.size(text)[0] <= width:
        return text
    while text and f.size("..." + text)[0] > width:
        text = text[1:]
    return "..." + text


def _blit_array(surf: Surface, img: np.ndarray, pos: Point) -> None:
    import pygame

    surf.blit(pygame.surfarray.make_surface(np.ascontiguousarray(img.swapaxes(0, 1))), pos)


def draw(surf: Surface, app: App) -> None:
    """Paint the app's current screen into ``surf`` (a ``WINDOW``-sized pygame surface)."""
    surf.fill(THEME["bg"])
    _SCREENS[app.screen](surf, app)
    for b in app.buttons():
        _button(surf, b, app)
    if app.message and app.screen not in ("game",):
        color = THEME["error"] if app.error else THEME["ok"]
        _text(surf, _fit(app.message, WINDOW[0] - 80, 22), (40, WINDOW[1] - 108), 22, color)


# ------------------------------------------------------------------------------ menu screens
@functools.cache
def _backdrop() -> np.ndarray:
    """The welcome screen's dimmed backdrop: scenario #24 after 40 s, its fire all shown."""
    from fcplan.scenario import load_scenario

    game = GameSession(load_scenario(24), seed=3)
    while game.tick < 400:
        game.step()
    frame = snapshot(game.world)
    frame = dataclasses.replace(frame, known=np.asarray(frame.fire == 1))
    img = render_frame(game.scenario, frame, size=WINDOW[0], panel=False)
    img = img[(WINDOW[0] - WINDOW[1]) // 2 :][: WINDOW[1]]
    return (img.astype(np.float32) * 0.35).astype(np.uint8)


def _draw_welcome(surf: Surface, app: App) -> None:
    _blit_array(surf, _backdrop(), (0, 0))
    cx = WINDOW[0] // 2
    _text(surf, "FireCommander", (cx, 130), 96, THEME["accent"], True, "center")
    _text(surf, "wildfire fighting with a team of perception and action drones", (cx, 200), 28,
          anchor="center")  # fmt: skip
    _text(surf, "fcplan play: every game is recorded for learning from demonstration",
          (cx, 236), 22, THEME["dim"], anchor="center")  # fmt: skip


def _draw_scenarios(surf: Surface, app: App) -> None:
    _text(surf, "Scenario mode", (40, 40), 48, THEME["accent"], True)
    _text(surf, "Pick a scenario: the game starts at once and runs in real time.", (40, 90), 24,
          THEME["dim"])  # fmt: skip
    y = 140
    for title, items in app.scenario_groups():
        _text(surf, title, (40, y + 12), 28, bold=True)
        y += 56 * ((len(items) + 5) // 6) + 24
    _text(surf, "Seed", (40, y + 20), 28, bold=True)
    _text(surf, str(app.seed), (322, y + 30), 30, anchor="center")
    summary = app.hover_summary()
    if summary:
        _text(surf, " ".join(summary.split()), (40, y + 80), 24, THEME["accent"])


def _draw_tutorial(surf: Surface, app: App) -> None:
    title, lines = TUTORIAL[app.tutorial_page]
    _text(surf, f"Tutorial: {title}", (40, 40), 48, THEME["accent"], True)
    _text(surf, f"page {app.tutorial_page + 1} of {len(TUTORIAL)}", (40, 92), 22, THEME["dim"])
    y = 150
    for line in lines:
        indent = 30 if line.startswith("   ") else 0
        _text(surf, line.strip(), (60 + indent, y), 28, THEME["dim"] if indent else THEME["text"])
        y += 44


def _draw_designer(surf: Surface, app: App) -> None:
    import pygame

    _text(surf, "Open-world mode: design a scenario", (40, 12), 34, THEME["accent"], True)
    for f, (_, y, _, h) in app.field_rows():
        size = min(22, h - 4)
        _text(surf, f.label, (40, y + h // 2 - 3), size, anchor="midleft")
        if f.kind != "cell":
            _text(surf, f.limit_text(), (322, y + h // 2 - 3), max(size - 4, 14), THEME["dim"],
                  anchor="midright")  # fmt: skip
    px, py, pw, ph = PREVIEW_RECT
    img = app.preview_image(pw)
    _blit_array(surf, img, (px, py))
    scenario = app.preview_target()
    if scenario is not None:
        _draw_regions(surf, scenario, PREVIEW_RECT)
    pygame.draw.rect(surf, THEME["button_edge"], pygame.Rect(px, py, pw, ph), 1)
    hint = "preview"
    if app.focus and app.focus != "__file__" and app.design.field(app.focus).kind == "cell":
        hint = "click on the map to place it, or type a cell and press Enter"
    elif app.focus:
        hint = "type a value, Enter to apply, Esc to cancel"
    _text(surf, hint, (px, py - 26), 22, THEME["dim"])
    _text(surf, "or load a scenario TOML file:", (640, 582), 20, THEME["dim"])


def _draw_regions(surf: Surface, scenario: Any, rect: tuple[int, int, int, int]) -> None:
    """Red squares and front counts on fire regions (the preview shows no burning fire yet)."""
    import pygame

    px, py, pw, ph = rect
    s = pw / scenario.world_size
    for i, r in enumerate(scenario.regions):
        x0, x1, y0, y1 = r.ignition_box
        box = pygame.Rect(px + x0 * s, py + y0 * s, (x1 - x0) * s, (y1 - y0) * s)
        pygame.draw.rect(surf, (255, 72, 24), box, 3)
        label = f"R{i + 1}: {r.fronts}f" + (f" +{r.delay_s:g}s" if r.delay_s else "")
        _text(surf, label, (box.left + 2, box.bottom + 2), 18, (255, 200, 160))


def _draw_preview(surf: Surface, app: App) -> None:
    sc = app.preview_scenario
    _text(surf, "Preview", (40, 20), 40, THEME["accent"], True)
    size = 620
    _blit_array(surf, app.preview_image(size), (40, 70))
    _draw_regions(surf, sc, (40, 70, size, size))
    x, y = 690, 80
    counts = sc.team_counts
    kinds = [f.kind for f in sc.facilities]
    lines = [
        ("name", sc.name),
        ("map", f"{sc.world_size} x {sc.world_size} px"),
        ("duration", f"{sc.duration_s:g} s"),
        ("team", ", ".join(f"{n} {k}" for k, n in counts.items() if n)),
        ("fire regions", str(len(sc.regions))),
        ("fronts", ", ".join(str(r.fronts) for r in sc.regions)),
        ("houses", str(kinds.count("house"))),
        ("hospitals", str(kinds.count("hospital"))),
        ("power stations", str(kinds.count("power_station"))),
        ("lakes", str(len(sc.lakes))),
    ]
    for k, v in lines:
        _text(surf, k, (x, y), 24, THEME["dim"])
        _text(surf, _fit(v, 260, 24), (x + 160, y), 24)
        y += 34
    _text(surf, "Do you like to proceed with this design?", (x, y + 20), 24, THEME["accent"])


# ------------------------------------------------------------------------------ game
def _game_frame(app: App) -> FrameData:
    s = app.game
    team, ctl = s.world.team, s.controller
    routes = []
    for i in range(team.n):
        if team.mode[i] in (2, 3):
            routes.append(team.home[i : i + 1].copy())
        else:
            routes.append(ctl.planned_route(i))
    frame = snapshot(s.world, s.belief, routes=routes)
    return dataclasses.replace(frame, selected=ctl.selected)


def _draw_game(surf: Surface, app: App) -> None:
    import pygame

    s = app.game
    mx, my, mw, mh = MAP_RECT
    frame = _game_frame(app)
    _blit_array(surf, render_frame(s.scenario, frame, size=mw, panel=False), (mx, my))
    team, ctl = s.world.team, s.controller
    role_col = _role_colors(s.scenario)
    # closed patrol loops, and the loop-closing radius of the selected agent
    for i in range(team.n):
        route, patrol = ctl._current_route(i)
        if patrol and len(route) > 1 and team.mode[i] == 1:
            a, b = app.window_point(*route[-1]), app.window_point(*route[0])
            _dashed(surf, role_col[i], a, b)
    i = ctl.selected
    goals = ctl.clicked[i]
    route, patrol = ctl._current_route(i)
    if route and not patrol and len(goals) >= 2:
        c = app.window_point(*goals[0])
        r = PATROL_RADIUS_STEPS * s.scenario.agents[i].speed * mw / s.scenario.world_size
        _dashed_circle(surf, (255, 255, 255), c, r)
    pygame.draw.rect(surf, THEME["line"], pygame.Rect(mx - 1, my - 1, mw + 2, mh + 2), 1)
    if app.paused:
        _text(surf, "PAUSED (space)", (mx + mw // 2, my + 30), 40, THEME["accent"], True, "center")
    _draw_panel(surf, app, frame, role_col)


def _role_colors(scenario: Any) -> list[Color]:
    return [COLORS[_ROLE_NAME[a.id[0]]] for a in scenario.agents]


def _dashed(surf: Surface, color: Color, a: Point, b: Point, dash: int = 8) -> None:
    import pygame

    d = math.dist(a, b)
    n = max(int(d // dash), 1)
    for k in range(0, n, 2):
        p = (a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n)
        q = (a[0] + (b[0] - a[0]) * (k + 1) / n, a[1] + (b[1] - a[1]) * (k + 1) / n)
        pygame.draw.line(surf, color, p, q, 2)


def _dashed_circle(surf: Surface, color: Color, c: Point, r: float, n: int = 36) -> None:
    import pygame

    for k in range(0, n, 2):
        a0, a1 = 2 * math.pi * k / n, 2 * math.pi * (k + 1) / n
        p = (c[0] + r * math.cos(a0), c[1] + r * math.sin(a0))
        q = (c[0] + r * math.cos(a1), c[1] + r * math.sin(a1))
        pygame.draw.line(surf, color, p, q, 1)


def _draw_panel(surf: Surface, app: App, frame: FrameData, role_col: list[Color]) -> None:
    import pygame

    s = app.game
    sc = s.scenario
    x, right = PANEL_X, WINDOW[0] - 16
    pygame.draw.rect(surf, THEME["panel"], pygame.Rect(x - 10, 10, right - x + 20, WINDOW[1] - 20),
                     border_radius=10)  # fmt: skip
    title = f"Scenario #{sc.number}" if sc.number else ("Practice" if sc.number == 0 else sc.name)
    _text(surf, _fit(title, 230, 34), (x, 22), 34, THEME["accent"], True)
    _text(surf, sc.difficulty, (right, 28), 24, THEME["dim"], anchor="topright")
    # time bar
    t, dur = s.world.time_s, sc.duration_s
    bar = pygame.Rect(x, 58, right - x, 10)
    pygame.draw.rect(surf, THEME["line"], bar, border_radius=4)
    pygame.draw.rect(surf, THEME["accent"], pygame.Rect(x, 58, int(bar.w * min(t / dur, 1)), 10),
                     border_radius=4)  # fmt: skip
    _text(surf, f"{t:5.1f} / {dur:g} s", (x, 74), 22)
    speed = "fast" if app.fast else f"x{app.speed:g}"
    _text(surf, f"seed {s.seed}  {speed}", (right, 74), 22, THEME["dim"], anchor="topright")
    # agent table
    cols = (x + 4, x + 62, x + 122, x + 300, x + 314)
    for c, h, a in zip(cols[1:], ("mode", "battery: now > at goal", "alt m", "tank"),
                       ("topleft", "topleft", "topright", "topleft"), strict=True):  # fmt: skip
        _text(surf, h, (c, 96), 18, THEME["dim"], anchor=a)
    team, ctl = s.world.team, s.controller
    for i in range(team.n):
        rx, ry, rw, rh = app.agent_row_rect(i)
        if i == ctl.selected:
            pygame.draw.rect(surf, THEME["selected"], pygame.Rect(rx - 4, ry, rw + 8, rh),
                             border_radius=5)  # fmt: skip
        cy = ry + rh // 2
        pygame.draw.circle(surf, role_col[i], (cols[0] + 6, cy), 6)
        _text(surf, f"{i + 1} {team.ids[i]}", (cols[0] + 16, cy), 22, anchor="midleft")
        _text(surf, _MODE.get(int(team.mode[i]), "?"), (cols[1], cy), 20, anchor="midleft")
        cap = max(float(sc.agents[i].battery), 1e-9)
        now = float(team.battery[i]) / cap
        goal = ctl.battery_at_goal(i) / cap
        bx, bw = cols[2], 60
        pygame.draw.rect(surf, THEME["line"], pygame.Rect(bx, cy - 6, bw, 12), border_radius=3)
        col = COLORS["bar_ok"] if now >= 0.25 else COLORS["bar_low"]
        pygame.draw.rect(surf, col, pygame.Rect(bx, cy - 6, int(bw * min(max(now, 0), 1)), 12),
                         border_radius=3)  # fmt: skip
        if abs(goal - now) > 1e-9:
            gx = bx + int(bw * min(max(goal, 0), 1))
            pygame.draw.line(surf, (255, 255, 255), (gx, cy - 8), (gx, cy + 7), 2)
        warn = THEME["error"] if goal < 0.1 else THEME["text"]
        _text(surf, f"{now * 100:.0f} > {goal * 100:.0f} %", (bx + bw + 6, cy), 20, warn,
              anchor="midleft")  # fmt: skip
        _text(surf, f"{team.z[i]:.0f}", (cols[3], cy), 20, anchor="midright")
        tank = f"{int(team.tank[i])}/{int(team.tank_capacity[i])}" if team.can_act[i] else "-"
        _text(surf, tank, (cols[4], cy), 20, anchor="midleft")
    # online scores
    y = 112 + 30 * team.n + 14
    pygame.draw.line(surf, THEME["line"], (x, y), (right, y))
    m = s.metrics()
    _text(surf, "Online scores", (x, y + 10), 24, THEME["dim"], True)
    y += 38
    *rows, final = ONLINE_METRICS
    for spec in rows:
        _text(surf, spec.heading, (x, y), 22)
        _text(surf, shown_text(spec, m, 1), (right, y), 22, anchor="topright")
        y += 25
    _text(surf, final.title, (x, y + 4), 26, bold=True)
    _text(surf, shown_text(final, m, 1), (right, y + 4), 26, _GRADE_COLOR[m.grade], True,
          anchor="topright")  # fmt: skip
    _text(surf, m.grade, (right, y + 30), 22, _GRADE_COLOR[m.grade], anchor="topright")
    y += 60
    fire = f"fire known {int(frame.known.sum())}, pruned {int(frame.pruned.sum())}"
    _text(surf, fire, (x, y), 20, THEME["dim"])
    y += 26
    pygame.draw.line(surf, THEME["line"], (x, y), (right, y))
    _text(surf, _fit(app.message, right - x, 20), (x, y + 8), 20, THEME["accent"])
    help_lines = ("1-9 select   click: goal   click first goal: patrol",
                  "Up/Down altitude   click base: home   Space pause")  # fmt: skip
    for k, line in enumerate(help_lines):
        _text(surf, line, (x, WINDOW[1] - 118 + 20 * k), 18, THEME["dim"])


# ------------------------------------------------------------------------------ results
def _draw_evaluation(surf: Surface, app: App) -> None:
    if app.final is None:  # no game scored yet
        return
    m = app.final["manual"]
    cx = WINDOW[0] // 2
    sc = app.scenario
    _text(surf, "Performance evaluation", (cx, 40), 36, THEME["dim"], anchor="center")
    _text(surf, m.grade, (cx, 110), 96, _GRADE_COLOR[m.grade], True, "center")
    _text(surf, f"{sc.name} ({sc.difficulty}), seed {app.seed}, {app.game.world.time_s:g} s played",
          (cx, 168), 24, THEME["dim"], anchor="center")  # fmt: skip
    y = 220
    for spec in METRICS:
        if spec.name == "grade":  # shown above, large
            continue
        bold = spec.name == "final_score"
        label = f"{spec.title} = {_FINAL_SCORE}" if bold else spec.title
        _text(surf, label, (cx - 330, y), 30, bold=bold)
        _text(surf, shown_text(spec, m, 2), (cx + 330, y), 30, bold=bold, anchor="topright")
        y += 44
    ref = app.final["reference2020"]
    _text(surf, f"2020 reference definition: final {ref.final_score:.2f} ({ref.grade})",
          (cx, y + 14), 22, THEME["dim"], anchor="center")  # fmt: skip


def _draw_playback(surf: Surface, app: App) -> None:
    _text(surf, "Save playback", (40, 40), 48, THEME["accent"], True)
    path = str(app.recording_path) if app.recording_path else "(not recorded)"
    lines = [
        ("Your game is recorded (every input, command and tick) in:", THEME["dim"]),
        (path, THEME["text"]),
        ("", THEME["text"]),
        ("Watch it again:", THEME["dim"]),
        (f"fcplan replay {path}", THEME["text"]),
        ("Make a video of it:", THEME["dim"]),
        (f"fcplan replay {path} --video game.mp4", THEME["text"]),
    ]
    if app.video_path is not None:
        lines += [("", THEME["text"]), (f"GIF written to {app.video_path}", THEME["ok"])]
    y = 130
    for text, color in lines:
        _text(surf, _fit(text, WINDOW[0] - 100, 26), (60, y), 26, color)
        y += 40


_SCREENS: dict[str, Callable[[Surface, App], None]] = {
    "welcome": _draw_welcome,
    "scenarios": _draw_scenarios,
    "tutorial": _draw_tutorial,
    "designer": _draw_designer,
    "preview": _draw_preview,
    "game": _draw_game,
    "evaluation": _draw_evaluation,
    "playback": _draw_playback,
}
"""The drawing function of each screen."""
