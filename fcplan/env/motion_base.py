"""The ``base`` preset under its first import path: see :mod:`fcplan.env.presets.base`.

Examples
--------
>>> from fcplan.env import presets
>>> BaseEnv is presets.BaseEnv
True
"""

from __future__ import annotations

from fcplan.env.presets.base import STATIONARY_FIRE, BaseEnv

__all__ = ["BaseEnv", "STATIONARY_FIRE"]
