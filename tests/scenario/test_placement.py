"""Tests of fcplan.scenario.placement: random placement under the open-world GUI's rules."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from fcplan.scenario.grid import block_cells, parse_cell
from fcplan.scenario.placement import GridLayout, PlacementError, draw_depot


@pytest.mark.parametrize("world", [800, 1200, 3000])
@pytest.mark.parametrize("orientation", ["vertical", "horizontal"])
def test_depots_sit_on_a_map_edge(world, orientation):
    """Depot rule: vertical depots in column A or the second-to-last column, horizontal ones in
    row 1 or the second-to-last row, every block inside the map."""
    n = world // 100
    for seed in range(20):
        d = draw_depot(np.random.default_rng(seed), world, orientation)
        column, row = parse_cell(d.cell)
        cells = block_cells(d.cell, f"depot_{orientation}")
        assert all(c < n and r <= n for c, r in cells)
        if orientation == "vertical":
            assert column in (0, n - 2)
        else:
            assert row in (1, n - 1)


def test_objects_share_no_cell_and_footprints_do_not_overlap():
    """Exclusivity: facilities, lakes and the depot share no grid cell with each other or a
    region, and no two footprints overlap (power stations overhang their block)."""
    for seed in range(10):
        rng = np.random.default_rng(seed)
        lay = GridLayout(1200, draw_depot(rng, 1200))
        lay.place_regions(rng, 3)
        lay.place_facilities(rng, {"power_station": 6, "house": 3}, distance=(0, 2000))
        lay.place_lakes(rng, 1)
        blocks = [block_cells(lay.depot.cell, f"depot_{lay.depot.orientation}")]
        blocks += [block_cells(f.cell, f.kind) for f in lay.facilities]
        blocks += [block_cells(lake.cell, "lake") for lake in lay.lakes]
        regions = {parse_cell(c) for c in lay.region_cells}
        for a, b in itertools.combinations(blocks, 2):
            assert not a & b
        assert all(not b & regions for b in blocks)
        boxes = [lay.depot.footprint] + [f.footprint for f in lay.facilities]
        for a, b in itertools.combinations(boxes, 2):
            assert not (a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3])


def test_facility_distance_and_regions_far_threshold():
    """Distance rules: facilities lie lo..hi from the nearest region; late regions lie beyond
    far_px, which is far_fraction of the largest depot-to-cell distance."""
    rng = np.random.default_rng(3)
    lay = GridLayout(1000, draw_depot(rng, 1000, "vertical"))
    lay.place_regions(rng, 4, n_late=2, far_fraction=0.6)
    lay.place_facilities(rng, {"house": 3}, distance=(150, 300))
    centres = [((c + 0.5) * 100, (r - 0.5) * 100) for c, r in map(parse_cell, lay.region_cells)]
    for f in lay.facilities:
        assert 150 <= min(math.dist(f.center, p) for p in centres) <= 300
    assert all(math.dist(lay.depot.center, p) >= lay.far_px for p in centres[2:])


def test_no_room_raises_placement_error_naming_the_knob():
    """Exhaustion: when no block satisfies the rule, PlacementError names the setting."""
    rng = np.random.default_rng(0)
    lay = GridLayout(800, draw_depot(rng, 800))
    lay.place_regions(rng, 1)
    with pytest.raises(PlacementError) as info:
        lay.place_facilities(rng, {"hospital": 20})
    assert info.value.knob == "n_hospitals"
    with pytest.raises(PlacementError, match="^n_lakes: no free 3 x 4 block"):
        lay.place_lakes(rng, 10)
