"""``task_v0``: the task-level environment as a versioned PettingZoo module.

:class:`raw_env` is :class:`fcplan.env.task.TaskEnv` (the documentation page: spaces, reward,
termination, seeding) with ``metadata["name"] = "task_v0"``, the scenario ``"practice"`` by
default and v0's rule for hybrids: one sent to a fire dumps on it from ``watch_altitude``
(``dump_altitude="watch"``; :mod:`fcplan.env.task_v1` and the env's default: the top of its
bounds, as the schedulers' hybrids do); ``parallel_env(**kwargs)`` and ``env(**kwargs)`` (AEC) take its keyword arguments plus
``obs_layout``, ``pad_actions`` and ``render_mode="human"`` (:mod:`fcplan.env.versions`).

Examples
--------
>>> from fcplan.env import task_v0
>>> env = task_v0.parallel_env(scenario=24, k=4, max_steps=2, obs_layout="flat")
>>> obs, infos = env.reset(seed=0)
>>> obs["P1"]["observation"].shape, obs["P1"]["action_mask"].shape
((85,), (5,))
"""

from __future__ import annotations

from typing import Any

from fcplan.env.task import TaskEnv
from fcplan.env.versions import versioned
from fcplan.mission import ScenarioLike

__all__ = ["env", "parallel_env", "raw_env"]


class raw_env(TaskEnv):  # noqa: N801 (PettingZoo's name for the env class)
    """:class:`fcplan.env.task.TaskEnv`, named ``task_v0``, on ``"practice"`` by default, with
    ``dump_altitude="watch"``."""

    metadata = {**TaskEnv.metadata, "name": "task_v0"}

    def __init__(
        self, scenario: ScenarioLike = "practice", dump_altitude: Any = "watch", **kwargs: Any
    ) -> None:
        super().__init__(scenario, dump_altitude=dump_altitude, **kwargs)


env, parallel_env = versioned(raw_env)
