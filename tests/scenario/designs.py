"""A small valid open-world design shared by the scenario tests."""

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
