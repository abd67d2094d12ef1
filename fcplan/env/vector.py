"""Batched environments: ``B`` worlds per call, for learners that need 10^7-10^9 steps.

:func:`vector_env` makes a ``gymnasium.vector.VectorEnv`` whose worlds all run in one
:class:`fcplan.batch.BatchWorld` (every per-tick array has a leading batch axis; no Python loop
over worlds on the per-tick path):

``mode="motion"`` (:class:`fcplan.env.vector_motion.VectorMotionEnv`)
    One step is one tick of every world; actions ``(B, N)``, observations ``(B, N, ...)`` with
    action masks. World ``i`` is bit for bit ``fcplan/Motion-v0`` (the centralised view of
    :class:`fcplan.env.motion.MotionEnv`) with seed ``s + i``.

``mode="task"`` (:class:`fcplan.env.vector_task.VectorTaskEnv`)
    One step is one replan period of every world; actions ``(B, A)`` candidate slots,
    observations ``(B, A, ...)``; world ``i`` is ``fcplan/Task-v1`` with seed ``s + i``
    (``fcplan/Task-v0`` with ``dump_altitude="watch"``, the env option of hybrids' dumps). The
    ticks are batched; the belief, task graph, candidates and features stay per world (that
    module says why and ``bench/README.md`` measures it).

``processes=K`` splits the worlds into ``K`` shards stepped at once, one here and ``K - 1`` in
worker processes (:class:`fcplan.env.vector_shards.ShardedVectorEnv`: the same worlds and
steps, on ``K`` cores).

``gymnasium.make_vec("fcplan/Motion-v0", num_envs=B, scenario=...)`` (and ``"fcplan/Task-v0"``,
``"fcplan/Task-v1"``) return the same envs (the ids' ``vector_entry_point``,
:func:`motion_vector_env` and :func:`task_vector_env`; ``processes=P`` too); ``vectorization_mode="sync"`` still gives
Gymnasium's ``SyncVectorEnv`` of single envs, which the batched ones match step for step.

Examples
--------
>>> import numpy as np
>>> from fcplan.env import vector_env
>>> env = vector_env("practice", mode="motion", num_envs=8)
>>> obs, infos = env.reset(seed=0)
>>> actions = env.action_space.sample()  # (8, 4): one action per world and agent
>>> obs, rewards, terminations, truncations, infos = env.step(actions)
>>> obs["fov"].shape, rewards.shape
((8, 4, 7, 15, 15), (8,))
"""

from __future__ import annotations

from typing import Any

from fcplan.env.vector_make import VECTOR_MODES, batched_env

__all__ = ["vector_env", "motion_vector_env", "task_vector_env", "VECTOR_MODES"]


def vector_env(
    scenario: Any,
    mode: str = "motion",
    num_envs: int = 1,
    *,
    processes: int | None = None,
    **kwargs: Any,
) -> Any:
    """Make a batched ``gymnasium.vector.VectorEnv`` of ``num_envs`` worlds of ``scenario``.

    Parameters
    ----------
    scenario : Scenario, str or int
        A scenario or a name/path for :func:`fcplan.load_scenario`.
    mode : {"motion", "task"}
        The level (module docstring).
    num_envs : int
        Worlds ``B``.
    processes : int, optional
        Step the worlds in this many processes at once, this one included
        (:class:`~fcplan.env.vector_shards.ShardedVectorEnv`, which also takes ``context`` and
        ``copy``); default: all in this process, in one batched env.
    **kwargs
        The level's options (``autoreset_mode``; ``cell_px``, ``view``, ... at the motion level;
        ``k``, ``replan_period``, ... at the task level).

    Raises
    ------
    EnvError
        For an unknown ``mode`` or a bad option.
    """
    if processes is not None:
        from fcplan.env.vector_shards import ShardedVectorEnv

        return ShardedVectorEnv(scenario, mode, num_envs, processes=processes, **kwargs)
    return batched_env(scenario, mode, num_envs, **kwargs)


def motion_vector_env(scenario: Any = "practice", num_envs: int = 1, **kwargs: Any) -> Any:
    """``vector_env(scenario, "motion", num_envs, **kwargs)``: what ``gymnasium.make_vec(
    "fcplan/Motion-v0", num_envs)`` makes."""
    return vector_env(scenario, "motion", num_envs, **kwargs)


def task_vector_env(scenario: Any = "practice", num_envs: int = 1, **kwargs: Any) -> Any:
    """``vector_env(scenario, "task", num_envs, **kwargs)``: what ``gymnasium.make_vec(
    "fcplan/Task-v0", num_envs)`` makes."""
    return vector_env(scenario, "task", num_envs, **kwargs)
