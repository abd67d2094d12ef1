"""``cmplx2_v0``: the reference preset ``cmplx2`` as a versioned PettingZoo module.

:class:`raw_env` is :class:`fcplan.env.presets.Cmplx2Env` (the documentation page:
:mod:`fcplan.env.presets.cmplx`) with ``metadata["name"] = "cmplx2_v0"``;
``parallel_env(**kwargs)`` and ``env(**kwargs)`` (AEC) take its keyword arguments plus
``obs_layout``, ``pad_actions`` and ``render_mode="human"`` (:mod:`fcplan.env.versions`).

Examples
--------
>>> from fcplan.env import cmplx2_v0
>>> env = cmplx2_v0.parallel_env(max_steps=4)
>>> env.metadata["name"], env.possible_agents[0]
('cmplx2_v0', 'perception_0')
"""

from __future__ import annotations

from fcplan.env.presets import Cmplx2Env
from fcplan.env.versions import versioned

__all__ = ["env", "parallel_env", "raw_env"]


class raw_env(Cmplx2Env):  # noqa: N801 (PettingZoo's name for the env class)
    """:class:`fcplan.env.presets.Cmplx2Env`, named ``cmplx2_v0``."""

    metadata = {**Cmplx2Env.metadata, "name": "cmplx2_v0"}


env, parallel_env = versioned(raw_env)
