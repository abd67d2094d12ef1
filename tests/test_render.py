"""Tests of the numpy frame renderer (fcplan.render)."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan import World, load_scenario
from fcplan.render import (
    COLORS,
    FrameData,
    RenderError,
    draw_text,
    panel_width,
    render_frame,
    snapshot,
    text_size,
)
from fcplan.team import Command


@pytest.fixture(scope="module")
def world():
    """Scenario 1 after a few seconds with agents sent out (so routes and FOVs exist)."""
    w = World().reset(load_scenario(1), seed=0)
    cmds = {
        aid: Command(route=((600.0, 600.0), (700.0, 300.0)), altitude=50.0) for aid in w.team.ids
    }
    w.step(cmds)
    for _ in range(40):
        w.step()
    return w


def _blank(world) -> FrameData:
    """A frame of ``world`` with no fire known, pruned or burning."""
    w = world.world_size
    empty = np.zeros((w, w), dtype=bool)
    return dataclasses.replace(
        snapshot(world), fire=np.zeros((w, w), np.uint8), known=empty, pruned=empty.copy()
    )


def _has_color(region: np.ndarray, color) -> bool:
    return bool(np.all(region == np.asarray(color, np.uint8), axis=-1).any())


@pytest.mark.parametrize("size", [64, 256, 512, 1500])
@pytest.mark.parametrize("panel", [True, False])
def test_shape_and_dtype(world, size, panel):
    """A frame is (size, size [+ panel], 3) uint8 at any size, zoomed out or in."""
    img = render_frame(world.scenario, snapshot(world), size=size, panel=panel)
    width = size + (panel_width(size) if panel else 0)
    assert img.shape == (size, width, 3)
    assert img.dtype == np.uint8


def test_fire_layers_drawn_where_cells_are(world):
    """Known fire, pruned cells and (with show_truth) unseen fire show their colours where the
    cells are, and unseen fire is hidden without show_truth."""
    frame = _blank(world)
    fire, known, pruned = frame.fire.copy(), frame.known.copy(), frame.pruned.copy()
    known[300:320, 900:920] = True  # world x 300..319, y 900..919
    fire[300:320, 900:920] = 1
    pruned[900:920, 1000:1020] = True
    fire[900:920, 1000:1020] = 2
    fire[1100:1120, 100:120] = 1  # burning, not known
    frame = dataclasses.replace(frame, fire=fire, known=known, pruned=pruned)
    size, s = 600, 600 / 1200
    img = render_frame(world.scenario, frame, size=size, panel=False)
    assert _has_color(img[int(900 * s) : int(920 * s), int(300 * s) : int(320 * s)], COLORS["fire"])
    assert _has_color(
        img[int(1000 * s) : int(1020 * s), int(900 * s) : int(920 * s)], COLORS["pruned"]
    )
    hidden = (slice(int(100 * s), int(120 * s)), slice(int(1100 * s), int(1120 * s)))
    plain = render_frame(world.scenario, _blank(world), size=size, panel=False)
    assert np.array_equal(img[hidden], plain[hidden])
    truth = render_frame(world.scenario, frame, size=size, panel=False, show_truth=True)
    assert not np.array_equal(truth[hidden], plain[hidden])


def test_single_cell_visible_when_zoomed_out(world):
    """One known burning cell still colours at least one pixel on a small image."""
    frame = _blank(world)
    known = frame.known.copy()
    known[777, 555] = True
    img = render_frame(
        world.scenario, dataclasses.replace(frame, known=known), size=100, panel=False
    )
    assert _has_color(img, COLORS["fire"])


def test_agents_drawn_with_role_colours():
    """Each agent's marker is drawn in its role's colour at its position (hybrids included) and
    the selected agent gets a white ring."""
    sc = load_scenario("open_world_example")
    w = World().reset(sc, seed=0)
    w.step({aid: Command(route=((500.0 + 60 * k, 500.0),)) for k, aid in enumerate(w.team.ids)})
    for _ in range(30):
        w.step()
    frame = dataclasses.replace(snapshot(w), selected=0)
    size = 500
    s = size / sc.world_size
    img = render_frame(sc, frame, size=size, panel=False)
    for i, a in enumerate(sc.agents):
        x, y = (frame.agent_pos[i] * s).round().astype(int)
        color = COLORS[("perception", "action", "hybrid")[int(a.role)]]
        assert _has_color(img[y - 2 : y + 3, x - 2 : x + 3], color), a.id
    x, y = (frame.agent_pos[0] * s).round().astype(int)
    assert _has_color(img[y - 12 : y + 13, x - 12 : x + 13], COLORS["selected"])


def test_deterministic(world):
    """The same inputs give byte-identical frames (the static-map cache changes nothing)."""
    frame = snapshot(world, scores={"score": 12.5})
    a = render_frame(world.scenario, frame, size=300, show_truth=True)
    b = render_frame(world.scenario, frame, size=300, show_truth=True)
    assert np.array_equal(a, b)


def test_panel_lists_scores_and_agents(world):
    """The panel draws text for scores and one row per agent (more ink with more scores)."""
    base = render_frame(world.scenario, snapshot(world), size=512)
    more = render_frame(world.scenario, snapshot(world, scores={"a": 1, "b": 2}), size=512)
    panel = slice(512, None)
    assert (more[:, panel] != base[:, panel]).any()


def test_mismatched_frame_is_refused(world):
    """A frame whose grids or team do not fit the scenario raises RenderError naming the field."""
    frame = snapshot(world)
    small = np.zeros((10, 10), bool)
    with pytest.raises(RenderError, match="known"):
        render_frame(world.scenario, dataclasses.replace(frame, known=small))
    with pytest.raises(RenderError, match="agent_pos"):
        render_frame(world.scenario, dataclasses.replace(frame, agent_pos=np.zeros((1, 2))))


def test_headless_without_gui_libraries():
    """Rendering imports neither pygame nor matplotlib."""
    code = (
        "import sys; from fcplan import World, load_scenario; from fcplan.render import *; "
        "w = World().reset(load_scenario('practice'), seed=0); w.step(); "
        "render_frame(w.scenario, snapshot(w), size=128); "
        "print('pygame' in sys.modules, 'matplotlib' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


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
