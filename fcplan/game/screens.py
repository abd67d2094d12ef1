"""The game's screens as a state machine, independent of pygame.

``fcplan play`` follows the FireCommander GUI's page flow (manual "GUI Reference Manual"):

.. code-block:: text

    welcome --Scenario mode--> scenarios --pick one--> game --time up / Esc--> evaluation
       |  \\--Open-world mode--> designer (general, fire, sites, team; or load a file)
       |                          --> preview --> tutorial --> game
       \\--Tutorial--> tutorial (pages)          evaluation --Save playback--> playback

:class:`App` holds the current screen and everything the screens show, lays out the buttons
(:class:`Button`, window pixels) and reacts to abstract events: ``{"type": "click", "pos": (x, y)}``,
``{"type": "move", "pos": (x, y)}`` and ``{"type": "key", "key": "up", "char": ""}`` (pygame key
names, ``char`` the typed text). The pygame front end (:mod:`fcplan.game.app`) only translates
events and draws what :class:`App` exposes, so every transition is testable without a display.

In the game, clicks on the map and the keys 1-9 / Up / Down become input dicts for the
:class:`~fcplan.game.session.GameSession` (see :mod:`fcplan.game.controls`); the session advances
at the scenario's real-time pace (``ticks_per_second`` x ``speed`` ticks per wall second, see
:meth:`App.advance`) or, in fast mode, a fixed number of ticks per frame.

Examples
--------
>>> app = App()
>>> app.screen
'welcome'
>>> app.press("scenario_mode"); app.screen
'scenarios'
>>> [b.label for b in app.buttons() if b.id.startswith("play:")][:3]
['Practice', '#1', '#2']
>>> app.press("back"); app.press("open_world"); app.screen, app.design.page
('designer', 'general')
>>> app.edit("fronts", "99")
'fronts per region: 99 is outside the manual limit 1..30'
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.game.designer import PAGES, Design
from fcplan.game.session import GameSession

__all__ = ["App", "Button", "SCREENS", "WINDOW", "MAP_RECT", "default_recording_path", "TUTORIAL"]

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

TUTORIAL: tuple[tuple[str, tuple[str, ...]], ...] = (
    (
        "Controls",
        (
            "Keys 1-9 select an agent (P = perception, A = action, H = hybrid).",
            "Click on the map to add a goal at the end of the selected agent's route.",
            "Click near the route's first goal to close a patrol loop (two goals or more).",
            "A later click replaces the loop with a new route.",
            "Up / Down: raise or lower a perception or hybrid agent by 5 m.",
            "   Higher = a larger field of view but less reliable sensing (100 % -> 40 %).",
            "Click on the agent base (depot) to send the selected agent home.",
            "Space pauses, Esc ends the game early. Every game is recorded.",
        ),
    ),
    (
        "The team",
        (
            "Perception agents (blue circles) find fire: only fire the team has sensed is shown.",
            "Action agents (yellow triangles) put out sensed fire: one water dump per goal",
            "   reached, over their field of view (the box), 90 % of the cells each time.",
            "Hybrid agents (violet diamonds) do both, pruning with 80 % confidence.",
            "Agents return to the base on low battery or an empty tank, recharge and refill,",
            "   then resume their route. An action agent idle at its last goal for 3 s goes home.",
            "The panel shows battery now and at the last planned goal, altitude and tank.",
        ),
    ),
    (
        "Scores",
        (
            "Negative reward: 0.1 per burning cell per second, plus the facility penalty",
            "   (house 1, hospital 2, power station 5, base 5) per burning cell inside it.",
            "OFS: pruned / all fire.  PS: sensed / all fire.  AS: pruned / sensed fire.",
            "FPS: facilities never on fire.  NRR: negative reward / expected without pruning.",
            "Final score = PS + AS + FPS - 3 NRR.",
            "Grades: Excellent >= 90, Well Done >= 80, Almost There! >= 60, Fair >= 50.",
        ),
    ),
)
"""Tutorial pages: (title, lines)."""

_KEYS_TO_GAME = {"1", "2", "3", "4", "5", "6", "7", "8", "9", "up", "down"}


@dataclass(frozen=True)
class Button:
    """A clickable rectangle: ``id`` names the action, ``rect`` is (x, y, width, height)."""

    id: str
    label: str
    rect: tuple[int, int, int, int]
    style: str = "normal"  #: normal | primary | small | selected | danger

    def contains(self, x: float, y: float) -> bool:
        bx, by, bw, bh = self.rect
        return bx <= x < bx + bw and by <= y < by + bh

    @property
    def center(self) -> tuple[int, int]:
        bx, by, bw, bh = self.rect
        return (bx + bw // 2, by + bh // 2)


def default_recording_path(
    scenario, seed: int, *, data_dir: str | os.PathLike | None = None
) -> Path:
    """Where a game is recorded when no path is given: the user's data folder.

    ``$FCPLAN_DATA_DIR``, else ``$XDG_DATA_HOME/fcplan`` (``~/.local/share/fcplan``) on Linux,
    ``~/Library/Application Support/fcplan`` on macOS, ``%APPDATA%/fcplan`` on Windows; then
    ``recordings/<scenario>-seed<seed>-<UTC time>.npz``.

    Examples
    --------
    >>> from fcplan import load_scenario
    >>> p = default_recording_path(load_scenario(3), 7, data_dir="/tmp/x")
    >>> p.parent.as_posix(), p.name.startswith("03-seed7-")
    ('/tmp/x/recordings', True)
    """
    if data_dir is None:
        data_dir = os.environ.get("FCPLAN_DATA_DIR")
    if data_dir is None:
        if sys.platform == "win32":
            base = Path(os.environ.get("APPDATA", Path.home() / "AppData" / "Roaming"))
        elif sys.platform == "darwin":
            base = Path.home() / "Library" / "Application Support"
        else:
            base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
        data_dir = base / "fcplan"
    if scenario.number is not None:
        slug = "practice" if scenario.number == 0 else f"{scenario.number:02d}"
    else:
        slug = "".join(c if c.isalnum() else "-" for c in scenario.name).strip("-") or "design"
    stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
    return Path(data_dir) / "recordings" / f"{slug}-seed{seed}-{stamp}.npz"


def _grid_buttons(items, x0, y0, w, h, gap, per_row, style="normal"):
    out = []
    for k, (bid, label) in enumerate(items):
        r, c = divmod(k, per_row)
        out.append(Button(bid, label, (x0 + c * (w + gap), y0 + r * (h + gap), w, h), style))
    return out


class App:
    """Everything the game's screens show and do (no pygame; see the module docstring).

    Parameters
    ----------
    scenario : Scenario, optional
        Start directly in a game of this scenario (``fcplan play --scenario``).
    seed : int
        Seed of the games played.
    record : path, optional
        Where to save the recording of the (first) game; default :func:`default_recording_path`.
    speed : float
        Real-time factor: 2 plays twice as fast as the scenario's pace.
    fast : bool
        Ignore the clock: each :meth:`advance` plays ``frame_ticks`` ticks (tests, screenshots).
    frame_ticks : int
        Ticks per :meth:`advance` in fast mode.
    data_dir : path, optional
        Folder for recordings (default: the user's data folder).
    exit_at_end : bool
        Quit when a game ends (after saving its recording) instead of showing the evaluation.
    """

    def __init__(
        self,
        scenario=None,
        *,
        seed: int = 0,
        record: str | os.PathLike | None = None,
        speed: float = 1.0,
        fast: bool = False,
        frame_ticks: int = 10,
        data_dir: str | os.PathLike | None = None,
        exit_at_end: bool = False,
    ) -> None:
        if not (speed > 0 and np.isfinite(speed)):
            raise FcplanError(f"speed must be a number > 0, got {speed!r}")
        self.seed = int(seed)
        self.record = Path(record) if record is not None else None
        self.speed = float(speed)
        self.fast = bool(fast)
        self.frame_ticks = max(int(frame_ticks), 1)
        self.data_dir = data_dir
        self.exit_at_end = exit_at_end
        self.running = True
        self.screen = "welcome"
        self.message = ""  #: status line (errors in the designer, notes in game)
        self.error = False  #: whether the message is an error
        self.tutorial_page = 0
        self.hover: str | None = None  #: id of the button under the mouse
        self.pending_scenario = None  #: open-world design waiting behind the tutorial
        self.design = Design()
        self.focus: str | None = None  #: designer field being typed into
        self.typed = ""
        self.file_text = ""  #: designer's "load a scenario file" box
        self.preview_scenario = None
        self.scenario = None
        self.session: GameSession | None = None
        self.recorder = None
        self.recording_path: Path | None = None
        self.final = None  #: both metric definitions of the last game
        self.paused = False
        self._tick_debt = 0.0
        self.video_path: Path | None = None
        self._saved: tuple | None = None  # (recorder id, path) last saved
        #: scripted inputs (dicts with a "tick") still to feed to the game, in tick order
        self.script: list[dict[str, Any]] = []
        if scenario is not None:
            self.start_game(scenario)

    # ================================================================== layout
    def buttons(self) -> list[Button]:
        """The clickable buttons of the current screen."""
        return getattr(self, f"_buttons_{self.screen}")()

    def _buttons_welcome(self) -> list[Button]:
        x, w = WINDOW[0] // 2 - 170, 340
        return [
            Button("scenario_mode", "Scenario mode", (x, 300, w, 60), "primary"),
            Button("open_world", "Open-world mode", (x, 380, w, 60), "primary"),
            Button("tutorial", "Tutorial", (x, 460, w, 60)),
            Button("quit", "Quit", (x, 560, w, 44), "small"),
        ]

    def hover_summary(self) -> str:
        """One line about the scenario button under the mouse (scenario mode), else ''."""
        if self.screen != "scenarios" or not (self.hover or "").startswith("play:"):
            return ""
        from fcplan.scenario import load_scenario

        return load_scenario(self.hover.split(":", 1)[1]).summary()

    def scenario_groups(self) -> list[tuple[str, list[tuple[str, str]]]]:
        """(group title, [(button id, label)]) for the scenario mode, by difficulty."""
        groups = [("Practice", [("play:practice", "Practice")])]
        for title, lo, hi in (("Easy", 1, 6), ("Moderate", 7, 18), ("Hard", 19, 24)):
            groups.append((title, [(f"play:{n}", f"#{n}") for n in range(lo, hi + 1)]))
        return groups

    def _buttons_scenarios(self) -> list[Button]:
        out = []
        y = 140
        for _title, items in self.scenario_groups():
            out += _grid_buttons(items, 220, y, 100 if len(items) > 1 else 160, 44, 12, 6)
            y += 56 * ((len(items) + 5) // 6) + 24
        out += [
            Button("seed:-1", "-", (220, y + 10, 44, 40), "small"),
            Button("seed:+1", "+", (380, y + 10, 44, 40), "small"),
            Button("back", "Back", (40, WINDOW[1] - 70, 140, 44), "small"),
        ]
        return out

    def _buttons_tutorial(self) -> list[Button]:
        out = [Button("back", "Back", (40, WINDOW[1] - 70, 140, 44), "small")]
        if self.pending_scenario is not None:  # open-world: preview -> tutorial -> game
            out.append(Button("tutorial:start", "Start the game", (WINDOW[0] // 2 - 120,
                                                                  WINDOW[1] - 70, 240, 44),
                              "primary"))  # fmt: skip
        if self.tutorial_page > 0:
            out.append(Button("tutorial:prev", "Previous", (WINDOW[0] - 360, WINDOW[1] - 70,
                                                               150, 44), "small"))  # fmt: skip
        if self.tutorial_page < len(TUTORIAL) - 1:
            out.append(Button("tutorial:next", "Next", (WINDOW[0] - 190, WINDOW[1] - 70, 150, 44)))
        return out

    def field_rows(self) -> list[tuple[Any, tuple[int, int, int, int]]]:
        """(field, value box rect) of the designer's current page."""
        fields = self.design.fields()
        h = min(40, 560 // max(len(fields), 1))
        return [(f, (330, 110 + k * h, 150, h - 6)) for k, f in enumerate(fields)]

    def _buttons_designer(self) -> list[Button]:
        out = []
        for k, page in enumerate(PAGES):
            style = "selected" if page == self.design.page else "small"
            out.append(Button(f"page:{page}", page.title(), (40 + k * 130, 50, 120, 40), style))
        for f, (x, y, w, h) in self.field_rows():
            out.append(Button(f"focus:{f.key}", self.design.text(f.key), (x, y, w, h), "field"))
            out.append(Button(f"nudge:{f.key}:-1", "-", (x + w + 8, y, h, h), "small"))
            out.append(Button(f"nudge:{f.key}:+1", "+", (x + w + 14 + h, y, h, h), "small"))
        bottom = WINDOW[1] - 70
        out += [
            Button("back", "Back", (40, bottom, 120, 44), "small"),
            Button("design:reset", "Reset", (170, bottom, 120, 44), "small"),
            Button("focus:__file__", self.file_text or "scenario.toml", (640, 600, 330, 40),
                   "field"),
            Button("design:load", "Load file", (980, 600, 130, 40), "small"),
            Button("design:next", "Next" if self.design.page != PAGES[-1] else "Preview",
                   (WINDOW[0] - 170, bottom, 140, 44), "primary"),
        ]  # fmt: skip
        return out

    def _buttons_preview(self) -> list[Button]:
        bottom = WINDOW[1] - 70
        return [
            Button("preview:back", "Back to design", (40, bottom, 200, 44), "small"),
            Button("preview:start", "Proceed: play", (WINDOW[0] - 240, bottom, 200, 44), "primary"),
        ]

    def _buttons_game(self) -> list[Button]:
        out = []
        if self.session is not None:
            for i, aid in enumerate(self.session.world.team.ids):
                out.append(Button(f"select:{i}", aid, self.agent_row_rect(i), "row"))
        out.append(Button("game:end", "End game (Esc)", (WINDOW[0] - 190, WINDOW[1] - 56, 170, 40),
                          "small"))  # fmt: skip
        return out

    def agent_row_rect(self, i: int) -> tuple[int, int, int, int]:
        """Panel row of agent ``i`` in the game screen."""
        return (PANEL_X, 112 + 30 * i, WINDOW[0] - PANEL_X - 16, 28)

    def _buttons_evaluation(self) -> list[Button]:
        y = WINDOW[1] - 80
        return [
            Button("save_playback", "Save playback", (60, y, 200, 48), "primary"),
            Button("play_again", "Play again", (280, y, 180, 48)),
            Button("scenario_mode", "Scenario mode", (480, y, 200, 48)),
            Button("main_menu", "Main menu", (700, y, 180, 48)),
            Button("quit", "Quit", (900, y, 160, 48), "small"),
        ]

    def _buttons_playback(self) -> list[Button]:
        y = WINDOW[1] - 80
        out = [Button("back_to_evaluation", "Back", (60, y, 160, 48), "small")]
        out.append(Button("write_video", "Write GIF video", (240, y, 240, 48), "primary"))
        out.append(Button("main_menu", "Main menu", (500, y, 180, 48)))
        return out

    # ================================================================== events
    def handle(self, event: dict[str, Any]) -> None:
        """React to one abstract event (a click or a key press)."""
        kind = event.get("type")
        if kind == "quit":
            self.quit()
        elif kind == "click":
            self.click(*event["pos"])
        elif kind == "move":
            x, y = event["pos"]
            self.hover = next((b.id for b in self.buttons() if b.contains(x, y)), None)
        elif kind == "key":
            self.key(str(event.get("key", "")), str(event.get("char", "")))

    def click(self, x: float, y: float) -> None:
        """A left click at window pixel (x, y)."""
        if self.screen == "game" and self._in_map(x, y):
            self._game_input({"type": "click", "button": 1, "screen": [int(x), int(y)],
                              "map": list(self.map_point(x, y))})  # fmt: skip
            return
        if self.screen == "designer" and self.focus and self.focus != "__file__":
            px, py, pw, ph = PREVIEW_RECT
            if (
                px <= x < px + pw
                and py <= y < py + ph
                and self.design.field(self.focus).kind == "cell"
            ):
                w = self.design.values["world_size"]
                problem = self.design.place(self.focus, (x - px) * w / pw, (y - py) * w / ph)
                self._say(problem or f"{self.design.field(self.focus).label} set", bool(problem))
                self.focus = None
                return
        for b in self.buttons():
            if b.contains(x, y):
                self.press(b.id)
                return

    def key(self, key: str, char: str = "") -> None:
        """A key press: ``key`` is the pygame key name, ``char`` the text it types."""
        if self.screen == "game":
            if key in _KEYS_TO_GAME:
                self._game_input({"type": "key", "key": key})
            elif key == "escape":
                self.end_game()
            elif key in ("space", "p"):
                self.paused = not self.paused
            return
        if self.screen == "designer" and self.focus:
            if key in ("return", "enter", "keypad enter"):
                self.commit_focus()
            elif key == "escape":
                self.focus = None
            elif key == "backspace":
                self.typed = self.typed[:-1]
            elif char and char.isprintable():
                self.typed += char
            return
        if key == "escape":
            if self.screen == "welcome":
                self.quit()
            elif self.screen in ("scenarios", "tutorial", "designer"):
                self.press("back")

    def press(self, bid: str) -> None:
        """Do what button ``bid`` does (also usable directly, e.g. in tests)."""
        head, _, arg = bid.partition(":")
        simple = {
            "scenario_mode": lambda: self._go("scenarios"),
            "open_world": lambda: self._go("designer"),
            "tutorial": self._open_tutorial,
            "quit": self.quit,
            "back": lambda: self._go("welcome"),
            "main_menu": lambda: self._go("welcome"),
            "play_again": lambda: self.start_game(self.scenario),
            "save_playback": lambda: self._go("playback"),
            "back_to_evaluation": lambda: self._go("evaluation"),
            "write_video": self.write_video,
        }
        if bid in simple:
            simple[bid]()
        elif head == "play":
            from fcplan.scenario import load_scenario

            self.start_game(load_scenario(arg))
        elif head == "seed":
            self.seed = max(self.seed + int(arg), 0)
        elif bid == "tutorial:start":
            scenario, self.pending_scenario = self.pending_scenario, None
            self.start_game(scenario)
        elif head == "tutorial":
            self.tutorial_page += 1 if arg == "next" else -1
            self.tutorial_page = min(max(self.tutorial_page, 0), len(TUTORIAL) - 1)
        elif head == "page":
            self.design.page = arg
            self.focus = None
        elif head == "focus":
            self.focus = arg
            self.typed = self.file_text if arg == "__file__" else self.design.text(arg)
        elif head == "nudge":
            key, _, d = arg.rpartition(":")
            problem = self.design.nudge(key, int(d))
            self._say(problem or "", bool(problem))
        elif head == "design":
            self._design_action(arg)
        elif head == "preview":
            if arg == "start":  # the manual shows the tutorial before an open-world game
                self.pending_scenario = self.preview_scenario
                self._open_tutorial()
            else:
                self._go("designer")
        elif head == "select" and self.session is not None:
            self._game_input({"type": "key", "key": str(int(arg) + 1), "via": "panel"})
        elif bid == "game:end":
            self.end_game()

    def _go(self, screen: str) -> None:
        if screen == "welcome":
            self.pending_scenario = None
        self.screen = screen
        self.hover = None
        self.focus = None
        self._say("")

    def _open_tutorial(self) -> None:
        self.tutorial_page = 0
        self._go("tutorial")

    def _say(self, message: str, error: bool = False) -> None:
        self.message, self.error = message, error

    def quit(self) -> None:
        """Stop the app; a game in progress is ended and its recording saved first."""
        if self.screen == "game" and self.session is not None:
            self.end_game(show=False)
        self.running = False

    # ================================================================== designer
    def edit(self, key: str, text: str) -> str | None:
        """Type ``text`` into designer field ``key`` and commit it; return the refusal, if any."""
        self.press(f"focus:{key}")
        self.typed = str(text)
        return self.commit_focus()

    def commit_focus(self) -> str | None:
        """Commit the typed text to the focused field; the refusal message is shown and returned."""
        key, text = self.focus, self.typed
        self.focus = None
        if key is None:
            return None
        if key == "__file__":
            self.file_text = text
            return None
        problem = self.design.set(key, text)
        self._say(problem or f"{self.design.field(key).label} = {self.design.text(key)}",
                  bool(problem))  # fmt: skip
        return problem

    def _design_action(self, arg: str) -> None:
        if arg == "reset":
            self.design = Design()
            self._say("design reset to the manual's defaults")
        elif arg == "next":
            k = PAGES.index(self.design.page)
            if k + 1 < len(PAGES):
                self.design.page = PAGES[k + 1]
                self.focus = None
            else:
                self.open_preview()
        elif arg == "load":
            if self.focus == "__file__":
                self.commit_focus()
            self.load_file(self.file_text)

    def open_preview(self) -> bool:
        """Build the design; show the preview, or the problems in the message line."""
        scenario, problems = self.design.build()
        if scenario is None:
            more = f" (+{len(problems) - 1} more)" if len(problems) > 1 else ""
            self._say(problems[0] + more, True)
            return False
        self.preview_scenario = scenario
        self._go("preview")
        return True

    def load_file(self, path: str) -> bool:
        """Load a scenario TOML file (or a shipped name) and preview it; errors go to the message."""
        from fcplan.scenario import load_scenario

        if not path.strip():
            self._say("type a scenario file path into the box first", True)
            return False
        try:
            scenario = load_scenario(path.strip())
        except (FcplanError, OSError) as exc:
            self._say(str(exc), True)
            return False
        self.preview_scenario = scenario
        self._go("preview")
        limits = scenario.manual_limit_violations()
        if limits:
            self._say(f"beyond the manual's GUI limits: {limits[0]}", True)
        return True

    def preview_image(self, size: int = PREVIEW_RECT[2]) -> np.ndarray:
        """The preview of the scenario being designed (or loaded), as an RGB image."""
        from fcplan.render import render_frame, snapshot
        from fcplan.world import World

        scenario = self.preview_scenario if self.screen == "preview" else None
        if scenario is None:
            scenario, _ = self.design.build()
        if scenario is None:
            scenario = self.preview_scenario
        if scenario is None:
            return np.zeros((size, size, 3), np.uint8)
        key = (id(scenario), size)
        if getattr(self, "_preview_key", None) != key:
            world = World().reset(scenario, seed=0)
            self._preview = (scenario, render_frame(scenario, snapshot(world), size=size,
                                                    panel=False))  # fmt: skip
            self._preview_key = key
        return self._preview[1]

    def preview_target(self):
        """The scenario the preview image shows (or None)."""
        return getattr(self, "_preview", (None, None))[0]

    # ================================================================== game
    def start_game(self, scenario) -> None:
        """Start a game of ``scenario`` (recorded) and show the game screen."""
        self.scenario = scenario
        self.recorder = _make_recorder(scenario, self.seed, self.speed, self.fast)
        self.session = GameSession(scenario, self.seed, recorder=self.recorder)
        if self.record is not None and self.recording_path is None:
            self.recording_path = self.record
        else:
            self.recording_path = default_recording_path(scenario, self.seed,
                                                         data_dir=self.data_dir)  # fmt: skip
        self.final = None
        self.paused = False
        self.video_path = None
        self._tick_debt = 0.0
        self._say(
            "" if self.recorder is not None else "recording unavailable", self.recorder is None
        )
        self._go("game")
        self.message = "Select an agent with 1-9, click on the map to give it goals."

    def map_point(self, x: float, y: float) -> tuple[float, float]:
        """World px of window pixel (x, y) in the game map."""
        mx, my, mw, mh = MAP_RECT
        w = self.session.scenario.world_size
        return (round((x - mx) * w / mw, 1), round((y - my) * w / mh, 1))

    def window_point(self, x: float, y: float) -> tuple[int, int]:
        """Window pixel of world point (x, y) in the game map."""
        mx, my, mw, mh = MAP_RECT
        w = self.session.scenario.world_size
        return (int(round(mx + x * mw / w)), int(round(my + y * mh / w)))

    def _in_map(self, x: float, y: float) -> bool:
        mx, my, mw, mh = MAP_RECT
        return mx <= x < mx + mw and my <= y < my + mh

    def _game_input(self, event: dict[str, Any]) -> None:
        if self.session is None or self.session.done:
            return
        self.session.input(event)
        self.message = self.session.controller.message

    def advance(self, dt_s: float = 0.0) -> int:
        """Play the game on: ``dt_s`` wall seconds at the scenario's pace (times ``speed``), or
        ``frame_ticks`` ticks in fast mode. Return the ticks played; end the game when time is up."""
        s = self.session
        if self.screen != "game" or s is None or self.paused:
            return 0
        if self.fast:
            n = self.frame_ticks
        else:
            tps = s.scenario.ticks_per_second
            self._tick_debt = min(self._tick_debt + dt_s * tps * self.speed, tps * self.speed)
            n = int(self._tick_debt)
            self._tick_debt -= n
        played = 0
        while played < n and not s.done:
            script = self.script
            while script and int(script[0]["tick"]) <= s.tick:
                self._game_input(script.pop(0))
            s.step()
            played += 1
        if s.done:
            self.end_game()
        return played

    def set_script(self, events) -> None:
        """Feed these input dicts (each with a ``"tick"``) to the game when it reaches their
        ticks, as if the player had made them then (e.g. the inputs of a recording)."""
        self.script = sorted((dict(e) for e in events), key=lambda e: int(e["tick"]))

    def end_game(self, show: bool = True) -> None:
        """Finish the game now: score it, save the recording, show the evaluation page."""
        s = self.session
        if s is None or self.screen != "game":
            return
        self.final = s.final_metrics()
        self.save_recording()
        if self.exit_at_end:
            self.running = False
        if show:
            self._go("evaluation")
            if self.recording_path is not None and self.recorder is not None:
                self._say(f"recorded to {self.recording_path}")

    def save_recording(self) -> Path | None:
        """Save the game's recording (once) to :attr:`recording_path`."""
        if self.recorder is None or self.recording_path is None:
            return None
        if self._saved == (id(self.recorder), self.recording_path):
            return self.recording_path
        self.recording_path.parent.mkdir(parents=True, exist_ok=True)
        self.recorder.save(self.recording_path)
        self._saved = (id(self.recorder), self.recording_path)
        return self.recording_path

    def write_video(self, *, speed: float = 10.0, size: int = 384) -> Path | None:
        """Write a GIF playback of the last game next to its recording (as ``fcplan replay
        PATH --video OUT.gif --speed 10`` does); show where, or why not."""
        if self.recording_path is None or not self.recording_path.exists():
            self._say("no recording to play back", True)
            return None
        try:
            from fcplan.recording import load_recording
            from fcplan.video import write_video
        except ImportError as exc:
            self._say(f"video playback unavailable: {exc}", True)
            return None
        out = self.recording_path.with_suffix(".gif")
        try:
            write_video(load_recording(self.recording_path), out, speed=speed, size=size)
        except (FcplanError, OSError, ImportError) as exc:
            self._say(str(exc), True)
            return None
        self.video_path = out
        self._say(f"playback written to {out}")
        return out


def _make_recorder(scenario, seed: int, speed: float, fast: bool = False):
    """A :class:`fcplan.recording.Recorder` for a human game, or None if it is unavailable."""
    try:
        from fcplan.recording import Recorder
    except ImportError:
        return None
    settings = {
        "game": "fcplan play",
        "mode": "scenario" if scenario.number is not None else "open-world",
        "speed": float(speed),
        "fast": bool(fast),
        "ticks_per_second": int(scenario.ticks_per_second),
    }
    return Recorder(scenario, seed, source="human", settings=settings)
