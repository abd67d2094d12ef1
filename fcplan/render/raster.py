"""Pixel drawing on numpy RGB images: the palette, markers, lines, boxes and cell grids.

Every function paints into an ``(H, W, 3)`` uint8 image in place and clips at its edges;
coordinates are image pixels (column ``x``, row ``y``). :data:`COLORS` names every colour a frame
uses (change an entry to restyle every frame); text is drawn by :mod:`fcplan.render.text`
(anti-aliased DejaVu Sans, :func:`font_px` px per map size). Marker masks are memoised by value
(they are pure functions of their arguments), and cell grids are painted in one numpy operation per layer (:func:`cell_pixels`, :func:`paint_px`).

Examples
--------
>>> import numpy as np
>>> img = np.zeros((20, 20, 3), np.uint8)
>>> stamp(img, "circle", 10, 10, 4.0, COLORS["perception"])
>>> tuple(img[10, 10]) == COLORS["perception"], int(img[0, 0].max())
(True, 0)
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = [
    "COLORS",
    "ROLE_SHAPES",
    "blit_mask",
    "cell_pixels",
    "clip_box",
    "font_px",
    "halo",
    "line",
    "paint_px",
    "rect",
    "shape_mask",
    "stamp",
    "text_scale",
]

Color = tuple[int, int, int]

#: Marker shape of each agent role (in the map and in the panel).
ROLE_SHAPES = {"perception": "circle", "action": "triangle", "hybrid": "diamond"}

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


def text_scale(size: int) -> int:
    """Text scale of the labels and panel of a ``size`` px map (1 below 960 px, then 2, ...)."""
    return max(1, int(size) // 480)


def font_px(size: int) -> int:
    """Font size in px (DejaVu Sans em) of the labels and panel of a ``size`` px map."""
    return 11 * text_scale(size)


def clip_box(img: np.ndarray, x: int, y: int, h: int, w: int) -> tuple[int, int, int, int] | None:
    """Rows ``r0:r1`` and columns ``c0:c1`` of the (h, w) box at (x, y) inside ``img`` as
    ``(r0, r1, c0, c1)``, or None when none of it is."""
    ih, iw = img.shape[:2]
    r0, c0 = max(y, 0), max(x, 0)
    r1, c1 = min(y + h, ih), min(x + w, iw)
    return None if r1 <= r0 or c1 <= c0 else (r0, r1, c0, c1)


def blit_mask(
    img: np.ndarray, mask: np.ndarray, x: int, y: int, color: Color, alpha: float = 1.0
) -> None:
    """Paint ``color`` where ``mask`` (h, w) is set, top-left at (x, y), clipped to ``img``."""
    box = clip_box(img, x, y, *mask.shape)
    if box is None:
        return
    r0, r1, c0, c1 = box
    m = mask[r0 - y : r1 - y, c0 - x : c1 - x]
    region = img[r0:r1, c0:c1]
    if alpha >= 1.0:
        region[m] = color
    else:
        col = np.asarray(color, dtype=np.float32)
        region[m] = (region[m] * (1.0 - alpha) + col * alpha).astype(np.uint8)


@lru_cache(maxsize=256)
def shape_mask(kind: str, r: float) -> tuple[np.ndarray, int]:
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


def stamp(
    img: np.ndarray,
    kind: str,
    cx: float,
    cy: float,
    r: float,
    color: Color,
    outline: Color | None = None,
) -> None:
    """Draw a filled marker (with a 1-px dark outline when ``outline`` is given)."""
    if outline is not None:
        m, rr = shape_mask(kind, r + 1.2)
        blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, outline)
    m, rr = shape_mask(kind, r)
    blit_mask(img, m, int(round(cx)) - rr, int(round(cy)) - rr, color)


def line(
    img: np.ndarray,
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    color: Color,
    dash: int = 0,
    alpha: float = 1.0,
) -> None:
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


def rect(
    img: np.ndarray,
    x0: float,
    x1: float,
    y0: float,
    y1: float,
    color: Color,
    fill_alpha: float = 0.0,
    edge: bool = True,
) -> None:
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


def nonzero_flat(cells: np.ndarray) -> np.ndarray:
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


def cell_pixels(cells: np.ndarray, size: int, grow: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Image rows and columns covered by the True cells of a (W, W) ``[x, y]`` grid.

    Each cell covers its ``ceil(size / W)`` px square (at least one pixel when zoomed out), and
    ``grow`` more px to the right and down (keeps 1-px fire trails visible on small images).
    """
    w = cells.shape[0]
    flat = nonzero_flat(cells)
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


def paint_px(
    img: np.ndarray, py: np.ndarray, px: np.ndarray, color: Color, alpha: float = 1.0
) -> None:
    """Paint ``color`` (optionally blended) at the pixels ``(py, px)``."""
    if py.size == 0:
        return
    if alpha >= 1.0:
        img[py, px] = color
    else:
        col = np.asarray(color, dtype=np.float32)
        img[py, px] = (img[py, px] * (1.0 - alpha) + col * alpha).astype(np.uint8)


def halo(py: np.ndarray, px: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """The pixels one step around ``(py, px)`` (4-neighbourhood), clipped to the image."""
    qy = np.concatenate([py - 1, py + 1, py, py])
    qx = np.concatenate([px, px, px - 1, px + 1])
    keep = (qy >= 0) & (qy < size) & (qx >= 0) & (qx < size)
    return qy[keep], qx[keep]
