"""Drawing whole frames: :class:`Renderer` (one scenario at one size) and :func:`render_frame`.

A :class:`Renderer` draws the scenario's static map once, when it is made, and then each frame
as a copy of it with the fire and agent layers (:mod:`fcplan.render.scene`) and, optionally, the
information panel (:mod:`fcplan.render.panel`) appended on the right. Hold one for as long as you
draw frames of the same scenario at the same size (a video, an environment's ``render()``).

:func:`render_frame` is the one-call convenience: it reuses a renderer for equal
``(scenario, size)`` (a bounded memo of a pure function of those values: the static map depends
on nothing else), so a loop of calls costs what a held renderer costs.

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.render import snapshot
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> renderer = Renderer(world.scenario, size=128)
>>> img = renderer.render(snapshot(world), panel=False)
>>> img.shape, bool((img == render_frame(world.scenario, snapshot(world), size=128,
...                                      panel=False)).all())
((128, 128, 3), True)
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from fcplan.render.frame import FrameData, RenderError
from fcplan.render.panel import draw_panel
from fcplan.render.scene import (
    check_frame,
    draw_agents,
    draw_background,
    draw_fire,
    role_of,
)

__all__ = ["Renderer", "render_frame"]


class Renderer:
    """Draws frames of one scenario at one map size; holds the static map.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
        Supplies the static map (facilities, depot, lakes) and the agents' ids and capacities.
    size : int
        Side of the square map in px (the world is scaled to it), at least 32.

    Attributes
    ----------
    background : numpy.ndarray
        ``(size, size, 3)`` uint8, read-only: the static map every frame is drawn on.

    Raises
    ------
    RenderError
        If ``size`` is below 32.
    """

    def __init__(self, scenario: Any, size: int = 512) -> None:
        size = int(size)
        if size < 32:
            raise RenderError(f"render size must be at least 32 px, got {size}")
        self.scenario = scenario
        self.size = size
        self.background = draw_background(scenario, size)

    def render(
        self, frame: FrameData, *, show_truth: bool = False, panel: bool = True
    ) -> np.ndarray:
        """Draw one frame (see :func:`render_frame` for the parameters).

        Returns
        -------
        numpy.ndarray
            ``(size, size [+ panel_width(size)], 3)`` uint8.
        """
        check_frame(self.scenario, frame)
        img = self.background.copy()
        draw_fire(img, frame, show_truth)
        roles = [role_of(frame, i) for i in range(len(frame.agent_pos))]
        draw_agents(img, self.scenario, frame, roles)
        if not panel:
            return img
        side = draw_panel(self.scenario, frame, self.size, roles, show_truth)
        return np.concatenate([img, side], axis=1)


@lru_cache(maxsize=16)
def _shared(scenario: Any, size: int) -> Renderer:
    """The renderer reused by :func:`render_frame` for an equal (scenario, size)."""
    return Renderer(scenario, size)


def render_frame(
    scenario: Any,
    frame: FrameData,
    *,
    size: int = 512,
    show_truth: bool = False,
    panel: bool = True,
) -> np.ndarray:
    """Draw one frame.

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
        Supplies the static map (facilities, depot, lakes) and the agents' ids and capacities.
    frame : FrameData
    size : int
        Side of the square map in px (the world is scaled to it).
    show_truth : bool
        Also draw burning cells the team does not know about (dim amber).
    panel : bool
        Append the information panel on the right (:func:`~fcplan.render.panel_width` px wide).

    Returns
    -------
    ndarray, (size, size [+ panel_width(size)], 3) uint8

    Raises
    ------
    RenderError
        A size below 32 px, or a frame that does not fit the scenario.

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> from fcplan.render import snapshot
    >>> world = World().reset(load_scenario(1), seed=0)
    >>> img = render_frame(world.scenario, snapshot(world), size=200, panel=False)
    >>> img.shape
    (200, 200, 3)
    """
    size = int(size)
    try:
        renderer = _shared(scenario, size)
    except TypeError:  # an unhashable scenario-like object: draw without reuse
        renderer = Renderer(scenario, size)
    return renderer.render(frame, show_truth=show_truth, panel=panel)
