"""The game's screens as a state machine, independent of pygame.

``fcplan play`` follows the FireCommander GUI's page flow (manual "GUI Reference Manual"):

.. code-block:: text

    welcome --Scenario mode--> scenarios --pick one--> game --time up / Esc--> evaluation
       |  \\--Open-world mode--> designer (general, fire, sites, team; or load a file)
       |                          --> preview --> tutorial --> game
       \\--Tutorial--> tutorial (pages)          evaluation --Save playback--> playback

:class:`App` holds the current screen and everything the screens show, gives the buttons of the
current screen (:class:`~fcplan.game.layout.Button`, window pixels, laid out by
:mod:`fcplan.game.layout`) and reacts to abstract events: ``{"type": "click", "pos": (x, y)}``,
``{"type": "move", "pos": (x, y)}`` and ``{"type": "key", "key": "up", "char": ""}`` (pygame key
names, ``char`` the typed text). The pygame front end (:mod:`fcplan.game.app`) only translates
events and draws what :class:`App` exposes, so every transition is testable without a display.

In the game, clicks on the map and the keys 1-9 / Up / Down become input dicts for the
:class:`~fcplan.game.session.GameSession` (see :mod:`fcplan.game.controls`); the session advances
at the scenario's real-time pace (``ticks_per_second`` x ``speed`` ticks per wall second, see
:meth:`App.advance`) or, in fast mode, a fixed number of ticks per frame. Every game is recorded
(:mod:`fcplan.game.storage`); the tutorial's text is :data:`fcplan.game.tutorial.TUTORIAL`.

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
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.game.designer import PAGES, Design
from fcplan.game.layout import (
    MAP_RECT,
    PANEL_X,
    PREVIEW_RECT,
    SCREENS,
    WINDOW,
    Button,
    agent_row_rect,
    designer_buttons,
    evaluation_buttons,
    field_rows,
    game_buttons,
    playback_buttons,
    preview_buttons,
    scenario_buttons,
    scenario_groups,
    tutorial_buttons,
    welcome_buttons,
)
from fcplan.game.session import GameSession
from fcplan.game.storage import default_recording_path, make_recorder
from fcplan.game.tutorial import TUTORIAL
from fcplan.metrics import Metrics

__all__ = [
    "App",
    "Button",
    "SCREENS",
    "WINDOW",
    "MAP_RECT",
    "PANEL_X",
    "PREVIEW_RECT",
    "default_recording_path",
    "TUTORIAL",
]

_KEYS_TO_GAME = {"1", "2", "3", "4", "5", "6", "7", "8", "9", "up", "down"}


@dataclass(frozen=True)
class _Preview:
    """The designer's preview image and the scenario (at the size) it shows."""

    scenario: Any
    size: int
    image: np.ndarray


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
        scenario: Any = None,
        *,
        seed: int = 0,
        record: str | os.PathLike[str] | None = None,
        speed: float = 1.0,
        fast: bool = False,
        frame_ticks: int = 10,
        data_dir: str | os.PathLike[str] | None = None,
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
        self.pending_scenario: Any = None  #: open-world design waiting behind the tutorial
        self.design = Design()
        self.focus: str | None = None  #: designer field being typed into
        self.typed = ""
        self.file_text = ""  #: designer's "load a scenario file" box
        self.preview_scenario: Any = None
        self._preview: _Preview | None = None
        self.scenario: Any = None
        self.session: GameSession | None = None
        self.recorder: Any = None
        self.recording_path: Path | None = None
        self.final: dict[str, Metrics] | None = None  #: both metric definitions of the last game
        self.paused = False
        self._tick_debt = 0.0
        self.video_path: Path | None = None
        self._saved: tuple[Any, Path] | None = None  # (recorder, path) last saved
        #: scripted inputs (dicts with a "tick") still to feed to the game, in tick order
        self.script: list[dict[str, Any]] = []
        if scenario is not None:
            self.start_game(scenario)

    # ================================================================== layout
    def buttons(self) -> list[Button]:
        """The clickable buttons of the current screen."""
        layouts: dict[str, Callable[[], list[Button]]] = {
            "welcome": welcome_buttons,
            "scenarios": scenario_buttons,
            "tutorial": lambda: tutorial_buttons(
                self.tutorial_page, len(TUTORIAL), self.pending_scenario is not None
            ),
            "designer": lambda: designer_buttons(self.design, PAGES, self.file_text),
            "preview": preview_buttons,
            "game": lambda: game_buttons(
                self.session.world.team.ids if self.session is not None else []
            ),
            "evaluation": evaluation_buttons,
            "playback": playback_buttons,
        }
        return layouts[self.screen]()

    def hover_summary(self) -> str:
        """One line about the scenario button under the mouse (scenario mode), else ''."""
        if self.screen != "scenarios" or not (self.hover or "").startswith("play:"):
            return ""
        from fcplan.scenario import load_scenario

        return load_scenario((self.hover or "").split(":", 1)[1]).summary()

    def scenario_groups(self) -> list[tuple[str, list[tuple[str, str]]]]:
        """(group title, [(button id, label)]) for the scenario mode, by difficulty."""
        return scenario_groups()

    def field_rows(self) -> list[tuple[Any, tuple[int, int, int, int]]]:
        """(field, value box rect) of the designer's current page."""
        return field_rows(self.design)

    def agent_row_rect(self, i: int) -> tuple[int, int, int, int]:
        """Panel row of agent ``i`` in the game screen."""
        return agent_row_rect(i)

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
        simple: dict[str, Callable[[], Any]] = {
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
        p = self._preview
        if p is None or p.size != size or p.scenario != scenario:  # equal scenarios look alike
            world = World().reset(scenario, seed=0)
            image = render_frame(scenario, snapshot(world), size=size, panel=False)
            p = self._preview = _Preview(scenario, size, image)
        return p.image

    def preview_target(self) -> Any:
        """The scenario the preview image shows (or None)."""
        return None if self._preview is None else self._preview.scenario

    # ================================================================== game
    def start_game(self, scenario: Any) -> None:
        """Start a game of ``scenario`` (recorded) and show the game screen."""
        self.scenario = scenario
        self.recorder = make_recorder(scenario, self.seed, self.speed, self.fast)
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
        w = self.game.scenario.world_size
        return (round((x - mx) * w / mw, 1), round((y - my) * w / mh, 1))

    def window_point(self, x: float, y: float) -> tuple[int, int]:
        """Window pixel of world point (x, y) in the game map."""
        mx, my, mw, mh = MAP_RECT
        w = self.game.scenario.world_size
        return (int(round(mx + x * mw / w)), int(round(my + y * mh / w)))

    @property
    def game(self) -> GameSession:
        """The game being played (an error outside a game)."""
        if self.session is None:
            raise FcplanError("no game has been started")
        return self.session

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

    def set_script(self, events: Iterable[Mapping[str, Any]]) -> None:
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
        saved = self._saved
        if saved is not None and saved[0] is self.recorder and saved[1] == self.recording_path:
            return self.recording_path
        self.recording_path.parent.mkdir(parents=True, exist_ok=True)
        self.recorder.save(self.recording_path)
        self._saved = (self.recorder, self.recording_path)
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
