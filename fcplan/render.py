"""Frames of an episode as RGB images: a pure-numpy rasteriser shared by replay, video, the game
and the environments' ``render_mode="rgb_array"``.

Two steps. :func:`snapshot` copies what is worth drawing out of a live :class:`fcplan.world.World`
(fire grid, what the team knows, agent states, planned routes, online scores) into a frozen
:class:`FrameData`; a recording rebuilds the same :class:`FrameData` for any tick without a world.
:func:`render_frame` draws a :class:`FrameData` on top of the scenario's static map:

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

Text uses a built-in 5x7 bitmap font (:func:`draw_text`), so neither matplotlib nor pygame is
needed. Everything is vectorised: fire layers are scattered (or gathered, when zooming in) in one
numpy operation each; only agents, routes and text lines are drawn one by one. The static map is
cached per (scenario, size). The output depends only on its inputs (no randomness, no clock).

Examples
--------
>>> from fcplan import World, load_scenario
>>> from fcplan.render import render_frame, snapshot
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> for _ in range(30):
...     _ = world.step()
>>> img = render_frame(world.scenario, snapshot(world), size=256)
>>> img.shape[0], img.dtype.name
(256, 'uint8')
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from fcplan.errors import FcplanError

__all__ = [
    "FrameData",
    "RenderError",
    "snapshot",
    "render_frame",
    "panel_width",
    "draw_text",
    "text_size",
    "COLORS",
    "MODE_NAMES",
]

DRAIN_PER_PX = 0.1  # battery per px flown (fcplan.team.DRAIN_PER_PX; kept here to stay light)
_BURNING, _PRUNED = 1, 2  # fcplan.fire.BURNING / PRUNED


class RenderError(FcplanError, ValueError):
    """A frame does not fit the scenario it is drawn on (grid or team size)."""


#: RGB colours of every element, by name (change them to restyle every frame).
COLORS: dict[str, tuple[int, int, int]] = {
    "grass": (70, 98, 62),
    "grid": (84, 114, 74),
    "lake": (58, 110, 168),
    "lake_edge": (120, 170, 215),
    "house": (181, 140, 96),
    "hospital": (222, 224, 230),
    "power_station": (128, 128, 146),
    "outline": (24, 24, 28),
    "marker_house": (140, 52, 38),
    "marker_hospital": (210, 40, 40),
    "marker_power_station": (250, 210, 40),
    "depot": (92, 94, 108),
    "depot_edge": (210, 212, 222),
    "slot": (150, 152, 166),
    "fire": (255, 72, 24),
    "fire_glow": (255, 200, 60),
    "fire_hidden": (255, 170, 40),
    "pruned": (176, 176, 182),
    "perception": (84, 190, 255),
    "action": (255, 208, 56),
    "hybrid": (214, 120, 255),
    "selected": (255, 255, 255),
    "panel": (27, 30, 37),
    "panel_line": (60, 64, 76),
    "text": (226, 228, 234),
    "text_dim": (140, 146, 160),
    "accent": (255, 150, 70),
    "bar_bg": (54, 58, 70),
    "bar_ok": (96, 200, 110),
    "bar_low": (230, 80, 60),
    "bar_goal": (255, 255, 255),
}

#: Short panel names of :class:`fcplan.team.Mode` values.
MODE_NAMES = {0: "IDLE", 1: "ACTV", 2: "RTRN", 3: "HOME"}
_ROLE_KEYS = ("perception", "action", "hybrid")


@dataclass(frozen=True, eq=False)
class FrameData:
    """What one frame shows: the state of an episode at one instant.

    Grids are indexed ``[x, y]`` (as :attr:`fcplan.fire.Fire.state`); agents are rows in scenario
    order (perception, action, hybrid).
    """

    tick: int
    time_s: float
    fire: np.ndarray | None  # (W, W) uint8 true fire state (fcplan.fire codes), None if unknown
    known: np.ndarray  # (W, W) bool cells the team knows are burning
    pruned: np.ndarray  # (W, W) bool cells put out
    agent_pos: np.ndarray  # (N, 2) float64 planar position (px)
    agent_z: np.ndarray  # (N,) float64 altitude (m)
    agent_can_sense: np.ndarray  # (N,) bool perception or hybrid
    agent_can_act: np.ndarray  # (N,) bool action or hybrid
    agent_battery: np.ndarray  # (N,) float64 remaining battery (capacity units)
    agent_tank: np.ndarray  # (N,) int remaining dumps
    agent_mode: np.ndarray  # (N,) int8 fcplan.team.Mode values
    routes: Sequence[np.ndarray] = ()  # N arrays (k, 2) float64: goals still ahead (may be empty)
    scores: Mapping[str, float] = field(default_factory=dict)  # online scores for the panel
    selected: int | None = None  # row of the highlighted agent


def snapshot(world, belief=None, routes=None, scores=None) -> FrameData:
    """Copy the drawable state of a live world into a :class:`FrameData`.

    Parameters
    ----------
    world : fcplan.world.World
    belief : fcplan.belief.Belief, optional
        Supplies the known burning cells; without it, the world's sensed and still burning cells.
    routes : sequence of (k, 2) arrays, optional
        Goals per agent; by default the goals each agent has still ahead (home when it is
        returning).
    scores : mapping of str to float, optional
        Online scores to show in the panel.

    Returns
    -------
    FrameData

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> world = World().reset(load_scenario("practice"), seed=0)
    >>> frame = snapshot(world, scores={"score": 0.0})
    >>> frame.agent_pos.shape == (world.team.n, 2), bool(frame.known.any())
    (True, False)
    """
    team = world.team
    state = world.fire.state
    w = world.world_size
    if belief is not None:
        known = np.zeros(w * w, dtype=bool)
        known[belief.known] = True
        known = known.reshape(w, w)
    else:
        known = world.sensed & (state == _BURNING)
    if routes is None:
        routes = []
        for i in range(team.n):
            if team.mode[i] in (2, 3):  # returning / homing: straight home
                routes.append(team.home[i : i + 1].copy())
            elif team.has_goal[i]:
                r = team.routes[i]
                k = int(team.goal_index[i])
                ahead = r[k:]
                if team.patrol[i] and k > 0:
                    ahead = np.concatenate([ahead, r[:k]])
                routes.append(np.array(ahead, dtype=np.float64).reshape(-1, 2))
            else:
                routes.append(np.zeros((0, 2)))
    else:
        routes = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in routes]
    return FrameData(
        tick=int(world.tick),
        time_s=float(world.time_s),
        fire=state.copy(),
        known=known,
        pruned=state == _PRUNED,
        agent_pos=team.pos.copy(),
        agent_z=team.z.copy(),
        agent_can_sense=team.can_sense.copy(),
        agent_can_act=team.can_act.copy(),
        agent_battery=team.battery.copy(),
        agent_tank=np.asarray(team.tank).copy(),
        agent_mode=np.asarray(team.mode).copy(),
        routes=tuple(routes),
        scores=dict(scores or {}),
    )


# ---------------------------------------------------------------------------------------- font
# 5x7 glyphs, one string of 7 rows per character ("#" = ink). Lower case is drawn as upper case.
_GLYPHS = {
    " ": ".....|.....|.....|.....|.....|.....|.....",
    "0": ".###.|#...#|#..##|#.#.#|##..#|#...#|.###.",
    "1": "..#..|.##..|..#..|..#..|..#..|..#..|.###.",
    "2": ".###.|#...#|....#|...#.|..#..|.#...|#####",
    "3": "#####|...#.|..#..|...#.|....#|#...#|.###.",
    "4": "...#.|..##.|.#.#.|#..#.|#####|...#.|...#.",
    "5": "#####|#....|####.|....#|....#|#...#|.###.",
    "6": "..##.|.#...|#....|####.|#...#|#...#|.###.",
    "7": "#####|....#|...#.|..#..|.#...|.#...|.#...",
    "8": ".###.|#...#|#...#|.###.|#...#|#...#|.###.",
    "9": ".###.|#...#|#...#|.####|....#|...#.|.##..",
    "A": ".###.|#...#|#...#|#####|#...#|#...#|#...#",
    "B": "####.|#...#|#...#|####.|#...#|#...#|####.",
    "C": ".###.|#...#|#....|#....|#....|#...#|.###.",
    "D": "###..|#..#.|#...#|#...#|#...#|#..#.|###..",
    "E": "#####|#....|#....|####.|#....|#....|#####",
    "F": "#####|#....|#....|####.|#....|#....|#....",
    "G": ".###.|#...#|#....|#.###|#...#|#...#|.####",
    "H": "#...#|#...#|#...#|#####|#...#|#...#|#...#",
    "I": ".###.|..#..|..#..|..#..|..#..|..#..|.###.",
    "J": "..###|...#.|...#.|...#.|...#.|#..#.|.##..",
    "K": "#...#|#..#.|#.#..|##...|#.#..|#..#.|#...#",
    "L": "#....|#....|#....|#....|#....|#....|#####",
    "M": "#...#|##.##|#.#.#|#.#.#|#...#|#...#|#...#",
    "N": "#...#|#...#|##..#|#.#.#|#..##|#...#|#...#",
    "O": ".###.|#...#|#...#|#...#|#...#|#...#|.###.",
    "P": "####.|#...#|#...#|####.|#....|#....|#....",
    "Q": ".###.|#...#|#...#|#...#|#.#.#|#..#.|.##.#",
    "R": "####.|#...#|#...#|####.|#.#..|#..#.|#...#",
    "S": ".####|#....|#....|.###.|....#|....#|####.",
    "T": "#####|..#..|..#..|..#..|..#..|..#..|..#..",
    "U": "#...#|#...#|#...#|#...#|#...#|#...#|.###.",
    "V": "#...#|#...#|#...#|#...#|#...#|.#.#.|..#..",
    "W": "#...#|#...#|#...#|#.#.#|#.#.#|#.#.#|.#.#.",
    "X": "#...#|#...#|.#.#.|..#..|.#.#.|#...#|#...#",
    "Y": "#...#|#...#|.#.#.|..#..|..#..|..#..|..#..",
    "Z": "#####|....#|...#.|..#..|.#...|#....|#####",
    ".": ".....|.....|.....|.....|.....|.##..|.##..",
    ",": ".....|.....|.....|.....|.##..|..#..|.#...",
    ":": ".....|.##..|.##..|.....|.##..|.##..|.....",
    ";": ".....|.##..|.##..|.....|.##..|..#..|.#...",
    "-": ".....|.....|.....|#####|.....|.....|.....",
    "+": ".....|..#..|..#..|#####|..#..|..#..|.....",
    "=": ".....|.....|#####|.....|#####|.....|.....",
    "_": ".....|.....|.....|.....|.....|.....|#####",
    "/": ".....|....#|...#.|..#..|.#...|#....|.....",
    "%": "##...|##..#|...#.|..#..|.#...|#..##|...##",
    "(": "...#.|..#..|.#...|.#...|.#...|..#..|...#.",
    ")": ".#...|..#..|...#.|...#.|...#.|..#..|.#...",
    "[": ".###.|.#...|.#...|.#...|.#...|.#...|.###.",
    "]": ".###.|...#.|...#.|...#.|...#.|...#.|.###.",
    "<": "...#.|..#..|.#...|#....|.#...|..#..|...#.",
    ">": ".#...|..#..|...#.|....#|...#.|..#..|.#...",
    "!": "..#..|..#..|..#..|..#..|..#..|.....|..#..",
    "?": ".###.|#...#|....#|...#.|..#..|.....|..#..",
    "*": ".....|..#..|#.#.#|.###.|#.#.#|..#..|.....",
    "'": "..#..|..#..|.#...|.....|.....|.....|.....",
    "|": "..#..|..#..|..#..|..#..|..#..|..#..|..#..",
    "#": ".#.#.|#####|.#.#.|.#.#.|.#.#.|#####|.#.#.",
}
_FONT_CHARS = "".join(_GLYPHS)
_FONT = np.array(
    [[[c == "#" for c in row] for row in _GLYPHS[ch].split("|")] for ch in _FONT_CHARS],
    dtype=bool,
)  # (n_glyphs, 7, 5)
_FONT_INDEX = {ch: i for i, ch in enumerate(_FONT_CHARS)}
_UNKNOWN = _FONT_INDEX["?"]
GLYPH_W, GLYPH_H = 6, 8  # advance per character and per line at scale 1 (5x7 ink + 1 px gap)


def text_size(text: str, scale: int = 1) -> tuple[int, int]:
    """(width, height) in px of ``text`` drawn by :func:`draw_text` (one line).

    Examples
    --------
    >>> text_size("P1 100%", scale=2)
    (82, 14)
    """
    n = len(text)
    return (max(n * GLYPH_W - 1, 0) * scale, 7 * scale)


@lru_cache(maxsize=4096)
def _text_mask(text: str, scale: int) -> np.ndarray:
    idx = np.array([_FONT_INDEX.get(c, _UNKNOWN) for c in text.upper()], dtype=np.int64)
    glyphs = np.zeros((len(idx), 7, GLYPH_W), dtype=bool)
    glyphs[:, :, :5] = _FONT[idx]
    mask = glyphs.transpose(1, 0, 2).reshape(7, -1)[:, : max(len(idx) * GLYPH_W - 1, 0)]
    if scale > 1:
        mask = mask.repeat(scale, axis=0).repeat(scale, axis=1)
    mask.setflags(write=False)
    return mask


def draw_text(
    img: np.ndarray,
    text: str,
    x: int,
    y: int,
    color: tuple[int, int, int] = COLORS["text"],
    scale: int = 1,
) -> int:
    """Draw one line of ``text`` into ``img`` (H, W, 3) uint8 with its top-left corner at
    column ``x``, row ``y`` (clipped at the edges); return the x just after the text.

    Examples
    --------
    >>> import numpy as np
    >>> img = np.zeros((10, 40, 3), np.uint8)
    >>> draw_text(img, "OK", 1, 1, (255, 255, 255))  # 1 + 11 px of text + 1 px gap
    13
    >>> int(img[..., 0].astype(bool).sum()) > 0
    True
    """
    if not text:
        return x
    mask = _text_mask(text, int(scale))
    _blit_mask(img, mask, int(x), int(y), color)
    return int(x) + mask.shape[1] + scale


def _blit_mask(img, mask, x, y, color, alpha: float = 1.0) -> None:
    """Paint ``color`` where ``mask`` (h, w) is set, top-left at (x, y), clipped to ``img``."""
    h, w = mask.shape
    ih, iw = img.shape[:2]
    r0, c0 = max(y, 0), max(x, 0)
    r1, c1 = min(y + h, ih), min(x + w, iw)
    if r1 <= r0 or c1 <= c0:
        return
    m = mask[r0 - y : r1 - y, c0 - x : c1 - x]
    region = img[r0:r1, c0:c1]
    if alpha >= 1.0:
        region[m] = color
    else:
        col = np.asarray(color, dtype=np.float32)
        region[m] = (region[m] * (1.0 - alpha) + col * alpha).astype(np.uint8)


# ------------------------------------------------------------------------------------ shapes
@lru_cache(maxsize=256)
def _shape_mask(kind: str, r: float) -> tuple[np.ndarray, int]:
    """Boolean mask of a marker of radius ``r`` px centred in a (2R+1) square; return (mask, R)."""
    rr = int(np.ceil(r)) + 1
    d = np.arange(-rr, rr + 1, dtype=np.float64)
    dy, dx = d[:, None], d[None, :]
    if kind == "circle":
        m = dx * dx + dy * dy <= r * r
    elif kind == "diamond":
        m = np.abs(dx) + np.abs(dy) <= r * 1.15
    elif kind == "triangle":  # pointing up
        top, base = -r, 0.75 * r
        half = (dy - top) / (base - top) * r * 1.05
        m = (dy >= top) & (dy <= base) & (np.abs(dx) <= half)
    elif kind == "ring":
        q = dx * dx + dy * dy
        m = (q <= r * r) & (q >= (r - max(1.5, r * 0.22)) ** 2)
    elif kind == "square":
        m = (np.abs(dx) <= r) & (np.abs(dy) <= r)
    else:  # pragma: no cover - internal
        raise ValueError(kind)
    m.setflags(write=False)
    return m, rr


def _stamp(img, kind: str, cx: float, cy: float, r: float, color, outline=None) -> None:
    """Draw a filled marker (with a 1-px dark outline when ``outline`` is given)."""
    if outline is not None:
        m, rr = _shape_mask(kind, r + 1.2)
        _blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, outline)
    m, rr = _shape_mask(kind, r)
    _blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, color)


def _line(img, x0, y0, x1, y1, color, dash: int = 0, alpha: float = 1.0) -> None:
    """A 1-px line from (x0, y0) to (x1, y1) in image px; ``dash`` > 0 draws dash-px dashes."""
    n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
    t = np.linspace(0.0, 1.0, n)
    xs = np.rint(x0 + (x1 - x0) * t).astype(np.int64)
    ys = np.rint(y0 + (y1 - y0) * t).astype(np.int64)
    keep = (xs >= 0) & (xs < img.shape[1]) & (ys >= 0) & (ys < img.shape[0])
    if dash > 0:
        keep &= (np.arange(n) // dash) % 2 == 0
    xs, ys = xs[keep], ys[keep]
    if alpha >= 1.0:
        img[ys, xs] = color
    else:
        col = np.asarray(color, dtype=np.float32)
        img[ys, xs] = (img[ys, xs] * (1.0 - alpha) + col * alpha).astype(np.uint8)


def _rect(img, x0, x1, y0, y1, color, fill_alpha: float = 0.0, edge: bool = True) -> None:
    """Axis-aligned rectangle in image px (inclusive bounds, clipped): edge and optional tint."""
    ih, iw = img.shape[:2]
    c0, c1 = int(np.floor(x0)), int(np.ceil(x1))
    r0, r1 = int(np.floor(y0)), int(np.ceil(y1))
    cc0, cc1, rr0, rr1 = max(c0, 0), min(c1, iw - 1), max(r0, 0), min(r1, ih - 1)
    if cc1 < cc0 or rr1 < rr0:
        return
    col = np.asarray(color, dtype=np.float32)
    if fill_alpha > 0:
        region = img[rr0 : rr1 + 1, cc0 : cc1 + 1]
        region[:] = (region * (1.0 - fill_alpha) + col * fill_alpha).astype(np.uint8)
    if edge:
        if r0 >= 0:
            img[r0, cc0 : cc1 + 1] = color
        if r1 < ih:
            img[r1, cc0 : cc1 + 1] = color
        if c0 >= 0:
            img[rr0 : rr1 + 1, c0] = color
        if c1 < iw:
            img[rr0 : rr1 + 1, c1] = color


# --------------------------------------------------------------------------------- static map
_BG_CACHE: dict[tuple[int, int], tuple[object, np.ndarray]] = {}


def _background(scenario, size: int) -> np.ndarray:
    """The static map (grass, grid, lakes, facilities, depot) at ``size`` px, cached."""
    key = (id(scenario), size)
    hit = _BG_CACHE.get(key)
    if hit is not None and hit[0] is scenario:
        return hit[1]
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
        _rect(img, x0, x1, y0, y1, fill, fill_alpha=0.85, edge=False)
        _rect(img, x0, x1, y0, y1, COLORS["outline"])
        _facility_marker(img, fac.kind, fac.center[0] * s, fac.center[1] * s, r_mark)
    dep = scenario.depot
    x0, x1, y0, y1 = (v * s for v in dep.footprint)
    _rect(img, x0, x1, y0, y1, COLORS["depot"], fill_alpha=0.9, edge=False)
    _rect(img, x0, x1, y0, y1, COLORS["depot_edge"])
    for ax, ay in (a.start for a in scenario.agents):
        _stamp(img, "ring", ax * s, ay * s, max(2.5, 9.0 * s), COLORS["slot"])
    img.setflags(write=False)
    if len(_BG_CACHE) >= 16:
        _BG_CACHE.pop(next(iter(_BG_CACHE)))
    _BG_CACHE[key] = (scenario, img)
    return img


def _facility_marker(img, kind: str, cx: float, cy: float, r: float) -> None:
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
    _blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, color)


# ------------------------------------------------------------------------------------ layers
def _nonzero_flat(cells: np.ndarray) -> np.ndarray:
    """Flat indices of the True cells of a bool grid, fast when few are set: scan 8-byte words
    first, then look inside the non-zero words only."""
    flat = np.ascontiguousarray(cells, dtype=bool).reshape(-1)
    n = flat.size
    if n % 8:
        return np.flatnonzero(flat)
    words = np.flatnonzero(flat.view(np.uint64))
    if words.size == 0:
        return words
    idx = (words[:, None] * 8 + np.arange(8)).reshape(-1)
    return idx[flat[idx]]


def _cell_pixels(cells: np.ndarray, size: int, grow: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Image rows and columns covered by the True cells of a (W, W) ``[x, y]`` grid.

    Each cell covers its ``ceil(size / W)`` px square (at least one pixel when zoomed out), and
    ``grow`` more px to the right and down (keeps 1-px fire trails visible on small images).
    """
    w = cells.shape[0]
    flat = _nonzero_flat(cells)
    if flat.size == 0:
        return flat, flat
    x, y = np.divmod(flat, w)
    k = max(1, -(-size // w)) + grow
    px = (x * size) // w
    py = (y * size) // w
    if k > 1:
        off = np.arange(k)
        px = (px[:, None, None] + off[None, None, :]).repeat(k, axis=1).reshape(-1)
        py = (py[:, None, None] + off[None, :, None]).repeat(k, axis=2).reshape(-1)
        keep = (px < size) & (py < size)
        px, py = px[keep], py[keep]
    return py, px


def _paint_px(img: np.ndarray, py: np.ndarray, px: np.ndarray, color, alpha: float = 1.0) -> None:
    """Paint ``color`` (optionally blended) at the pixels ``(py, px)``."""
    if py.size == 0:
        return
    if alpha >= 1.0:
        img[py, px] = color
    else:
        col = np.asarray(color, dtype=np.float32)
        img[py, px] = (img[py, px] * (1.0 - alpha) + col * alpha).astype(np.uint8)


def _halo(py: np.ndarray, px: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """The pixels one step around ``(py, px)`` (4-neighbourhood), clipped to the image."""
    qy = np.concatenate([py - 1, py + 1, py, py])
    qx = np.concatenate([px, px, px - 1, px + 1])
    keep = (qy >= 0) & (qy < size) & (qx >= 0) & (qx < size)
    return qy[keep], qx[keep]


def _role_of(frame: FrameData, i: int) -> str:
    sense, act = bool(frame.agent_can_sense[i]), bool(frame.agent_can_act[i])
    return "hybrid" if sense and act else ("action" if act else "perception")


_SHAPES = {"perception": "circle", "action": "triangle", "hybrid": "diamond"}


def _check(scenario, frame: FrameData) -> None:
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


def panel_width(size: int) -> int:
    """Width in px of the information panel drawn next to a ``size`` px map.

    Examples
    --------
    >>> panel_width(512)
    252
    """
    scale = _text_scale(size)
    return 40 * GLYPH_W * scale + 12 * scale


def _text_scale(size: int) -> int:
    return max(1, int(size) // 480)


def render_frame(
    scenario,
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
        Append the information panel on the right (:func:`panel_width` px wide).

    Returns
    -------
    ndarray, (size, size [+ panel_width(size)], 3) uint8

    Examples
    --------
    >>> from fcplan import World, load_scenario
    >>> world = World().reset(load_scenario(1), seed=0)
    >>> img = render_frame(world.scenario, snapshot(world), size=200, panel=False)
    >>> img.shape
    (200, 200, 3)
    """
    size = int(size)
    if size < 32:
        raise RenderError(f"render size must be at least 32 px, got {size}")
    _check(scenario, frame)
    s = size / scenario.world_size
    img = _background(scenario, size).copy()
    # fire layers (hidden truth under known, pruned last so it stays visible)
    grow = 1 if s < 0.75 else 0
    if show_truth and frame.fire is not None:
        hidden = (frame.fire == _BURNING) & ~frame.known
        _paint_px(img, *_cell_pixels(hidden, size, grow), COLORS["fire_hidden"], 0.75)
    _paint_px(img, *_cell_pixels(frame.pruned, size, grow), COLORS["pruned"])
    ky, kx = _cell_pixels(frame.known, size, grow)
    _paint_px(img, *_halo(ky, kx, size), COLORS["fire_glow"], 0.5)
    _paint_px(img, ky, kx, COLORS["fire"])
    pos = np.asarray(frame.agent_pos, dtype=np.float64) * s
    z = np.asarray(frame.agent_z, dtype=np.float64)
    n = len(pos)
    roles = [_role_of(frame, i) for i in range(n)]
    # fields of view: half extents z (x) and tan(30 deg) z (y)
    hx, hy = z * s, z * np.tan(np.pi / 6) * s
    for i in range(n):
        col = COLORS[roles[i]]
        x, y = pos[i]
        _rect(img, x - hx[i], x + hx[i], y - hy[i], y + hy[i], col, fill_alpha=0.16)
    # planned routes: dashed line from the agent through its goals, a dot at each goal
    dash = max(2, size // 128)
    for i, route in enumerate(frame.routes[:n]):
        route = np.asarray(route, dtype=np.float64).reshape(-1, 2) * s
        if len(route) == 0:
            continue
        col = COLORS[roles[i]]
        pts = np.vstack([pos[i : i + 1], route])
        for a, b in zip(pts[:-1], pts[1:], strict=True):
            _line(img, a[0], a[1], b[0], b[1], col, dash=dash, alpha=0.9)
        for gx, gy in route:
            _stamp(img, "square", gx, gy, max(1.0, 2.5 * s * 2), col, outline=COLORS["outline"])
    # agents on top
    r_agent = max(3.5, 13.0 * s)
    for i in range(n):
        x, y = pos[i]
        if frame.selected is not None and i == frame.selected:
            _stamp(img, "ring", x, y, r_agent + max(3.0, 6 * s), COLORS["selected"])
        _stamp(img, _SHAPES[roles[i]], x, y, r_agent, COLORS[roles[i]], outline=COLORS["outline"])
    if size >= 256:
        ts = _text_scale(size)
        for i in range(n):
            x, y = pos[i]
            label = scenario.agents[i].id if i < len(scenario.agents) else str(i + 1)
            lx, ly = int(round(x + r_agent + 2)), int(round(y - r_agent - 5 * ts))
            _blit_mask(img, _text_mask(label, ts), lx + 1, ly + 1, COLORS["outline"])
            draw_text(img, label, lx, ly, COLORS["text"], ts)
    if not panel:
        return img
    return np.concatenate([img, _panel(scenario, frame, size, roles, show_truth)], axis=1)


def _fmt(v: float) -> str:
    v = float(v)
    if not np.isfinite(v):
        return "-"
    if abs(v) >= 1000:
        return f"{v:.0f}"
    if abs(v) >= 100:
        return f"{v:.1f}"
    return f"{v:.2f}"


def _panel(scenario, frame: FrameData, size: int, roles, show_truth: bool) -> np.ndarray:
    ts = _text_scale(size)
    pw = panel_width(size)
    p = np.empty((size, pw, 3), dtype=np.uint8)
    p[:] = COLORS["panel"]
    p[:, 0:ts] = COLORS["panel_line"]
    lh = GLYPH_H * ts + 2 * ts  # line height
    x0 = 6 * ts
    y = 6 * ts

    def line(text, color=COLORS["text"], x=x0):
        nonlocal y
        draw_text(p, text, x, y, color, ts)
        y += lh

    def rule():
        nonlocal y
        p[y - ts : y, x0 : pw - x0] = COLORS["panel_line"]
        y += ts * 3

    title = scenario.name if scenario.number is None else f"SCENARIO {scenario.number}"
    line(f"{title}  {scenario.difficulty}", COLORS["accent"])
    line(f"T {frame.time_s:6.1f} / {scenario.duration_s:g} S   TICK {frame.tick}")
    n_known = int(np.count_nonzero(frame.known))
    n_pruned = int(np.count_nonzero(frame.pruned))
    fire_line = f"FIRE KNOWN {n_known}  PRUNED {n_pruned}"
    if show_truth and frame.fire is not None:
        fire_line += f"  TRUE {int(np.count_nonzero(frame.fire == _BURNING))}"
    line(fire_line)
    rule()
    if frame.scores:
        line("SCORES", COLORS["text_dim"])
        for k, v in frame.scores.items():
            key = str(k).upper().replace("_", " ")[:26]
            draw_text(p, key, x0, y, COLORS["text"], ts)
            val = _fmt(v)
            draw_text(p, val, pw - x0 - text_size(val, ts)[0], y, COLORS["text"], ts)
            y += lh
        rule()
    # agent table
    # columns in characters; the id column widens for long ids (P10, H100)
    m = max(4, 2 + max((len(a.id) for a in scenario.agents), default=2))
    cols = {"id": 0, "mode": m, "batt": m + 5, "alt": m + 24, "tank": m + 30}
    cw = GLYPH_W * ts
    for name, c in cols.items():
        label = {"batt": "BATTERY NOW > GOAL"}.get(name, name.upper())
        draw_text(p, label, x0 + c * cw, y, COLORS["text_dim"], ts)
    y += lh
    n = len(roles)
    capacity = np.array([a.battery for a in scenario.agents], dtype=np.float64)[:n]
    batt = np.asarray(frame.agent_battery, dtype=np.float64)
    pct = 100.0 * batt / np.maximum(capacity, 1e-9)
    goal_pct = pct.copy()
    for i, route in enumerate(frame.routes[:n]):
        route = np.asarray(route, dtype=np.float64).reshape(-1, 2)
        if len(route):
            d = float(np.hypot(*(route[0] - frame.agent_pos[i])))
            goal_pct[i] = 100.0 * (batt[i] - DRAIN_PER_PX * d) / max(capacity[i], 1e-9)
    legend_h = 3 * lh + 4 * ts
    rows_fit = max(0, (size - y - legend_h) // lh)
    shown = n if n <= rows_fit else max(rows_fit - 1, 0)
    bar_x = x0 + cols["batt"] * cw
    bar_w = 8 * cw - 2 * ts
    for i in range(shown):
        if frame.selected is not None and i == frame.selected:
            p[y - ts : y + 7 * ts + ts, x0 - 2 * ts : pw - x0 + 2 * ts] = COLORS["panel_line"]
        col = COLORS[roles[i]]
        _stamp(p, _SHAPES[roles[i]], x0 + 2 * ts, y + 3.5 * ts, 3.0 * ts, col)
        aid = scenario.agents[i].id if i < len(scenario.agents) else str(i + 1)
        draw_text(p, aid, x0 + 1 * cw, y, COLORS["text"], ts)
        draw_text(
            p,
            MODE_NAMES.get(int(frame.agent_mode[i]), "?"),
            x0 + cols["mode"] * cw,
            y,
            COLORS["text"],
            ts,
        )
        # battery bar: filled to now, white tick at the goal estimate
        frac = float(np.clip(pct[i] / 100.0, 0, 1))
        p[y : y + 7 * ts, bar_x : bar_x + bar_w] = COLORS["bar_bg"]
        fill = int(round(frac * bar_w))
        bar_col = COLORS["bar_ok"] if pct[i] >= 25 else COLORS["bar_low"]
        p[y : y + 7 * ts, bar_x : bar_x + fill] = bar_col
        g = int(round(float(np.clip(goal_pct[i] / 100.0, 0, 1)) * (bar_w - 1)))
        if goal_pct[i] != pct[i]:
            p[y - ts : y + 8 * ts, bar_x + g : bar_x + g + ts] = COLORS["bar_goal"]
        txt = f"{pct[i]:3.0f}>{goal_pct[i]:3.0f}"
        draw_text(p, txt, bar_x + bar_w + 2 * ts, y, COLORS["text"], ts)
        draw_text(p, f"{frame.agent_z[i]:3.0f}", x0 + cols["alt"] * cw, y, COLORS["text"], ts)
        tank = f"{int(frame.agent_tank[i])}" if frame.agent_can_act[i] else "-"
        draw_text(p, tank, x0 + cols["tank"] * cw, y, COLORS["text"], ts)
        y += lh
    if shown < n:
        line(f"+{n - shown} MORE AGENTS", COLORS["text_dim"])
    # legend at the bottom
    y = size - legend_h + ts
    p[y - 2 * ts : y - ts, x0 : pw - x0] = COLORS["panel_line"]
    sw = 5 * ts
    items = [("fire", "KNOWN FIRE"), ("pruned", "PRUNED")]
    if show_truth:
        items.append(("fire_hidden", "UNSEEN"))
    x = x0
    for key, label in items:
        p[y + ts : y + 6 * ts, x : x + sw] = COLORS[key]
        x = draw_text(p, label, x + sw + 2 * ts, y, COLORS["text"], ts) + 3 * ts
    y += lh
    x = x0
    for role in _ROLE_KEYS:
        _stamp(p, _SHAPES[role], x + 3 * ts, y + 3.5 * ts, 3.0 * ts, COLORS[role])
        x = draw_text(p, role.upper(), x + 8 * ts, y, COLORS["text"], ts) + 3 * ts
    y += lh
    draw_text(p, "BOX = FIELD OF VIEW  - - = ROUTE", x0, y, COLORS["text_dim"], ts)
    return p
