"""Demonstration episodes in units of work, played in this process or in worker processes.

:func:`fcplan.env.demonstrations.demonstrations` splits its (scenario, seed) episodes into
:class:`DemoUnit` s: one scenario and some of its seeds, rolled out in one
:class:`~fcplan.env.task.TaskEnv` (``num_envs=1``: the seeds one after another) or in one
batched :class:`~fcplan.env.vector_task.VectorTaskEnv` of as many worlds (``num_envs > 1``).
:func:`play_unit` plays a unit and returns its :class:`~fcplan.env.demo_episodes.EpisodeRecord`
s in seed order; :func:`play_units` plays a list of units with
``jobs=1`` in this process, else on the local process pool of
:func:`~fcplan.experiments.compare` and :func:`~fcplan.experiments.sweep`
(:func:`fcplan.experiments.backends.select_backend`: workers that ignore Ctrl-C, die with the
parent and know the schedulers registered at run time), and hands the results back in the units'
order, whatever order they finished in. An episode is a pure function of its scenario, seed and
scheduler, so the dataset is the same for every ``jobs`` (for a scheduler that keeps no state
between episodes, as for ``num_envs``; ``tests/env/test_demo_units.py``).

:func:`demo_units` makes the units: one per seed at ``num_envs=1`` (a fresh env each, which
costs 13-20 ms against seconds for an episode, so that progress counts episodes); per
``num_envs`` seeds in a batched env, and with more jobs at most ``ceil(seeds / jobs)`` worlds
per batched env, so that every worker gets work.

Examples
--------
>>> from fcplan.scheduling import make_scheduler
>>> from fcplan.scenario import load_scenario
>>> sc = load_scenario("practice")
>>> units = demo_units([(sc, "practice", [0, 1, 2])], make_scheduler("greedy"), "greedy",
...                    env_kwargs={"max_steps": 2}, time_limit=None, num_envs=1, jobs=2)
>>> [u.seeds for u in units]
[(0,), (1,), (2,)]
>>> [r.seed for r in play_unit(units[1]).records]
[1]
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from fcplan.env.demo_episodes import EpisodeRecord, batched_rollouts, rollout_episode
from fcplan.env.task import TaskEnv
from fcplan.errors import FcplanError
from fcplan.scheduling import Scheduler, make_scheduler
from fcplan.scheduling_batch import instances

__all__ = ["DemoUnit", "UnitResult", "demo_units", "play_unit", "play_units"]


@dataclass(frozen=True)
class DemoUnit:
    """One scenario's seeds rolled out together (module docstring).

    Attributes
    ----------
    key : str
        Unique among a run's units (the backends' requirement).
    scenario : Scenario
    scenario_key : str
        The dataset's key of the scenario.
    seeds : tuple of int
    scheduler : Scheduler
        The instance that plans the seeds of a single-env unit in turn.
    spec : str or Scheduler
        What a batched unit makes its instances from (a spec, or copies of the object).
    env_kwargs : dict
    time_limit : float or None
    num_envs : int
        1: one env, the seeds in turn; more: a batched env of ``len(seeds)`` worlds.
    """

    key: str
    scenario: Any
    scenario_key: str
    seeds: tuple[int, ...]
    scheduler: Scheduler
    spec: str | Scheduler
    env_kwargs: dict[str, Any]
    time_limit: float | None
    num_envs: int


@dataclass
class UnitResult:
    """A played unit: its episodes in seed order (each with its mapping counts)."""

    records: list[EpisodeRecord]


def demo_units(
    plan: Sequence[tuple[Any, str, Sequence[int]]],
    scheduler: Scheduler,
    spec: str | Scheduler,
    *,
    env_kwargs: dict[str, Any],
    time_limit: float | None,
    num_envs: int,
    jobs: int,
) -> list[DemoUnit]:
    """The units of the seeds of every ``(scenario, key, seeds)`` of ``plan``, in the dataset's
    order (scenario, then seed; module docstring for the sizes)."""
    units: list[DemoUnit] = []
    for scenario, key, seeds in plan:
        n = len(seeds)
        size = 1
        if num_envs > 1:
            size = num_envs if jobs == 1 else max(1, min(num_envs, math.ceil(n / jobs)))
        for i in range(0, n, size):
            chunk = tuple(int(s) for s in seeds[i : i + size])
            units.append(DemoUnit(str(len(units)), scenario, key, chunk, scheduler, spec,
                                  env_kwargs, time_limit, num_envs))  # fmt: skip
    return units


def play_unit(unit: DemoUnit, runtime: dict[str, Callable[..., Any]] | None = None) -> UnitResult:
    """Roll out ``unit``'s seeds (module docstring); a module-level function, so pool workers
    can run it (``runtime``: schedulers registered at run time in the parent, registered here
    first, as Dask workers need: :func:`fcplan.experiments.play.play_episode`)."""
    if runtime:
        from fcplan.experiments.workers import register_runtime

        register_runtime(runtime)
    if unit.num_envs > 1:
        from fcplan.env.vector_task import VectorTaskEnv

        env = VectorTaskEnv(unit.scenario, len(unit.seeds), autoreset_mode="disabled",
                            **unit.env_kwargs)  # fmt: skip
        spec = unit.spec
        scheds = instances(lambda: make_scheduler(spec) if isinstance(spec, str)
                           else copy.deepcopy(spec), len(unit.seeds))  # fmt: skip
        records = batched_rollouts(env, scheds, unit.scenario_key, unit.seeds,
                                   time_limit=unit.time_limit)  # fmt: skip
    else:
        one = TaskEnv(unit.scenario, **unit.env_kwargs)
        records = [rollout_episode(one, unit.scheduler, unit.scenario_key, seed,
                                   time_limit=unit.time_limit)
                   for seed in unit.seeds]  # fmt: skip
    return UnitResult(records)


def play_units(
    units: Sequence[DemoUnit],
    jobs: int,
    *,
    dask: str | None = None,
    on_unit: Callable[[DemoUnit, UnitResult], None] | None = None,
) -> list[UnitResult]:
    """Play ``units`` (``jobs=1``: here, in order; else on a local pool of at most ``jobs``
    workers; with ``dask``, on a Dask cluster, :func:`fcplan.experiments.backends.iter_dask`)
    and return their results in the units' order; ``on_unit`` is called as each one finishes
    (completion order).

    Raises
    ------
    FcplanError
        For units that cannot be pickled for the workers (a scheduler object holding a lambda,
        a lock ...: checked before any episode), and for a unit whose worker failed or died (it names the scenario and the seeds); what the
        episode raised comes with it. In this process a unit's exception propagates as it is.
    """
    from fcplan.experiments.backends import select_backend
    from fcplan.experiments.workers import runtime_factories

    if units and (dask is not None or (jobs > 1 and len(units) > 1)):
        _check_sendable(units[0], f"jobs={jobs}" if dask is None else f"dask={dask!r}")
    names = sorted({u.spec for u in units if isinstance(u.spec, str)})
    _, outcomes = select_backend(
        list(units), jobs, runtime_factories(names), dask=dask, play=play_unit
    )
    done: dict[str, UnitResult] = {}
    try:
        for unit, result, lost in outcomes:
            if result is None:
                raise FcplanError(
                    f"demonstrations: {unit.scenario_key} seeds {list(unit.seeds)} produced "
                    f"nothing: {lost}"
                )
            done[unit.key] = result
            if on_unit is not None:
                on_unit(unit, result)
    finally:
        outcomes.close()
    return [done[u.key] for u in units]


def _check_sendable(unit: DemoUnit, where: str) -> None:
    """Fail in one line, before the pool starts, when ``unit`` (its scheduler object) cannot be
    pickled for a worker process (``where``: the argument that sends it, for the message)."""
    import pickle

    try:
        pickle.dumps(unit)
    except Exception as exc:  # noqa: BLE001 - whatever pickling raises, said in one line
        raise FcplanError(
            f"demonstrations: {where} sends the scheduler to worker processes, and it cannot "
            f"be pickled ({type(exc).__name__}: {exc}); pass a registered name or spec, or jobs=1"
        ) from None
