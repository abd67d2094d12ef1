"""The ``cmplx1`` / ``cmplx2`` presets under their first import path: see
:mod:`fcplan.env.presets.cmplx`.

Examples
--------
>>> from fcplan.env import presets
>>> CmplxEnv is presets.CmplxEnv
True
"""

from __future__ import annotations

from fcplan.env.presets.cmplx import WIND_DIRECTIONS, CmplxEnv

__all__ = ["CmplxEnv", "WIND_DIRECTIONS"]
