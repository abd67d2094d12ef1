"""``task_v1``: the task-level environment, hybrids dumping by the schedulers' rule.

The same env as :mod:`fcplan.env.task_v0` (:class:`fcplan.env.task.TaskEnv`: spaces, reward,
termination, seeding; the scenario ``"practice"`` by default) except for one rule, which is why
the version changed: a hybrid (camera and water) sent to a fire dumps on it from
``dump_altitude=None``, the top of its altitude bounds, the rule of every built-in scheduler
(:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`), where ``task_v0`` flies it at
``watch_altitude`` (35 m). On scenarios without hybrids (the manual's) both versions give the
same episodes. ``fcplan/Task-v1`` is its Gymnasium id; ``parallel_env(**kwargs)`` and
``env(**kwargs)`` (AEC) take the env's keyword arguments plus ``obs_layout``, ``pad_actions``
and ``render_mode="human"`` (:mod:`fcplan.env.versions`).

Examples
--------
>>> from fcplan.env import task_v1
>>> env = task_v1.parallel_env(scenario="open_world_example", k=4, max_steps=2)
>>> env.metadata["name"], env.dump_altitude is None
('task_v1', True)
"""

from __future__ import annotations

from typing import Any

from fcplan.env.task import TaskEnv
from fcplan.env.versions import versioned
from fcplan.mission import ScenarioLike

__all__ = ["env", "parallel_env", "raw_env"]


class raw_env(TaskEnv):  # noqa: N801 (PettingZoo's name for the env class)
    """:class:`fcplan.env.task.TaskEnv`, named ``task_v1``, on ``"practice"`` by default, with
    ``dump_altitude=None``."""

    metadata = {**TaskEnv.metadata, "name": "task_v1"}

    def __init__(
        self, scenario: ScenarioLike = "practice", dump_altitude: Any = None, **kwargs: Any
    ) -> None:
        super().__init__(scenario, dump_altitude=dump_altitude, **kwargs)


env, parallel_env = versioned(raw_env)
