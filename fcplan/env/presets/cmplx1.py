"""Preset ``cmplx1``: the reference ``FireCommanderHard`` (action agents prune every step).

The rules, spaces and deviations are those of :mod:`fcplan.env.presets.cmplx`; this variant gives
action agents ``Discrete(4)`` (moves only).

Examples
--------
>>> env = Cmplx1Env(max_steps=10)
>>> env.variant, [int(env.action_space(a).n) for a in env.possible_agents]
('cmplx1', [6, 6, 4, 4])
"""

from __future__ import annotations

from typing import Any

from fcplan.env.presets.cmplx import CmplxEnv

__all__ = ["Cmplx1Env"]


class Cmplx1Env(CmplxEnv):
    """:class:`CmplxEnv` with ``variant="cmplx1"``; takes its other keyword arguments."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(variant="cmplx1", **kwargs)
