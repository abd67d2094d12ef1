"""Scheduling experts on a sharded batched env: every shard plans its own worlds, all at once.

The experts of the batched envs (:class:`fcplan.env.vector_expert.BatchPlanFollower` at the
motion level, :meth:`fcplan.env.vector_task.VectorTaskEnv.expert_actions` at the task level)
read the worlds' simulator, beliefs and graphs, which a
:class:`fcplan.env.vector_shards.ShardedVectorEnv` spreads over its processes. The experts here put one of them in every shard, next to the
shard's batched env (in the worker process that steps it, or in this one for the first shard),
and keep it there as long as the expert lives: each call sends every shard only its part of
the request (its rows of the action masks), the shards plan at the same time, and the answers
are joined in world order. So world ``i``'s actions are those the one-process expert gives
world ``i`` of one batched env of all ``B`` worlds (``tests/env/test_vector_shard_experts.py``
compares them step for step), and scheduling, usually the dearest part of an expert's step,
runs on every core.

Schedulers given as instances are sent to the workers once, when the expert is made: each
worker shard plans with its own copies, which keep their state between calls (a routing
scheduler's warm start, say) as the first shard's instances do. One shared instance (a
scheduler with ``plan_batch``) is therefore one instance per shard.

Examples
--------
>>> import numpy as np
>>> from fcplan.env import vector_env
>>> env = vector_env("practice", mode="motion", num_envs=4, processes=2)
>>> expert = ShardedPlanFollower(env, "greedy")
>>> obs, infos = env.reset(seed=0)
>>> for _ in range(30):
...     obs, rewards, terms, truncs, infos = env.step(expert.actions(obs))
>>> expert.replans.tolist()
[3, 3, 3, 3]
>>> env.close()
"""

from __future__ import annotations

import contextlib
import itertools
import weakref
from collections.abc import Sequence
from typing import Any

import numpy as np

from fcplan.env.task_actions import MappingCounts
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_shards import ShardedVectorEnv
from fcplan.errors import EnvError
from fcplan.plan import Plan

__all__ = ["ShardedPlanFollower", "ShardedTaskExpert"]

#: the keys of the experts in their shards' kept objects (one per expert of this process)
_KEYS = itertools.count()


# -------------------------------------------------------------- run in every shard
def _keep(env: Any, kept: dict[str, Any], key: str, follow: bool, scheduler: Any,
          kw: dict[str, Any]) -> None:  # fmt: skip
    """Keep a shard's expert under ``key``: a follower of ``scheduler`` (the motion level), or
    the schedulers themselves, which ``env.expert_actions`` plans with (the task level)."""
    kept[key] = BatchPlanFollower(env, scheduler, **kw) if follow else scheduler


def _drop(env: Any, kept: dict[str, Any], key: str) -> None:
    """Forget a shard's expert."""
    kept.pop(key, None)


def _follow(env: Any, kept: dict[str, Any], key: str, mask: np.ndarray) -> np.ndarray:
    """The shard's follower's actions for the shard's action masks."""
    return kept[key].actions({"action_mask": mask})


def _attribute(env: Any, kept: dict[str, Any], key: str, name: str) -> Any:
    """An attribute of the shard's expert (``replans``, ``plans``)."""
    return getattr(kept[key], name)


def _follower_reset(env: Any, kept: dict[str, Any], key: str, rows: np.ndarray) -> None:
    """Start the shard's worlds ``rows`` afresh in its follower."""
    kept[key].reset(rows)


def _plan(env: Any, kept: dict[str, Any], key: str, time_limit: Any,
          counts: Any) -> tuple[np.ndarray, np.ndarray, Any]:  # fmt: skip
    """The task level's expert actions of the shard's worlds, with their mapping counts."""
    acts, fallback = env.expert_actions(kept[key], time_limit=time_limit, counts=counts)
    return acts, fallback, counts


# -------------------------------------------------------------- the experts
class _ShardedExpert:
    """An expert kept in every shard of ``env`` under one key (module docstring)."""

    def __init__(self, env: ShardedVectorEnv, mode: str, schedulers: Any,
                 kw: dict[str, Any]) -> None:  # fmt: skip
        if not isinstance(env, ShardedVectorEnv):
            raise EnvError(f"{type(self).__name__}: env must be a ShardedVectorEnv")
        if env.mode != mode:
            raise EnvError(
                f"{type(self).__name__}: env must be a {mode}-level env (got {env.mode})"
            )
        parts = _cut(env, schedulers, "scheduler")
        self.env, self.key = env, f"expert-{next(_KEYS)}"
        #: forgets the shards' experts once: at :meth:`close`, or when this object is collected
        self._forget = weakref.finalize(self, _forget, env, self.key)
        try:
            follow = mode == "motion"
            env.apply_shards(_keep, [(self.key, follow, s, kw) for s in parts])
        except EnvError:  # (the shards that made theirs forget it)
            self.close()
            raise

    def _apply(self, fn: Any, per_shard: Sequence[tuple]) -> list[Any]:
        if not self._forget.alive:
            raise EnvError(f"{type(self).__name__}: the expert is closed")
        return self.env.apply_shards(fn, [(self.key, *a) for a in per_shard])

    def close(self) -> None:
        """Forget the expert in every shard (a closed env has forgotten it already). An expert
        that is collected without ``close`` is forgotten then."""
        self._forget()


