"""Learner interfaces: PettingZoo environments, a Gymnasium view, scheduler demonstrations.

Two levels of control over the same simulator:

``mode="task"`` (:mod:`fcplan.env.task`)
    One step is one replan period (1 simulated second by default). Each UAV picks one of its
    ``k`` most relevant tasks of the current task graph, or no-op. Observations are a ``Dict``
    of the agent's own state, a ``k x F`` task-feature table and an ``action_mask``.
``mode="motion"`` (:mod:`fcplan.env.motion`)
    One step is one tick: moves, altitude, dump, with local field-of-view observations.
    :class:`PlanFollower` (:mod:`fcplan.env.motion_expert`) drives it with any scheduler's plans.
    The 2020 MARL package's grid environments (``base``, ``cmplx1``, ``cmplx2``) are its presets
    (:mod:`fcplan.env.presets`).

Batched: :func:`vector_env` (:mod:`fcplan.env.vector`) runs ``B`` worlds per call on
:class:`fcplan.batch.BatchWorld` as a ``gymnasium.vector.VectorEnv``, world ``i`` bit-identical
to the single env with seed ``s + i``; ``gymnasium.make_vec("fcplan/Motion-v0", num_envs=B)``
makes it too. :class:`BatchPlanFollower` (:mod:`fcplan.env.vector_expert`) is the
:class:`PlanFollower` of every world of a batched motion env, and
:meth:`VectorTaskEnv.expert_actions <fcplan.env.vector_task.VectorTaskEnv.expert_actions>` a
scheduler's actions on every world of the batched task level.
``vector_env(..., processes=P)`` splits the worlds over ``P`` processes stepped at once
(:mod:`fcplan.env.vector_shards`), and :class:`ShardedPlanFollower` and
:class:`ShardedTaskExpert` (:mod:`fcplan.env.vector_shard_experts`) are the two experts on it,
each shard planning its own worlds. Their ``reset(seed=s)`` seeds world ``b`` with ``s + b``, also when ``options["reset_mask"]``
picks the worlds, as Gymnasium's vector envs do (:func:`fcplan.env.vector_base.reset_seeds`).

Actions are integers; floats of whole values are taken as those integers, and a fractional or
non-finite one raises :class:`~fcplan.errors.EnvError` before anything steps
(:mod:`fcplan.env.action_input`).

Also here: :func:`gym_env` (a Gymnasium single-agent view of the task level with a centralised
joint action), :func:`demonstrations` / :func:`load_demonstrations` (expert datasets from any
registered scheduler, stored as npz without pickle) and :mod:`fcplan.env.bc` (a small numpy
behaviour-cloning baseline). Everything is imported lazily, so ``import fcplan.env`` is cheap
and does not need PettingZoo until an environment is made; it registers the Gymnasium ids
``fcplan/Task-v1``, ``fcplan/Task-v0``, ``fcplan/Motion-v0``, ``fcplan/MotionBase-v0``,
``fcplan/MotionCmplx1-v0`` and ``fcplan/MotionCmplx2-v0`` (:mod:`fcplan.env.registration`).

Standard integrations: the versioned PettingZoo modules :mod:`~fcplan.env.task_v1` (hybrids
dump from the top of their bounds, as the schedulers' do), :mod:`~fcplan.env.task_v0`,
:mod:`~fcplan.env.motion_v0`, :mod:`~fcplan.env.base_v0`, :mod:`~fcplan.env.cmplx1_v0` and
:mod:`~fcplan.env.cmplx2_v0` (``env()``, ``parallel_env()``, ``raw_env``;
:mod:`fcplan.env.versions`); the options ``obs_layout="flat"`` and ``pad_actions=True``
(:mod:`fcplan.env.wrappers`), which give the ``{"observation", "action_mask"}`` layout and equal
action spaces that SuperSuit's vector wrappers need; ``render_mode="human"``
(:mod:`fcplan.env.human`). :class:`~fcplan.errors.EnvError` is
defined in :mod:`fcplan.errors` and exported here.

Examples
--------
>>> from fcplan.env import parallel_env
>>> env = parallel_env("practice", k=4)
>>> obs, infos = env.reset(seed=0)
>>> env.agents
['P1', 'P2', 'A1', 'A2']
>>> obs["A1"]["tasks"].shape, obs["A1"]["action_mask"].shape
((4, 17), (5,))
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from fcplan.errors import EnvError

if TYPE_CHECKING:
    from pettingzoo import AECEnv, ParallelEnv

__all__ = [
    "EnvError",
    "MODES",
    "parallel_env",
    "aec_env",
    "gym_env",
    "TaskEnv",
    "TaskGymEnv",
    "demonstrations",
    "load_demonstrations",
    "Demonstrations",
    "replay_actions",
    "PlanFollower",
    "BatchPlanFollower",
    "VERSIONED",
    "vector_env",
    "VectorMotionEnv",
    "VectorTaskEnv",
    "ShardedVectorEnv",
    "ShardedPlanFollower",
    "ShardedTaskExpert",
]

#: Environment levels accepted by :func:`parallel_env`.
MODES = ("task", "motion")


_LAZY = {
    "TaskEnv": "fcplan.env.task",
    "TaskGymEnv": "fcplan.env.gym_view",
    "gym_env": "fcplan.env.gym_view",
    "demonstrations": "fcplan.env.demonstrations",
    "load_demonstrations": "fcplan.env.demonstrations",
    "Demonstrations": "fcplan.env.demonstrations",
    "replay_actions": "fcplan.env.demonstrations",
    "PlanFollower": "fcplan.env.motion_expert",
    "BatchPlanFollower": "fcplan.env.vector_expert",
    "vector_env": "fcplan.env.vector",
    "VectorMotionEnv": "fcplan.env.vector_motion",
    "VectorTaskEnv": "fcplan.env.vector_task",
    "ShardedVectorEnv": "fcplan.env.vector_shards",
    "ShardedPlanFollower": "fcplan.env.vector_shard_experts",
    "ShardedTaskExpert": "fcplan.env.vector_shard_experts",
}


#: the versioned PettingZoo modules, imported on first access as attributes
VERSIONED = ("task_v0", "task_v1", "motion_v0", "base_v0", "cmplx1_v0", "cmplx2_v0")


def __getattr__(name: str) -> Any:
    if name in VERSIONED:
        return import_module(f"fcplan.env.{name}")
    if name in _LAZY:
        value = getattr(import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'fcplan.env' has no attribute {name!r}")


def parallel_env(
    scenario: Any,
    mode: str = "task",
    *,
    obs_layout: str = "dict",
    pad_actions: bool = False,
    render_mode: str | None = None,
    **kwargs: Any,
) -> ParallelEnv:
    """Make a PettingZoo ``ParallelEnv`` on ``scenario``.

    Parameters
    ----------
    scenario : Scenario or str or int
        A scenario or a name/path for :func:`fcplan.load_scenario` (at the motion level also a
        preset name: ``"base"``, ``"cmplx1"``, ``"cmplx2"``).
    mode : {"task", "motion"}
        ``"task"``: :class:`fcplan.env.task.TaskEnv` (one step per replan period);
        ``"motion"``: :func:`fcplan.env.motion.parallel_env` (one step per tick).
    obs_layout : {"dict", "flat"}
        ``"flat"``: ``{"observation", "action_mask"}`` per agent
        (:class:`fcplan.env.wrappers.FlatObservations`); ``"dict"`` (default): the env's own.
    pad_actions : bool
        Give every agent the team's largest ``Discrete`` space, extra actions masked
        (:class:`fcplan.env.wrappers.PadActions`).
    render_mode : {None, "rgb_array", "human"}
        ``"human"`` shows the frames in a pygame window (:mod:`fcplan.env.human`).
    **kwargs
        Passed to the environment (see its module docstring).

    Raises
    ------
    EnvError
        If ``mode`` is not one of :data:`MODES`, or ``obs_layout`` is unknown.
    """
    from fcplan.env.wrappers import split_options, wrap

    inner_mode, human = split_options(render_mode)
    if inner_mode is not None:
        kwargs["render_mode"] = inner_mode
    env: ParallelEnv
    if mode == "task":
        from fcplan.env.task import TaskEnv

        env = TaskEnv(scenario, **kwargs)
    elif mode == "motion":
        from fcplan.env.motion import parallel_env as motion_env

        env = motion_env(scenario, **kwargs)
    else:
        raise EnvError(f"mode: must be one of {', '.join(MODES)} (got {mode!r})")
    return wrap(env, obs_layout=obs_layout, pad_actions=pad_actions, human=human)


def aec_env(scenario: Any, mode: str = "task", **kwargs: Any) -> AECEnv:
    """The same environment as :func:`parallel_env`, as a PettingZoo ``AECEnv``
    (``pettingzoo.utils.parallel_to_aec``)."""
    from pettingzoo.utils import parallel_to_aec

    return parallel_to_aec(parallel_env(scenario, mode, **kwargs))


# Gymnasium ids (fcplan/Task-v0 ...): registered on import, see fcplan.env.registration
from fcplan.env.registration import register_envs as _register_envs  # noqa: E402

_register_envs()
