"""Tests of fcplan.render.raster: the markers."""

from __future__ import annotations

import numpy as np

from fcplan.render.raster import COLORS, stamp


def test_markers_are_clipped_at_the_image_edges():
    """A marker stamped partly outside the image paints only the pixels inside it."""
    img = np.zeros((10, 10, 3), np.uint8)
    stamp(img, "diamond", -2, 5, 6.0, COLORS["hybrid"], outline=COLORS["outline"])
    stamp(img, "ring", 12, 12, 5.0, COLORS["selected"])
    assert np.all(img[5, 0] == COLORS["hybrid"])
    assert np.all(img[9, 9] == COLORS["selected"]) or np.all(img[9, 8] == COLORS["selected"])