def _forget(env: ShardedVectorEnv, key: str) -> None:
    """Drop the expert ``key`` from every shard of ``env``, if the env still runs."""
    if env._closed or env._broken is not None:
        return
    with contextlib.suppress(EnvError, OSError):  # (a worker gone: nothing left to drop)
        env.apply_shards(_drop, [(key,)] * len(env.shards))


class ShardedPlanFollower(_ShardedExpert):
    """:class:`fcplan.env.vector_expert.BatchPlanFollower` on a sharded motion-level env.

    Parameters
    ----------
    env : ShardedVectorEnv
        A motion-level env (``vector_env(..., mode="motion", processes=n)``).
    scheduler : str, Scheduler or sequence of Scheduler
        As :class:`~fcplan.env.vector_expert.BatchPlanFollower`; one instance per world is cut
        into the shards' parts, one shared instance is copied to each worker shard.
    replan_period, time_limit, graph_params
        As :class:`~fcplan.env.vector_expert.BatchPlanFollower`.
    """

    def __init__(self, env: ShardedVectorEnv, scheduler: Any, **kwargs: Any) -> None:
        super().__init__(env, "motion", scheduler, kwargs)

    def actions(self, observations: dict[str, np.ndarray]) -> np.ndarray:
        """(B, N) int64 actions of every world for the current tick (0 in finished worlds)."""
        mask = np.asarray(observations["action_mask"])
        parts = self._apply(_follow, [(mask[lo:hi],) for lo, hi in self.env.shards])
        return np.concatenate(parts)

    def reset(self, rows: Any = None) -> None:
        """Start the worlds ``rows`` (default all) afresh (``BatchPlanFollower.reset``)."""
        rows = np.arange(self.env.num_envs) if rows is None else np.asarray(rows, dtype=np.int64)
        self._apply(_follower_reset, [(rows[(rows >= lo) & (rows < hi)] - lo,)
                                      for lo, hi in self.env.shards])  # fmt: skip

    @property
    def replans(self) -> np.ndarray:
        """(B,) int64 plans made in each world since its episode started."""
        return np.concatenate(self._apply(_attribute, [("replans",)] * len(self.env.shards)))

    @property
    def plans(self) -> list[Plan | None]:
        """Each world's last plan (copies from the shards)."""
        parts = self._apply(_attribute, [("plans",)] * len(self.env.shards))
        return [p for part in parts for p in part]


class ShardedTaskExpert(_ShardedExpert):
    """:meth:`fcplan.env.vector_task.VectorTaskEnv.expert_actions` on a sharded task-level env.

    Parameters
    ----------
    env : ShardedVectorEnv
        A task-level env (``vector_env(..., mode="task", processes=n)``).
    schedulers : Scheduler or sequence of Scheduler
        One instance for every world, or one per world (as ``VectorTaskEnv.expert_actions``).
    time_limit : float, optional
        Seconds per plan (as ``VectorTaskEnv.expert_actions``).

    Examples
    --------
    >>> from fcplan.env import vector_env
    >>> from fcplan.scheduling import make_scheduler
    >>> env = vector_env("practice", mode="task", num_envs=3, processes=2, k=4)
    >>> expert = ShardedTaskExpert(env, make_scheduler("greedy"))
    >>> obs, infos = env.reset(seed=0)
    >>> actions, fallback = expert.actions()
    >>> actions.shape, fallback.tolist()
    ((3, 4), [False, False, False])
    >>> env.close()
    """

    def __init__(self, env: ShardedVectorEnv, schedulers: Any, *,
                 time_limit: float | None = None) -> None:  # fmt: skip
        super().__init__(env, "task", schedulers, {})
        self.time_limit = time_limit

    def actions(
        self, counts: MappingCounts | Sequence[MappingCounts] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """(B, A) actions of the schedulers' plans on every world's current graph, and (B,)
        bool: the plan came from the greedy fallback. ``counts`` (one for all the worlds, or
        one per world) are added to as ``VectorTaskEnv.expert_actions`` adds to them."""
        mine: list[MappingCounts] = []
        if isinstance(counts, MappingCounts):
            mine = [counts] * self.env.num_envs
        elif counts is not None:
            mine = [c for part in _cut(self.env, counts, "counts") for c in part]
        fresh = [[MappingCounts() for _ in range(hi - lo)] for lo, hi in self.env.shards]
        parts = self._apply(_plan, [(self.time_limit, c) for c in fresh])
        if mine:
            for total, theirs in zip(mine, [c for p in parts for c in p[2]], strict=True):
                total.add(theirs)
        return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _cut(env: Any, value: Any, name: str) -> list[Any]:
    """Every shard's part of ``value``: a per-world sequence cut into the shards' parts,
    anything else the same for each shard."""
    if not isinstance(value, (list, tuple)):
        return [value] * len(env.shards)
    if len(value) != env.num_envs:
        raise EnvError(f"{name}: need {env.num_envs}, one per world (got {len(value)})")
    return [list(value[lo:hi]) for lo, hi in env.shards]
