"""``cmplx1_v0``: the reference preset ``cmplx1`` as a versioned PettingZoo module.

:class:`raw_env` is :class:`fcplan.env.presets.Cmplx1Env` (the documentation page:
:mod:`fcplan.env.presets.cmplx`) with ``metadata["name"] = "cmplx1_v0"``;
``parallel_env(**kwargs)`` and ``env(**kwargs)`` (AEC) take its keyword arguments plus
``obs_layout``, ``pad_actions`` and ``render_mode="human"`` (:mod:`fcplan.env.versions`).

Examples
--------
>>> from fcplan.env import cmplx1_v0
>>> env = cmplx1_v0.parallel_env(max_steps=4)
>>> env.metadata["name"], env.possible_agents[0]
('cmplx1_v0', 'perception_0')
"""

from __future__ import annotations

from fcplan.env.presets import Cmplx1Env
from fcplan.env.versions import versioned

__all__ = ["env", "parallel_env", "raw_env"]


class raw_env(Cmplx1Env):  # noqa: N801 (PettingZoo's name for the env class)
    """:class:`fcplan.env.presets.Cmplx1Env`, named ``cmplx1_v0``."""

    metadata = {**Cmplx1Env.metadata, "name": "cmplx1_v0"}


env, parallel_env = versioned(raw_env)
