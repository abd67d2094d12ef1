"""The PettingZoo module convention: ``env()``, ``parallel_env()`` and ``raw_env`` per version.

PettingZoo environments are versioned modules (``pistonball_v6``) that export ``raw_env`` (the
environment class), ``parallel_env(**kwargs)`` and ``env(**kwargs)`` (its AEC form, here
``pettingzoo.utils.parallel_to_aec``). fcplan's are :mod:`fcplan.env.task_v0`,
:mod:`fcplan.env.motion_v0` and the presets :mod:`fcplan.env.base_v0`,
:mod:`fcplan.env.cmplx1_v0`, :mod:`fcplan.env.cmplx2_v0`; each is two lines on top of
:func:`versioned`. ``raw_env`` is the environment class with ``metadata["name"]`` set to the
module's name; ``parallel_env`` and ``env`` also take the options of
:mod:`fcplan.env.wrappers`: ``obs_layout="flat"``, ``pad_actions=True`` and
``render_mode="human"``.

A module's version changes whenever a change of the env would change its observations, rewards
or episodes for the same seed and actions; the old module then stays importable as long as it
can.

Examples
--------
>>> from fcplan.env import base_v0
>>> env = base_v0.parallel_env(max_steps=3)
>>> env.metadata["name"], type(env).__name__
('base_v0', 'raw_env')
>>> aec = base_v0.env(max_steps=3)
>>> aec.reset(seed=0)
>>> aec.agent_selection
'perception_0'
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pettingzoo import AECEnv, ParallelEnv

from fcplan.env.wrappers import split_options, wrap

__all__ = ["versioned"]


def versioned(
    raw_env: Callable[..., ParallelEnv],
) -> tuple[Callable[..., AECEnv], Callable[..., ParallelEnv]]:
    """The ``(env, parallel_env)`` makers of a versioned module whose class is ``raw_env``."""

    def parallel_env(
        *args: Any,
        obs_layout: str = "dict",
        pad_actions: bool = False,
        render_mode: str | None = None,
        **kwargs: Any,
    ) -> ParallelEnv:
        inner_mode, human = split_options(render_mode)
        if inner_mode is not None:
            kwargs["render_mode"] = inner_mode
        env = raw_env(*args, **kwargs)
        return wrap(env, obs_layout=obs_layout, pad_actions=pad_actions, human=human)

    def env(*args: Any, **kwargs: Any) -> AECEnv:
        from pettingzoo.utils import parallel_to_aec

        return parallel_to_aec(parallel_env(*args, **kwargs))

    name = getattr(raw_env, "metadata", {}).get("name", "env")
    parallel_env.__doc__ = (
        f"Make ``{name}`` as a PettingZoo ``ParallelEnv`` (keyword arguments: the env's, plus "
        "``obs_layout``, ``pad_actions``, ``render_mode``; :mod:`fcplan.env.wrappers`)."
    )
    env.__doc__ = f"Make ``{name}`` as a PettingZoo ``AECEnv`` (``parallel_to_aec``)."
    return env, parallel_env
