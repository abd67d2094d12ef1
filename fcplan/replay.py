"""Watching a recording in a pygame window: the player behind ``fcplan replay``.

Frames are rebuilt from the recording alone (cumulative fire events, agent states, the routes of
the last commands) and drawn by :mod:`fcplan.render`, the renderer the environments and the game
use. :func:`play_window` plays the episode at a frame rate and a speed (Space pauses, Left/Right
step while paused, Esc or closing the window quits); it needs a display (:func:`has_display`) and
pygame (``fcplan[game]``). Videos are written by :mod:`fcplan.video`; the command line is
:mod:`fcplan.cli.replay`.

The window keeps the last :data:`HISTORY` rendered frames (for stepping back while paused) and
renders the others as they are shown, so memory does not grow with the episode's length.

Examples
--------
``fcplan replay run.npz --speed 4`` opens the window; from Python,
``play_window(load_recording("run.npz"), speed=4)``. At 10 frames per second and 4x speed, a
180-s episode at 10 Hz shows every 4th tick, 450 frames:

>>> from fcplan.video import replay_ticks
>>> len(replay_ticks(1800, 10, fps=10, speed=4))
450
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

from fcplan.errors import FcplanError, install_hint

if TYPE_CHECKING:
    from fcplan.recording import Recording

__all__ = ["HISTORY", "ReplayError", "has_display", "play_window"]

#: Rendered frames kept for stepping back while paused.
HISTORY = 100


class ReplayError(FcplanError):
    """The replay window cannot open (no pygame)."""


def has_display() -> bool:
    """Whether a window can be opened (Windows/macOS, or X11/Wayland on other systems)."""
    if os.environ.get("SDL_VIDEODRIVER", "") == "dummy":
        return True  # headless SDL (tests); windows open, nothing is shown
    if sys.platform in ("win32", "darwin"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def play_window(
    rec: Recording,
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    size: int = 512,
    show_truth: bool = False,
    start_s: float = 0.0,
    end_s: float | None = None,
) -> int:
    """Play ``rec`` in a pygame window; return 0 when the window is closed.

    Parameters
    ----------
    rec : fcplan.recording.Recording
    fps, speed, start_s, end_s
        Frames per second, times real time and the simulated time window
        (:func:`fcplan.video.replay_ticks`).
    size : int
        Map side in px (the information panel is added on the right).
    show_truth : bool
        Also draw the fire the team has not sensed.

    Raises
    ------
    ReplayError
        Without pygame.
    """
    try:
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame
    except ImportError:
        raise ReplayError(f"the replay window needs pygame: {install_hint('game')}") from None
    from fcplan.render import render_frame
    from fcplan.video import replay_ticks

    sc = rec.scenario
    ticks = replay_ticks(
        rec.n_ticks, sc.ticks_per_second, fps=fps, speed=speed, start_s=start_s, end_s=end_s
    )
    headless = os.environ.get("SDL_VIDEODRIVER", "") == "dummy"
    pygame.display.init()
    try:
        frames = rec.frames(ticks.start, ticks.stop - 1, ticks.step)
        first = render_frame(sc, next(frames), size=size, show_truth=show_truth)
        screen = pygame.display.set_mode((first.shape[1], first.shape[0]))
        pygame.display.set_caption(f"fcplan replay - {sc.name} - {rec.source}")
        clock = pygame.time.Clock()
        shown = {0: first}  # the last HISTORY rendered frames, so Left can step back
        k, paused, more, n = 0, False, True, 1
        while True:
            for ev in pygame.event.get():
                if ev.type == pygame.QUIT or (
                    ev.type == pygame.KEYDOWN and ev.key in (pygame.K_ESCAPE, pygame.K_q)
                ):
                    return 0
                if ev.type == pygame.KEYDOWN and ev.key == pygame.K_SPACE:
                    paused = not paused
                if ev.type == pygame.KEYDOWN and paused and ev.key == pygame.K_LEFT:
                    k = max(k - 1, min(shown))
                if ev.type == pygame.KEYDOWN and paused and ev.key == pygame.K_RIGHT:
                    k += 1
            if not paused:
                k += 1
            while more and k >= n:
                frame = next(frames, None)
                if frame is None:
                    more = False
                    break
                shown[n] = render_frame(sc, frame, size=size, show_truth=show_truth)
                shown.pop(n - HISTORY, None)
                n += 1
            if k >= n:
                k = n - 1
                if headless:
                    return 0
                paused = True  # hold the last frame until the window is closed
            surf = pygame.surfarray.make_surface(shown[k].swapaxes(0, 1))
            screen.blit(surf, (0, 0))
            pygame.display.flip()
            clock.tick(fps)
    finally:
        pygame.display.quit()
