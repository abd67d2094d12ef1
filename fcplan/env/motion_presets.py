"""The reference presets' shared parts and maker, under their first import path.

The presets live in :mod:`fcplan.env.presets` (base class and RF1 penalty in
:mod:`fcplan.env.presets.core`); this module exports the same objects.

Examples
--------
>>> from fcplan.env import presets
>>> make_preset is presets.make_preset and PresetEnv is presets.PresetEnv
True
"""

from __future__ import annotations

from fcplan.env.presets import (
    MOVES,
    PresetEnv,
    make_preset,
    rf1_penalty_small,
    rf1_structure_penalty,
)

__all__ = ["make_preset", "rf1_structure_penalty", "rf1_penalty_small", "PresetEnv", "MOVES"]
