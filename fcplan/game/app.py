"""The pygame front end of ``fcplan play``: window, event loop, clock and screenshots.

:func:`run_app` opens the window, turns pygame events into the abstract events of
:class:`~fcplan.game.screens.App` (left clicks, key presses with their pygame key names), advances
the game by the wall time since the last frame (the scenario's ``ticks_per_second`` times the
``speed`` factor; in fast mode a fixed number of ticks per frame, never waiting), draws with
:mod:`fcplan.game.view` and, if asked, saves a screenshot of the window once the game reaches a
given simulated time. Headless use (tests, screenshots on a server) needs
``SDL_VIDEODRIVER=dummy``.

``script`` feeds recorded-style input dicts (``{"tick": 12, "type": "click", "map": [x, y]}``) to
the game at their ticks, exactly as if they had been clicked: that is how the README screenshot
is made (``docs/game_inputs.json``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from fcplan.errors import FcplanError, install_hint
from fcplan.game.screens import WINDOW, App
from fcplan.recording.reader import read_bytes

__all__ = ["run_app", "GameError", "require_display", "load_script"]


class GameError(FcplanError):
    """The game cannot start (no pygame, no display) or a script file is malformed."""


def _import_pygame() -> Any:
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        import pygame
    except ImportError:
        raise GameError(f"the game needs pygame: {install_hint('game')}") from None
    return pygame


def require_display() -> None:
    """Raise :class:`GameError` when no display is available (and no SDL driver is forced)."""
    if os.environ.get("SDL_VIDEODRIVER"):
        return
    import sys

    if sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    ):
        raise GameError(
            "no display found (DISPLAY is not set); to run headless set SDL_VIDEODRIVER=dummy"
        )


#: Bound on an input script file (a 10-minute game with an input every tick is about 2 MB).
MAX_SCRIPT_BYTES = 64 * 2**20


def load_script(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Read a JSON list of input dicts, each with an integer ``"tick"`` and a ``"type"``.

    Only a regular file of at most :data:`MAX_SCRIPT_BYTES` is read (a FIFO or device is
    refused without blocking); every failure is one :class:`GameError` line naming the file.
    """
    raw = read_bytes(os.fspath(path), GameError, MAX_SCRIPT_BYTES)
    try:
        data = json.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise GameError(f"{path}: not valid JSON: not UTF-8 text") from None
    except json.JSONDecodeError as exc:
        raise GameError(f"{path}: not valid JSON: {exc.msg} (line {exc.lineno})") from None
    except RecursionError:
        raise GameError(f"{path}: not valid JSON: nested too deeply") from None
    if not isinstance(data, list):
        raise GameError(f"{path}: expected a JSON list of input events")
    for k, ev in enumerate(data):
        if not (isinstance(ev, dict) and isinstance(ev.get("tick"), int) and "type" in ev):
            raise GameError(f"{path}: event [{k}] needs an integer 'tick' and a 'type'")
    return data


def _save(pygame: Any, surf: Any, path: str | os.PathLike[str]) -> None:
    """Save the window as PNG at ``path``; a one-line GameError if that cannot be done."""
    if os.path.exists(path) and not os.path.isfile(path):  # a folder, device or FIFO
        raise GameError(f"--screenshot {str(path)!r}: not a regular file")
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        pygame.image.save(surf, str(path))
    except (OSError, pygame.error) as exc:
        raise GameError(f"--screenshot {str(path)!r}: cannot save the window: {exc}") from None


def _translate(pygame: Any, ev: Any) -> dict[str, Any] | None:
    if ev.type == pygame.QUIT:
        return {"type": "quit"}
    if ev.type == pygame.MOUSEBUTTONDOWN and getattr(ev, "button", 1) == 1:
        return {"type": "click", "pos": tuple(ev.pos)}
    if ev.type == pygame.MOUSEMOTION:
        return {"type": "move", "pos": tuple(ev.pos)}
    if ev.type == pygame.KEYDOWN:
        name = pygame.key.name(ev.key)
        if len(name) == 3 and name[0] == "[" and name[1].isdigit():  # keypad digits
            name = name[1]
        return {"type": "key", "key": name, "char": getattr(ev, "unicode", "")}
    return None


def run_app(
    app: App,
    *,
    fps: int = 30,
    script: Iterable[Mapping[str, Any]] = (),
    screenshot: str | os.PathLike[str] | None = None,
    screenshot_at_s: float | None = None,
    quit_after_screenshot: bool = False,
    on_frame: Callable[[App], None] | None = None,
) -> App:
    """Run the game window until the player quits (or the app stops itself); return the app.

    Parameters
    ----------
    app : App
        The state machine to show (e.g. ``App(scenario, seed=0)`` to start in a game).
    fps : int
        Frame-rate cap when playing in real time (the game's pace comes from the clock, not fps).
    script : iterable of dict
        Input dicts with a ``"tick"``, fed to the game when it reaches that tick.
    screenshot : path, optional
        Save the window as PNG once the game reaches ``screenshot_at_s`` simulated seconds (or at
        the first game frame if None).
    quit_after_screenshot : bool
        Stop (ending and saving the game) right after the screenshot.
    on_frame : callable, optional
        Called with the app after every frame (tests use it to post pygame events).
    """
    pygame = _import_pygame()
    require_display()
    try:
        pygame.display.init()
        pygame.font.init()
        surf = pygame.display.set_mode(WINDOW)
    except pygame.error as exc:
        raise GameError(
            f"cannot open a window ({exc}); to run headless set SDL_VIDEODRIVER=dummy"
        ) from None
    pygame.display.set_caption("fcplan play - FireCommander")
    from fcplan.game.view import draw, reset_fonts

    reset_fonts()
    app.set_script(script)
    shot_done = screenshot is None
    clock = pygame.time.Clock()
    clock.tick()
    try:
        while app.running:
            for ev in pygame.event.get():
                abstract = _translate(pygame, ev)
                if abstract is not None:
                    app.handle(abstract)
            s = app.session
            dt = clock.tick(0 if app.fast else fps) / 1000.0
            app.advance(dt)
            if not app.running:
                break
            draw(surf, app)
            pygame.display.flip()
            if screenshot is not None and not shot_done and s is not None:
                # due at its time, or when the game ended before it (else nothing would quit)
                due = screenshot_at_s is None or s.world.time_s >= screenshot_at_s or s.done
                if due and (app.screen == "game" or s.done):
                    _save(pygame, surf, screenshot)
                    shot_done = True
                    if quit_after_screenshot:
                        app.quit()
            if on_frame is not None:
                on_frame(app)
    finally:
        if app.screen == "game" and app.session is not None:
            app.end_game(show=False)  # Ctrl-C or an error: keep the recording
        pygame.display.quit()
    return app
