"""Tests of fcplan.render.renderer: whole frames, drawn by a Renderer or render_frame."""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from fcplan import World, load_scenario
from fcplan.render import (
    COLORS,
    FrameData,
    Renderer,
    RenderError,
    panel_width,
    render_frame,
    snapshot,
)
from fcplan.team import Command


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


def test_renderer_holds_the_static_map_and_matches_render_frame(world):
    """A Renderer draws its read-only static map once; its frames equal render_frame's, with and
    without panel, for every frame it is given."""
    renderer = Renderer(world.scenario, 300)
    assert renderer.background.shape == (300, 300, 3) and not renderer.background.flags.writeable
    background = renderer.background
    for frame in (snapshot(world), _blank(world)):
        for panel in (True, False):
            got = renderer.render(frame, panel=panel, show_truth=True)
            want = render_frame(world.scenario, frame, size=300, panel=panel, show_truth=True)
            assert np.array_equal(got, want)
    assert renderer.background is background


def test_render_frame_reuses_a_renderer_for_equal_scenarios(world):
    """render_frame shares one renderer between equal scenarios (the static map depends only on
    the scenario's values and the size), and a different size gets its own."""
    from fcplan.render import renderer as renderer_mod

    copy = dataclasses.replace(world.scenario)
    assert copy == world.scenario and copy is not world.scenario
    assert renderer_mod._shared(world.scenario, 256) is renderer_mod._shared(copy, 256)
    assert renderer_mod._shared(world.scenario, 257) is not renderer_mod._shared(copy, 256)


def test_too_small_size_is_refused(world):
    """Maps smaller than 32 px are a RenderError, from render_frame and Renderer alike."""
    with pytest.raises(RenderError, match="at least 32"):
        render_frame(world.scenario, snapshot(world), size=31)
    with pytest.raises(RenderError, match="at least 32"):
        Renderer(world.scenario, 16)
