"""Anti-aliased text on numpy images with the bundled DejaVu Sans, and label placement.

Text is rasterised by Pillow (``ImageFont.truetype`` on the TTF files shipped in
``fcplan/render/fonts/``, DejaVu Sans 2.37 under the Bitstream Vera licence) into an 8-bit coverage
mask, then alpha-blended into an ``(H, W, 3)`` uint8 image:

.. math:: I \\leftarrow I + (c - I)\\,\\frac{a}{255},

with ``a`` the coverage of each pixel and ``c`` the text colour. Masks are memoised by value
(``(text, px, bold)``: a pure function of its arguments), so a video re-rasterises only what
changes (times, scores). Pillow is imported when the first mask is made, never by ``import fcplan``.

Every box has the height of the font's line (ascent + descent, :func:`line_height`), whatever
the text, so lines align and a label box always covers its ink. :func:`place_labels` puts labels
next to points (agents) greedily: each label takes the first of 24 candidate offsets around its
point (right, left, above, below, the diagonals; on three rings) whose box meets no box already
placed and no other point's marker; when none is free, the one that overlaps least (other labels
weigh 1000 times more than markers). Boxes are shifted inside the image.

Examples
--------
>>> import numpy as np
>>> img = np.zeros((20, 60, 3), np.uint8)
>>> end = draw_text(img, "P1 ok", 2, 2, (255, 255, 255), px=11)
>>> end > 2, int(img.max()) == 255, text_size("P1 ok", 11)[1] == line_height(11)
(True, True, True)
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.render.raster import clip_box

__all__ = [
    "FONT_FILES",
    "blit_alpha",
    "draw_text",
    "line_height",
    "place_labels",
    "text_mask",
    "text_size",
]

Color = tuple[int, int, int]
Box = tuple[int, int, int, int]  # x0, y0, x1, y1 (exclusive)

_FONT_DIR = Path(__file__).with_name("fonts")
#: The bundled TTF files: regular and bold DejaVu Sans.
FONT_FILES = {False: _FONT_DIR / "DejaVuSans.ttf", True: _FONT_DIR / "DejaVuSans-Bold.ttf"}


@lru_cache(maxsize=64)
def _font(px: int, bold: bool) -> Any:
    """The Pillow font of ``px`` pixels (em size)."""
    from PIL import ImageFont  # lazy: keep `import fcplan` and `import fcplan.render` light

    return ImageFont.truetype(str(FONT_FILES[bool(bold)]), int(px))


def line_height(px: int, bold: bool = False) -> int:
    """Height in px of one line of text at ``px`` (the font's ascent + descent)."""
    ascent, descent = _font(int(px), bool(bold)).getmetrics()
    return int(ascent + descent)


@lru_cache(maxsize=8192)
def text_mask(text: str, px: int, bold: bool = False) -> np.ndarray:
    """The read-only uint8 coverage mask ``(line_height(px), advance)`` of one line of text."""
    from PIL import Image, ImageDraw

    font = _font(int(px), bool(bold))
    width = int(np.ceil(font.getlength(text))) + 1 if text else 0
    canvas = Image.new("L", (max(width, 1), line_height(px, bold)), 0)
    if text:
        ImageDraw.Draw(canvas).text((0, 0), text, fill=255, font=font)
    mask = np.asarray(canvas, dtype=np.uint8)[:, :width].copy()
    mask.setflags(write=False)
    return mask


def text_size(text: str, px: int, bold: bool = False) -> tuple[int, int]:
    """(width, height) in px of the box :func:`draw_text` fills with ``text`` (one line).

    Examples
    --------
    >>> w, h = text_size("A1", 11)
    >>> 10 < w < 20, h == line_height(11)
    (True, True)
    """
    mask = text_mask(text, int(px), bool(bold))
    return int(mask.shape[1]), int(mask.shape[0])


def blit_alpha(img: np.ndarray, alpha: np.ndarray, x: int, y: int, color: Color) -> None:
    """Blend ``color`` into ``img`` with the uint8 coverage ``alpha`` (h, w), top-left (x, y),
    clipped to the image."""
    box = clip_box(img, x, y, *alpha.shape)
    if box is None:
        return
    r0, r1, c0, c1 = box
    a = alpha[r0 - y : r1 - y, c0 - x : c1 - x, None].astype(np.uint16)
    region = img[r0:r1, c0:c1]
    old = region.astype(np.uint16)
    col = np.asarray(color, dtype=np.uint16)
    # integer blend, rounded: (old (255 - a) + c a + 127) // 255
    region[:] = ((old * (255 - a) + col * a + 127) // 255).astype(np.uint8)


def draw_text(
    img: np.ndarray,
    text: str,
    x: int,
    y: int,
    color: Color,
    px: int = 11,
    bold: bool = False,
    shadow: Color | None = None,
) -> int:
    """Draw one line of ``text`` (anti-aliased DejaVu Sans of ``px`` pixels) into ``img``
    (H, W, 3) uint8 with its box's top-left corner at column ``x``, row ``y`` (clipped at the
    edges); return the x just after the text. ``shadow`` draws a 1-px dark offset copy first
    (labels on the map).

    Examples
    --------
    >>> import numpy as np
    >>> img = np.zeros((16, 40, 3), np.uint8)
    >>> draw_text(img, "OK", 1, 1, (255, 255, 255), px=11) == 1 + text_size("OK", 11)[0]
    True
    """
    if not text:
        return int(x)
    mask = text_mask(text, int(px), bool(bold))
    if shadow is not None:
        blit_alpha(img, mask, int(x) + 1, int(y) + 1, shadow)
    blit_alpha(img, mask, int(x), int(y), color)
    return int(x) + int(mask.shape[1])


def _overlap(a: Box, b: Box) -> int:
    """Area of the intersection of two boxes (0 when they do not meet)."""
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    return max(w, 0) * max(h, 0)


def place_labels(
    points: np.ndarray,
    sizes: Sequence[tuple[int, int]],
    radius: float,
    bounds: tuple[int, int],
    gap: int = 2,
) -> list[Box]:
    """Boxes for labels of ``sizes`` (w, h) next to ``points`` (n, 2) image px, greedily.

    Labels are placed in order. Each tries eight offsets around its point, at ``radius + gap``
    from it: right, left, above, below, then the four diagonals (then the same eight one and two
    label heights further out); every candidate box is shifted inside ``bounds`` (width,
    height). It takes the first that meets neither a box placed before nor the square ``radius``
    around another point; when every candidate collides, the one of least overlap, counting an
    overlap with a label 1000 times an overlap with a marker. So every label is drawn, inside
    the image, and labels meet only when the 24 candidates are all taken.

    Returns
    -------
    list of (x0, y0, x1, y1)
        One box per label, ``x1``/``y1`` exclusive.

    Examples
    --------
    >>> pts = np.array([[50.0, 50.0], [60.0, 50.0]])
    >>> a, b = place_labels(pts, [(14, 13), (14, 13)], radius=4, bounds=(200, 200))
    >>> _overlap(a, b)
    0
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    bw, bh = int(bounds[0]), int(bounds[1])
    d = float(radius) + gap
    markers = [
        (int(np.floor(x - radius)), int(np.floor(y - radius)), int(np.ceil(x + radius)) + 1,
         int(np.ceil(y + radius)) + 1)
        for x, y in pts
    ]  # fmt: skip
    placed: list[Box] = []
    for i, ((x, y), (w, h)) in enumerate(zip(pts, sizes, strict=True)):
        cands = []
        for r in (d, d + h + gap, d + 2 * (h + gap)):  # rings further out when crowded
            cands += [
                (x + r, y - h / 2),  # right
                (x - r - w, y - h / 2),  # left
                (x - w / 2, y - r - h),  # above
                (x - w / 2, y + r),  # below
                (x + r * 0.7, y - r * 0.7 - h),  # above right
                (x - r * 0.7 - w, y - r * 0.7 - h),  # above left
                (x + r * 0.7, y + r * 0.7),  # below right
                (x - r * 0.7 - w, y + r * 0.7),  # below left
            ]
        others = [m for j, m in enumerate(markers) if j != i]
        best: Box | None = None
        best_cost = -1
        for cx, cy in cands:
            x0 = min(max(int(round(cx)), 0), max(bw - w, 0))
            y0 = min(max(int(round(cy)), 0), max(bh - h, 0))
            box = (x0, y0, x0 + w, y0 + h)
            # label-label overlap is what makes text unreadable: it dominates the cost
            cost = sum(_overlap(box, o) for o in placed) * 1000 + sum(
                _overlap(box, o) for o in others
            )
            if best is None or cost < best_cost:
                best, best_cost = box, cost
            if cost == 0:
                break
        assert best is not None
        placed.append(best)
    return placed
