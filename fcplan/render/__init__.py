"""Frames of an episode as RGB images: a pure-numpy rasteriser shared by replay, video, the game
and the environments' ``render_mode="rgb_array"``.

Two steps. :func:`snapshot` copies what is worth drawing out of a live :class:`fcplan.world.World`
(fire grid, what the team knows, agent states, planned routes, online scores) into a frozen
:class:`FrameData`; a recording rebuilds the same :class:`FrameData` for any tick without a world.
A :class:`Renderer` (or the one-call :func:`render_frame`) draws a :class:`FrameData` on top of the
scenario's static map:

* the map (``size`` px square, world x to the right, world y downwards as in the game): grass with
  the 100-px chess grid, lakes, facilities (footprint outline and a marker per kind: house roof,
  hospital cross, power-station bolt), the depot with its agent slots;
* fire: cells the team knows are burning (red-orange), pruned cells (ash grey), and with
  ``show_truth=True`` the burning cells the team has not sensed (dim amber);
* every agent's field of view (translucent rectangle), its planned route (dashed line through its
  goals), and the agent itself: perception = blue circle, action = yellow triangle,
  hybrid = violet diamond; the selected agent gets a white ring;
* an information panel on the right (``panel=True``): time, fire counts, online scores, and per
  agent its mode, battery now and at its next goal (bar and %), altitude and tank, and a legend.

Modules: :mod:`~fcplan.render.frame` (:class:`FrameData`, :func:`snapshot`),
:mod:`~fcplan.render.raster` (the palette :data:`COLORS`, markers, lines and cell grids on numpy
images), :mod:`~fcplan.render.text` (anti-aliased DejaVu Sans text with Pillow, :func:`draw_text`,
and the greedy label placement :func:`place_labels`), :mod:`~fcplan.render.scene` (static map, fire
and agent layers), :mod:`~fcplan.render.panel` (the information panel) and
:mod:`~fcplan.render.renderer` (:class:`Renderer`, :func:`render_frame`). Neither matplotlib nor
pygame is needed; Pillow rasterises text with the bundled DejaVu Sans (``fcplan/render/fonts/``,
Bitstream Vera licence), imported on the first frame, not by ``import fcplan``. Everything is vectorised: fire layers are scattered (or gathered, when zooming in)
in one numpy operation each; only agents, routes and text lines are drawn one by one. A renderer
draws the static map once. The output depends only on its inputs (no randomness, no clock).

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.render import render_frame, snapshot
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> img = render_frame(world.scenario, snapshot(world), size=256)
>>> img.shape[0], img.dtype.name
(256, 'uint8')
"""

from fcplan.render.frame import FrameData, RenderError, snapshot
from fcplan.render.panel import MODE_NAMES, panel_width
from fcplan.render.raster import COLORS, font_px
from fcplan.render.renderer import Renderer, render_frame
from fcplan.render.text import draw_text, place_labels, text_size

__all__ = [
    "FrameData",
    "RenderError",
    "Renderer",
    "snapshot",
    "render_frame",
    "panel_width",
    "draw_text",
    "text_size",
    "place_labels",
    "font_px",
    "COLORS",
    "MODE_NAMES",
]
