"""Preset ``cmplx2``: the reference ``FireCommanderExtreme`` (action agents prune on a dump).

The rules, spaces and deviations are those of :mod:`fcplan.env.presets.cmplx`; this variant gives
action agents ``Discrete(5)``, action 4 being the dump (the only way to prune).

Examples
--------
>>> env = Cmplx2Env(max_steps=10)
>>> env.variant, [int(env.action_space(a).n) for a in env.possible_agents]
('cmplx2', [6, 6, 5, 5])
"""

from __future__ import annotations

from typing import Any

from fcplan.env.presets.cmplx import CmplxEnv

__all__ = ["Cmplx2Env"]


class Cmplx2Env(CmplxEnv):
    """:class:`CmplxEnv` with ``variant="cmplx2"``; takes its other keyword arguments."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(variant="cmplx2", **kwargs)
