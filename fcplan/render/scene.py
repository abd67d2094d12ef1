"""The map layers of a frame: the static map, the fire, the agents.

* :func:`draw_background`: the scenario's static map at ``size`` px (world x to the right, world y
  downwards as in the game): grass with a faint deterministic texture and the 100-px chess grid,
  lakes with a lighter rim, facilities (footprint and a marker per kind: house roof, hospital
  cross, power-station bolt), the depot with its agent slots. It depends only on the scenario and
  the size, so a :class:`~fcplan.render.Renderer` draws it once.
* :func:`draw_fire`: the cells the team knows are burning (red-orange, with a glow), pruned cells
  (ash grey), and with ``show_truth`` the burning cells the team has not sensed (dim amber). Each
  layer is scattered (or gathered, when zooming in) in one numpy operation; a cell covers at least
  one pixel, and on small images one more to the right and down, so 1-px trails stay visible.
* :func:`draw_agents`: every agent's field of view (translucent ``2z x 1.1547z`` rectangle), its
  planned route (dashed line through its goals), and the agent itself: perception = blue circle,
  action = yellow triangle, hybrid = violet diamond; the selected agent gets a white ring. On maps
  of 256 px or more each agent carries its id in bold DejaVu Sans, placed by
  :func:`~fcplan.render.text.place_labels` so that no two labels (and no label and another
  agent's marker) overlap when a free spot exists (agents bunched at the depot, a crowded fire).

Examples
--------
>>> from fcplan import load_scenario
>>> img = draw_background(load_scenario("practice"), 64)
>>> img.shape, img.flags.writeable
((64, 64, 3), False)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.fire import BURNING
from fcplan.render.frame import FrameData, RenderError
from fcplan.render.raster import (
    COLORS,
    ROLE_SHAPES,
    blit_mask,
    cell_pixels,
    font_px,
    halo,
    line,
    paint_px,
    rect,
    stamp,
)
from fcplan.render.text import draw_text, place_labels, text_size

__all__ = ["check_frame", "draw_agents", "draw_background", "draw_fire", "role_of"]


def draw_background(scenario: Any, size: int) -> np.ndarray:
    """The static map (grass, grid, lakes, facilities, depot) at ``size`` px, read-only."""
    w = scenario.world_size
    s = size / w
    img = np.empty((size, size, 3), dtype=np.uint8)
    img[:] = COLORS["grass"]
    # subtle deterministic texture: a smooth two-frequency pattern, no randomness
    p = np.arange(size, dtype=np.float32) / max(s, 1e-9)
    tex = np.sin(p[:, None] / 37.0) * np.cos(p[None, :] / 53.0) + 0.5 * np.sin(
        (p[:, None] + p[None, :]) / 23.0
    )
    img[:] = np.clip(img.astype(np.float32) + 5.0 * tex[..., None], 0, 255).astype(np.uint8)
    # 100-px grid
    for g in np.arange(100, w, 100) * s:
        k = int(round(g))
        if 0 <= k < size:
            img[:, k] = COLORS["grid"]
            img[k, :] = COLORS["grid"]
    # lakes: union of circles, with a lighter rim
    ys, xs = np.mgrid[0:size, 0:size].astype(np.float32) / s  # world y (rows), x (cols)
    lake = np.zeros((size, size), dtype=bool)
    rim = np.zeros((size, size), dtype=bool)
    for lk in scenario.lakes:
        for cx, cy, r in lk.circles:
            d2 = (xs - cx) ** 2 + (ys - cy) ** 2
            lake |= d2 <= r * r
            rim |= d2 <= (r + 6.0 / s) ** 2
    img[rim & ~lake] = COLORS["lake_edge"]
    img[lake] = COLORS["lake"]
    # facilities and depot
    r_mark = max(3.0, 18.0 * s)
    for fac in scenario.facilities:
        x0, x1, y0, y1 = (v * s for v in fac.footprint)
        fill = COLORS.get(fac.kind, COLORS["house"])
        rect(img, x0, x1, y0, y1, fill, fill_alpha=0.85, edge=False)
        rect(img, x0, x1, y0, y1, COLORS["outline"])
        _facility_marker(img, fac.kind, fac.center[0] * s, fac.center[1] * s, r_mark)
    dep = scenario.depot
    x0, x1, y0, y1 = (v * s for v in dep.footprint)
    rect(img, x0, x1, y0, y1, COLORS["depot"], fill_alpha=0.9, edge=False)
    rect(img, x0, x1, y0, y1, COLORS["depot_edge"])
    for ax, ay in (a.start for a in scenario.agents):
        stamp(img, "ring", ax * s, ay * s, max(2.5, 9.0 * s), COLORS["slot"])
    img.setflags(write=False)
    return img


def _facility_marker(img: np.ndarray, kind: str, cx: float, cy: float, r: float) -> None:
    """A label-free marker: house = roof and wall, hospital = cross, power station = bolt."""
    rr = int(np.ceil(r)) + 1
    d = np.arange(-rr, rr + 1, dtype=np.float64) / r
    dy, dx = d[:, None], d[None, :]
    if kind == "hospital":
        m = ((np.abs(dx) <= 0.28) & (np.abs(dy) <= 0.9)) | (
            (np.abs(dy) <= 0.28) & (np.abs(dx) <= 0.9)
        )
    elif kind == "power_station":
        upper = (dy >= -1) & (dy <= 0.1) & (dx >= -0.55 - 0.5 * dy) & (dx <= 0.05 - 0.5 * dy)
        lower = (dy >= -0.1) & (dy <= 1) & (dx >= -0.05 - 0.5 * dy) & (dx <= 0.55 - 0.5 * dy)
        m = upper | lower
    else:
        roof = (dy >= -0.9) & (dy <= -0.1) & (np.abs(dx) <= (dy + 0.9) * 1.1)
        wall = (dy > -0.1) & (dy <= 0.8) & (np.abs(dx) <= 0.6)
        m = roof | wall
    color = COLORS.get(f"marker_{kind}", COLORS["marker_house"])
    blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, color)


def role_of(frame: FrameData, i: int) -> str:
    """``"perception"``, ``"action"`` or ``"hybrid"``: the role of agent row ``i``."""
    sense, act = bool(frame.agent_can_sense[i]), bool(frame.agent_can_act[i])
    return "hybrid" if sense and act else ("action" if act else "perception")


def check_frame(scenario: Any, frame: FrameData) -> None:
    """Refuse a frame whose grids or team do not fit ``scenario`` (:class:`RenderError`)."""
    w = scenario.world_size
    for name in ("known", "pruned") + (("fire",) if frame.fire is not None else ()):
        shape = np.shape(getattr(frame, name))
        if shape != (w, w):
            raise RenderError(
                f"FrameData.{name}: shape {shape} does not match the scenario's {w} x {w} map"
            )
    n = len(scenario.agents)
    if np.shape(frame.agent_pos) != (n, 2):
        raise RenderError(
            f"FrameData.agent_pos: shape {np.shape(frame.agent_pos)}, expected ({n}, 2) for "
            f"scenario {scenario.name!r}"
        )


def draw_fire(img: np.ndarray, frame: FrameData, show_truth: bool) -> None:
    """Paint the fire layers: unseen burning cells (``show_truth``), pruned cells, then the known
    burning cells with a glow (so they stay visible)."""
    size = img.shape[0]
    s = size / frame.known.shape[0]
    # fire layers (hidden truth under known, pruned last so it stays visible)
    grow = 1 if s < 0.75 else 0
    if show_truth and frame.fire is not None:
        hidden = (frame.fire == BURNING) & ~frame.known
        paint_px(img, *cell_pixels(hidden, size, grow), COLORS["fire_hidden"], 0.75)
    paint_px(img, *cell_pixels(frame.pruned, size, grow), COLORS["pruned"])
    ky, kx = cell_pixels(frame.known, size, grow)
    paint_px(img, *halo(ky, kx, size), COLORS["fire_glow"], 0.5)
    paint_px(img, ky, kx, COLORS["fire"])


def draw_agents(img: np.ndarray, scenario: Any, frame: FrameData, roles: list[str]) -> None:
    """Paint every agent's field of view, planned route, marker (the selected one ringed) and,
    on maps of 256 px or more, its id."""
    size = img.shape[0]
    s = size / scenario.world_size
    pos = np.asarray(frame.agent_pos, dtype=np.float64) * s
    z = np.asarray(frame.agent_z, dtype=np.float64)
    n = len(pos)
    # fields of view: half extents z (x) and tan(30 deg) z (y)
    hx, hy = z * s, z * np.tan(np.pi / 6) * s
    for i in range(n):
        col = COLORS[roles[i]]
        x, y = pos[i]
        rect(img, x - hx[i], x + hx[i], y - hy[i], y + hy[i], col, fill_alpha=0.16)
    # planned routes: dashed line from the agent through its goals, a dot at each goal
    dash = max(2, size // 128)
    for i, route in enumerate(frame.routes[:n]):
        route = np.asarray(route, dtype=np.float64).reshape(-1, 2) * s
        if len(route) == 0:
            continue
        col = COLORS[roles[i]]
        pts = np.vstack([pos[i : i + 1], route])
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            line(img, a[0], a[1], b[0], b[1], col, dash=dash, alpha=0.9)
        for gx, gy in route:
            stamp(img, "square", gx, gy, max(1.0, 2.5 * s * 2), col, outline=COLORS["outline"])
    # agents on top
    r_agent = max(3.5, 13.0 * s)
    for i in range(n):
        x, y = pos[i]
        if frame.selected is not None and i == frame.selected:
            stamp(img, "ring", x, y, r_agent + max(3.0, 6 * s), COLORS["selected"])
        stamp(
            img, ROLE_SHAPES[roles[i]], x, y, r_agent, COLORS[roles[i]], outline=COLORS["outline"]
        )
    if size >= 256:
        _draw_labels(img, scenario, pos, r_agent)


def _draw_labels(img: np.ndarray, scenario: Any, pos: np.ndarray, r_agent: float) -> None:
    """Every agent's id next to its marker, at non-overlapping spots (greedy placement)."""
    size = img.shape[0]
    px = font_px(size)
    n = len(pos)
    labels = [scenario.agents[i].id if i < n and i < len(scenario.agents) else str(i + 1)
              for i in range(n)]  # fmt: skip
    sizes = [(w + 1, h + 1) for w, h in (text_size(t, px, bold=True) for t in labels)]  # + shadow
    boxes = place_labels(pos, sizes, r_agent + 1.0, (img.shape[1], size), gap=1)
    for label, (x0, y0, _, _) in zip(labels, boxes, strict=True):
        draw_text(img, label, x0, y0, COLORS["text"], px, bold=True, shadow=COLORS["outline"])
