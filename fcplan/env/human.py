"""``render_mode="human"``: the environments' frames in a pygame window.

Every environment of :mod:`fcplan.env` draws its ``rgb_array`` frame with the renderer the game
uses (:func:`fcplan.render.render_frame` for the task and motion levels, the state grid for the
presets). :class:`HumanWindow` shows such frames in a pygame window, the way the game's viewer
(:mod:`fcplan.game.view`) blits the map, at the environment's ``render_fps``. The human mode of
every env is the ``rgb_array`` mode plus this window: the env renders itself after ``reset`` and
every ``step``, and ``render()`` returns None (the Gymnasium and PettingZoo convention).

pygame is optional (the ``game`` extra). Without it, asking for ``render_mode="human"`` raises
:class:`fcplan.errors.EnvError` with the one-line install hint :data:`PYGAME_HINT`. Headless
machines (tests, CI) set ``SDL_VIDEODRIVER=dummy``.

Examples
--------
``SDL_VIDEODRIVER=dummy python -c "..."`` runs this headless:

>>> import numpy as np
>>> window = HumanWindow("fcplan", fps=1000)  # doctest: +SKIP
>>> window.show(np.zeros((40, 60, 3), dtype=np.uint8))  # doctest: +SKIP
>>> window.size  # doctest: +SKIP
(60, 40)
>>> print(PYGAME_HINT)
render_mode="human" needs pygame: pip install "fcplan[game]" (from a checkout: pip install -e ".[game]")
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from fcplan.errors import EnvError

__all__ = ["HumanWindow", "WindowedRender", "PYGAME_HINT", "import_pygame"]

#: The one-line error when pygame is missing.
PYGAME_HINT = (
    'render_mode="human" needs pygame: pip install "fcplan[game]" '
    '(from a checkout: pip install -e ".[game]")'
)


def import_pygame() -> Any:
    """Import pygame, or raise :class:`EnvError` with :data:`PYGAME_HINT`."""
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    try:
        import pygame
    except ImportError:
        raise EnvError(PYGAME_HINT) from None
    return pygame


class HumanWindow:
    """A pygame window showing ``(H, W, 3)`` uint8 frames at most ``fps`` times a second.

    Parameters
    ----------
    title : str
        The window's caption.
    fps : float
        Frames per second; :meth:`show` waits so that frames are not shown faster.

    Raises
    ------
    EnvError
        If pygame is not installed (checked here, before any episode runs).
    """

    def __init__(self, title: str, fps: float = 10.0) -> None:
        self._pygame = import_pygame()
        self.title, self.fps = str(title), float(fps)
        self._screen: Any = None
        self._clock: Any = None
        #: the window's (width, height) once a frame was shown
        self.size: tuple[int, int] | None = None

    def show(self, frame: np.ndarray | None) -> None:
        """Show ``frame`` (rows = y); opens the window on first use and keeps events flowing."""
        if frame is None:
            return
        pg = self._pygame
        h, w = int(frame.shape[0]), int(frame.shape[1])
        if self._screen is None or self.size != (w, h):
            from fcplan.game.app import require_display

            require_display()
            pg.display.init()
            self._screen = pg.display.set_mode((w, h))
            pg.display.set_caption(self.title)
            self._clock = pg.time.Clock()
            self.size = (w, h)
        # the game viewer's blit: pygame surfaces are indexed (x, y)
        surf = pg.surfarray.make_surface(np.ascontiguousarray(frame[..., :3].swapaxes(0, 1)))
        self._screen.blit(surf, (0, 0))
        pg.event.pump()
        pg.display.flip()
        self._clock.tick(self.fps)

    def close(self) -> None:
        """Close the window (a later :meth:`show` opens a new one)."""
        if self._screen is not None:
            self._pygame.display.quit()
            self._screen = None
            self.size = None


class WindowedRender:
    """Render and close of the Gymnasium views over an inner env (``self.env``, made in
    ``rgb_array`` mode when a frame is wanted) with an optional :class:`HumanWindow`
    (``self.window``, set in ``render_mode="human"``)."""

    env: Any
    window: HumanWindow | None

    def _show(self) -> None:
        """Show the inner env's frame (human mode; otherwise nothing)."""
        if self.window is not None:
            self.window.show(self.env.render())

    def render(self) -> np.ndarray | None:
        """The inner env's ``rgb_array`` frame (or None); in human mode shows it, returns
        None."""
        if self.window is not None:
            self._show()
            return None
        frame: np.ndarray | None = self.env.render()
        return frame

    def close(self) -> None:
        """Close the window (human mode) and the inner env."""
        if self.window is not None:
            self.window.close()
        self.env.close()
