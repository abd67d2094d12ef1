"""Tests of fcplan.render.raster: the bitmap font and the markers."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.render import draw_text, text_size
from fcplan.render.raster import COLORS, stamp


@settings(max_examples=40, deadline=None)
@given(
    st.text(alphabet=st.characters(min_codepoint=32, max_codepoint=126), max_size=20),
    st.integers(1, 3),
)
def test_text_fits_its_size(text, scale):
    """draw_text inks only inside the box text_size reports, and returns the next x."""
    w, h = text_size(text, scale)
    img = np.zeros((h + 10, w + 10, 3), np.uint8)
    end = draw_text(img, text, 5, 5, (255, 255, 255), scale)
    ink = img[..., 0] > 0
    outside = ink.copy()
    outside[5 : 5 + h, 5 : 5 + w] = False
    assert not outside.any()
    assert end == (5 + w + scale if text else 5)


def test_markers_are_clipped_at_the_image_edges():
    """A marker stamped partly outside the image paints only the pixels inside it."""
    img = np.zeros((10, 10, 3), np.uint8)
    stamp(img, "diamond", -2, 5, 6.0, COLORS["hybrid"], outline=COLORS["outline"])
    stamp(img, "ring", 12, 12, 5.0, COLORS["selected"])
    assert np.all(img[5, 0] == COLORS["hybrid"])
    assert np.all(img[9, 9] == COLORS["selected"]) or np.all(img[9, 8] == COLORS["selected"])
