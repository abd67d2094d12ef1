"""The batched env of a level in this process: the one rule behind
:func:`fcplan.env.vector_env` and the shards of :class:`fcplan.env.vector_shards.ShardedVectorEnv`.

Examples
--------
>>> env = batched_env("practice", "task", 2, k=4)
>>> type(env).__name__, env.num_envs
('VectorTaskEnv', 2)
"""

from __future__ import annotations

from typing import Any

from fcplan.errors import EnvError

__all__ = ["VECTOR_MODES", "batched_env"]

#: levels the batched envs batch
VECTOR_MODES = ("motion", "task")


def batched_env(scenario: Any, mode: str, num_envs: int, **kwargs: Any) -> Any:
    """:class:`~fcplan.env.vector_motion.VectorMotionEnv` (``mode="motion"``) or
    :class:`~fcplan.env.vector_task.VectorTaskEnv` (``"task"``) of ``num_envs`` worlds."""
    if mode == "motion":
        from fcplan.env.vector_motion import VectorMotionEnv

        return VectorMotionEnv(scenario, num_envs, **kwargs)
    if mode == "task":
        from fcplan.env.vector_task import VectorTaskEnv

        return VectorTaskEnv(scenario, num_envs, **kwargs)
    raise EnvError(f"mode: must be one of {', '.join(VECTOR_MODES)} (got {mode!r})")
