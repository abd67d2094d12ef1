"""Gymnasium ids of fcplan's single-agent views, registered when :mod:`fcplan.env` is imported.

=========================  ==============================================  =====================
id                         environment                                     default kwargs
=========================  ==============================================  =====================
``fcplan/Task-v1``         :class:`fcplan.env.gym_view.TaskGymEnv`: the    ``scenario="practice"``,
                           task level, joint ``MultiDiscrete`` action;     ``dump_altitude=None``
                           hybrids dump from the top of their bounds
                           (:mod:`fcplan.env.task_v1`)
``fcplan/Task-v0``         the same with v0's rule: such a hybrid flies    ``scenario="practice"``,
                           at ``watch_altitude``                           ``dump_altitude="watch"``
                           (:mod:`fcplan.env.task_v0`)
``fcplan/Motion-v0``       :class:`fcplan.env.joint_gym.JointGymEnv` on    ``scenario="practice"``
                           :class:`fcplan.env.motion.MotionEnv`
``fcplan/MotionBase-v0``   the ``base`` preset (:mod:`~fcplan.env.presets`) ``preset="base"``
``fcplan/MotionCmplx1-v0`` the ``cmplx1`` preset                            ``preset="cmplx1"``
``fcplan/MotionCmplx2-v0`` the ``cmplx2`` preset                            ``preset="cmplx2"``
=========================  ==============================================  =====================

``gymnasium.make_vec("fcplan/Motion-v0", num_envs=B, scenario=...)`` makes the batched env of
:data:`VECTOR_ENTRY_POINTS` (:func:`fcplan.env.vector_env`: a
:class:`fcplan.env.vector_motion.VectorMotionEnv` of ``B`` worlds in one call, each
bit-identical to the single env with seed ``s + i``; with ``processes=P``, a
:class:`fcplan.env.vector_shards.ShardedVectorEnv`); ``vectorization_mode="sync"`` gives
Gymnasium's ``SyncVectorEnv`` of single envs instead.

Any keyword of the environment goes through ``gymnasium.make``: ``gymnasium.make("fcplan/Task-v0",
scenario=24, k=8)``, ``gymnasium.make("fcplan/MotionBase-v0", reward="rf1")``. Every id accepts
``render_mode="rgb_array"`` and ``render_mode="human"`` (:mod:`fcplan.env.human`).

Gymnasium 1.x reads no plugin entry points: an id is known once :mod:`fcplan.env` is imported
(``import fcplan.env`` or ``gymnasium.register_envs(fcplan.env)``), or through the module prefix
of ``gymnasium.make``, which imports it: ``gymnasium.make("fcplan.env:fcplan/Task-v0")`` works
after ``import gymnasium`` alone. A version number changes whenever a change of the env would
change its observations, rewards or episodes for the same seed and actions.

Examples
--------
>>> import gymnasium
>>> import fcplan.env
>>> env = gymnasium.make("fcplan/Task-v0", k=4, max_steps=2)
>>> env.spec.id, env.unwrapped.action_space.nvec.tolist()
('fcplan/Task-v0', [5, 5, 5, 5])
>>> sorted(ENV_IDS)[:2]
['fcplan/Motion-v0', 'fcplan/MotionBase-v0']
"""

from __future__ import annotations

from typing import Any

__all__ = ["ENV_IDS", "VECTOR_ENTRY_POINTS", "register_envs"]

_JOINT = "fcplan.env.joint_gym:JointGymEnv"

#: Gymnasium id -> (entry point, default keyword arguments).
ENV_IDS: dict[str, tuple[str, dict[str, Any]]] = {
    "fcplan/Task-v1": (
        "fcplan.env.gym_view:TaskGymEnv",
        {"scenario": "practice", "dump_altitude": None},
    ),
    "fcplan/Task-v0": (
        "fcplan.env.gym_view:TaskGymEnv",
        {"scenario": "practice", "dump_altitude": "watch"},
    ),
    "fcplan/Motion-v0": (_JOINT, {"scenario": "practice"}),
    "fcplan/MotionBase-v0": (_JOINT, {"preset": "base"}),
    "fcplan/MotionCmplx1-v0": (_JOINT, {"preset": "cmplx1"}),
    "fcplan/MotionCmplx2-v0": (_JOINT, {"preset": "cmplx2"}),
}


#: Gymnasium id -> the batched env ``gymnasium.make_vec`` makes (:mod:`fcplan.env.vector`).
VECTOR_ENTRY_POINTS: dict[str, str] = {
    "fcplan/Motion-v0": "fcplan.env.vector:motion_vector_env",
    "fcplan/Task-v0": "fcplan.env.vector:task_vector_env",
    "fcplan/Task-v1": "fcplan.env.vector:task_vector_env",
}


def register_envs() -> None:
    """Register every id of :data:`ENV_IDS` with Gymnasium (ids already there are kept), with
    its :data:`VECTOR_ENTRY_POINTS` entry if it has one."""
    import gymnasium

    for env_id, (entry_point, kwargs) in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                env_id,
                entry_point=entry_point,
                vector_entry_point=VECTOR_ENTRY_POINTS.get(env_id),
                kwargs=dict(kwargs),
            )
