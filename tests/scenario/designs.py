"""A small valid open-world design shared by the scenario tests, and helpers to load variants."""

from __future__ import annotations

from pathlib import Path

import pytest

from fcplan.scenario import ScenarioError, load_scenario

#: 800 px, one region, one house, 1 perception + 2 action agents
BASE = """\
name = "small"
world_size = 800
duration_s = 120

[fire]
mode = "specific"

[[fire.regions]]
cell = "E-02"
fronts = 4
fuel = 8
wind_speed = 5
wind_dir_deg = 90

[depot]
cell = "A-01"
orientation = "vertical"

[[facilities]]
kind = "house"
cell = "F-05"

[team.perception]
count = 1

[team.action]
count = 2
"""


def write(tmp_path: Path, text: str, name: str = "design.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def edit(old: str, new: str) -> str:
    """BASE with ``old`` replaced by ``new`` (``old`` must occur)."""
    assert old in BASE, old
    return BASE.replace(old, new)


def load_error(tmp_path: Path, text: str) -> str:
    """The one-line message of the ScenarioError that loading ``text`` raises."""
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    msg = str(info.value)
    assert "\n" not in msg, msg
    assert msg.startswith(f"{path}: "), msg
    return msg
