"""``motion_v0``: the motion-level environment as a versioned PettingZoo module.

:class:`raw_env` is :class:`fcplan.env.motion.MotionEnv` (the documentation page: spaces,
reward, termination, seeding) with ``metadata["name"] = "motion_v0"`` and the scenario
``"practice"`` by default; ``parallel_env(**kwargs)`` and ``env(**kwargs)`` (AEC) take its keyword
arguments plus ``obs_layout``, ``pad_actions`` and ``render_mode="human"``
(:mod:`fcplan.env.versions`). The reference presets have their own modules:
:mod:`fcplan.env.base_v0`, :mod:`fcplan.env.cmplx1_v0`, :mod:`fcplan.env.cmplx2_v0`.

Examples
--------
>>> from fcplan.env import motion_v0
>>> env = motion_v0.parallel_env(pad_actions=True)
>>> [int(env.action_space(a).n) for a in env.possible_agents]
[7, 7, 7, 7]
"""

from __future__ import annotations

from typing import Any

from fcplan.env.motion import MotionEnv
from fcplan.env.versions import versioned
from fcplan.mission import ScenarioLike

__all__ = ["env", "parallel_env", "raw_env"]


class raw_env(MotionEnv):  # noqa: N801 (PettingZoo's name for the env class)
    """:class:`fcplan.env.motion.MotionEnv`, named ``motion_v0``, on ``"practice"`` by default."""

    metadata = {**MotionEnv.metadata, "name": "motion_v0"}

    def __init__(self, scenario: ScenarioLike = "practice", **kwargs: Any) -> None:
        super().__init__(scenario, **kwargs)


env, parallel_env = versioned(raw_env)
