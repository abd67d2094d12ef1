"""The reference MARL package's three environments as seeded, standard PettingZoo envs.

FIRECOMMANDER.md section 6 describes the 2020 MARL package: ``FireCommanderEasy`` (here
``base``: a 10 x 10 grid with static fire, :mod:`fcplan.env.presets.base`), ``FireCommanderHard``
and ``FireCommanderExtreme`` (here ``cmplx1`` and ``cmplx2``: a 100 x 100 grid with FARSITE fire,
:mod:`fcplan.env.presets.cmplx`). The presets keep their grids, teams, start positions, action and
observation meanings, reward functions RF1-RF3 with their parameters and done rules, and add
what the originals lacked: ``reset(seed=...)``, spaces, ``state()``, ``render()``, determinism,
and no crashes. Every deviation is listed in the env's module docstring.

Modules: :mod:`~fcplan.env.presets.core` (the base class :class:`PresetEnv`, which knows no
concrete preset, and the RF1 penalty), then one module per preset: :mod:`~fcplan.env.presets.base`,
:mod:`~fcplan.env.presets.cmplx1` and :mod:`~fcplan.env.presets.cmplx2` (both variants of
:mod:`~fcplan.env.presets.cmplx`). :data:`PRESETS` maps each name to its class;
:func:`make_preset` makes one (``fcplan.env.motion.parallel_env(preset=...)`` calls it).

Examples
--------
>>> env = make_preset("base")
>>> obs, infos = env.reset(seed=0)
>>> env.agents
['perception_0', 'perception_1', 'action_0', 'action_1']
>>> sorted(PRESETS)
['base', 'cmplx1', 'cmplx2']
"""

from __future__ import annotations

from typing import Any

from fcplan.env.presets.base import STATIONARY_FIRE, BaseEnv
from fcplan.env.presets.cmplx import WIND_DIRECTIONS, CmplxEnv
from fcplan.env.presets.cmplx1 import Cmplx1Env
from fcplan.env.presets.cmplx2 import Cmplx2Env
from fcplan.env.presets.core import MOVES, PresetEnv, rf1_penalty_small, rf1_structure_penalty
from fcplan.errors import EnvError

__all__ = [
    "PRESETS",
    "make_preset",
    "PresetEnv",
    "BaseEnv",
    "CmplxEnv",
    "Cmplx1Env",
    "Cmplx2Env",
    "MOVES",
    "STATIONARY_FIRE",
    "WIND_DIRECTIONS",
    "rf1_structure_penalty",
    "rf1_penalty_small",
]

#: Preset name -> environment class (constructed with the preset's keyword arguments).
PRESETS: dict[str, type[PresetEnv]] = {
    "base": BaseEnv,
    "cmplx1": Cmplx1Env,
    "cmplx2": Cmplx2Env,
}


def make_preset(name: str, **kwargs: Any) -> PresetEnv:
    """Make the preset ``"base"``, ``"cmplx1"`` or ``"cmplx2"`` with its keyword arguments.

    Raises
    ------
    EnvError
        For an unknown name.
    """
    if name not in PRESETS:
        raise EnvError(f"preset: must be one of {', '.join(PRESETS)} (got {name!r})")
    return PRESETS[name](**kwargs)
