"""Tests of fcplan.render.text: anti-aliased DejaVu Sans text and the greedy label placement."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.render import place_labels, render_frame, snapshot, text_size
from fcplan.render.raster import font_px
from fcplan.render.text import FONT_FILES, draw_text, line_height, text_mask


def _overlap(a, b) -> bool:
    return min(a[2], b[2]) > max(a[0], b[0]) and min(a[3], b[3]) > max(a[1], b[1])


def test_the_fonts_and_their_licence_ship_with_the_package():
    """Both TTF files and the licence are package files (fcplan/render/fonts/)."""
    for path in FONT_FILES.values():
        assert path.is_file() and path.stat().st_size > 100_000
    assert (FONT_FILES[False].parent / "LICENSE.txt").read_text().count("Bitstream") > 1


def test_text_is_anti_aliased():
    """Glyph edges carry intermediate coverage (grey levels), not only ink and paper."""
    mask = text_mask("Scenario 24", 11)
    levels = np.unique(mask)
    assert levels[0] == 0 and levels[-1] >= 250
    assert ((levels > 0) & (levels < 250)).sum() > 10


def test_boxes_have_the_line_height_and_grow_with_the_font():
    """Every box is one line high whatever the text; a larger font gives a larger box."""
    assert text_size("ag", 11)[1] == text_size("AA", 11)[1] == line_height(11)
    assert text_size("P1", 22)[0] > text_size("P1", 11)[0]
    assert text_size("", 11) == (0, line_height(11))


@settings(max_examples=40, deadline=None)
@given(
    st.text(alphabet=st.characters(min_codepoint=32, max_codepoint=126), max_size=20),
    st.sampled_from([9, 11, 22]),
)
def test_text_fits_its_size(text, px):
    """draw_text inks only inside the box text_size reports, and returns the x after it."""
    w, h = text_size(text, px)
    img = np.zeros((h + 10, w + 10, 3), np.uint8)
    end = draw_text(img, text, 5, 5, (255, 255, 255), px)
    ink = img[..., 0] > 0
    outside = ink.copy()
    outside[5 : 5 + h, 5 : 5 + w] = False
    assert not outside.any()
    assert end == 5 + w


def test_text_is_blended_over_the_background():
    """Full coverage gives the text colour; partial coverage a mix of text and background."""
    img = np.full((20, 60, 3), 100, np.uint8)
    draw_text(img, "HIH", 2, 2, (200, 0, 0), 16)
    red = img[..., 0].astype(int)
    assert red.max() == 200 and ((red > 100) & (red < 200)).any()
    assert img[..., 1].min() < 100  # green goes towards 0 under the ink


def test_crowded_labels_do_not_intersect():
    """On a crowded frame (scenario 17's eight agents bunched at the depot at t = 0) no two
    label boxes intersect, and every box is inside the map."""
    world = World().reset(load_scenario(17), seed=0)
    size = 512
    s = size / world.world_size
    pos = world.team.pos * s
    labels = [a.id for a in world.scenario.agents]
    sizes = [text_size(t, font_px(size), bold=True) for t in labels]
    boxes = place_labels(pos, sizes, radius=max(3.5, 13.0 * s) + 1, bounds=(size, size))
    for i, a in enumerate(boxes):
        assert a[0] >= 0 and a[2] <= size and a[1] >= 0 and a[3] <= size
        for b in boxes[:i]:
            assert not _overlap(a, b), (a, b)
    img = render_frame(world.scenario, snapshot(world), size=size, panel=False)
    assert img.shape == (size, size, 3)


def test_labels_of_agents_on_one_spot_do_not_intersect():
    """Five agents at exactly the same point still get five disjoint label boxes."""
    pts = np.full((5, 2), 100.0)
    boxes = place_labels(pts, [(16, 13)] * 5, radius=5.0, bounds=(256, 256))
    for i, a in enumerate(boxes):
        for b in boxes[:i]:
            assert not _overlap(a, b)


@pytest.mark.parametrize("corner", [(0.0, 0.0), (255.0, 255.0), (0.0, 255.0)])
def test_labels_stay_inside_the_image(corner):
    """A label of an agent in a corner is moved inside the image."""
    (box,) = place_labels(np.array([corner]), [(20, 13)], radius=4.0, bounds=(256, 256))
    assert box[0] >= 0 and box[1] >= 0 and box[2] <= 256 and box[3] <= 256
