"""Benchmark the batched env on several cores: ``B`` worlds in one process against the same
``B`` worlds over ``P`` processes, wall clock, in the same rounds.

For every ``P`` of ``--procs`` (default 1, 2) it measures, with random legal actions (drawn
from the masks between steps):

* ``independent``: ``P`` processes started together, each with a batched env
  (:class:`fcplan.env.vector_motion.VectorMotionEnv`, or ``VectorTaskEnv`` with ``--level
  task``) of ``B / P`` worlds, exchanging nothing: the bound of any process-parallel design,
  which pays for moving actions and observations on top. ``P`` = 1 is the one-process batched
  env, the baseline of every ratio;
* ``sharded``: :class:`fcplan.env.vector_shards.ShardedVectorEnv` of the ``B`` worlds over
  ``P`` processes (this one and ``P - 1`` workers), with ``copy=True`` (its default) and
  ``copy=False`` (the observations left in the shared arrays).

``--expert greedy`` (any scheduler name) acts by a scheduler's plans instead: the one-process
expert in the ``independent`` processes (:class:`fcplan.env.vector_expert.BatchPlanFollower`,
``VectorTaskEnv.expert_actions``), the sharded one, which plans in every shard at once, on the
sharded env (:mod:`fcplan.env.vector_shard_experts`); the expert's time is inside the rate.

Each is reset, then stepped ``--steps`` times; the rate is ``B x steps`` over the wall-clock
time from the first process's first step to the last one's last. ``--rounds`` interleaved
rounds (default 3); the table gives the median rate and the median ratio to the baseline of
the same round with its range.

Usage::

    python bench/bench_vector_procs.py                          # about 2 minutes
    python bench/bench_vector_procs.py --procs 1 2 4 --worlds 256 --steps 600
    python bench/bench_vector_procs.py --level task --worlds 256 --steps 20
    python bench/bench_vector_procs.py --expert greedy --worlds 256 --steps 300
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from fcplan.env import vector_env
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_shard_experts import ShardedPlanFollower, ShardedTaskExpert
from fcplan.env.vector_shards import ShardedVectorEnv, shard_bounds
from fcplan.scheduling import deterministic_spec, make_scheduler
from fcplan.scheduling_batch import instances


def _actor(env: Any, level: str, expert: str | None, seed: int) -> Callable[[Any], Any]:
    """The actions of every step: random legal ones (drawn from the masks), or ``expert``'s
    plans (the one-process expert on a batched env, the sharded one on a sharded env)."""
    if expert is None:
        rng = np.random.default_rng(seed)
        return lambda obs: (rng.random(obs["action_mask"].shape) * obs["action_mask"]).argmax(2)
    if level == "motion":
        make = ShardedPlanFollower if isinstance(env, ShardedVectorEnv) else BatchPlanFollower
        follower = make(env, expert)
        return follower.actions
    schedulers = instances(lambda: make_scheduler(deterministic_spec(expert)), env.num_envs)
    if isinstance(env, ShardedVectorEnv):
        task_expert = ShardedTaskExpert(env, schedulers)
        return lambda obs: task_expert.actions()[0]
    return lambda obs: env.expert_actions(schedulers)[0]


def _play(env: Any, obs: Any, steps: int, act: Callable[[Any], Any]) -> None:
    """``steps`` steps of the actions ``act(obs)``."""
    for _ in range(steps):
        obs, *_ = env.step(act(obs))


def _shard(level: str, scenario: str, num: int, steps: int, seed: int, barrier: Any,
           out: Any, expert: str | None) -> None:  # fmt: skip
    """One process: make and reset its env, wait for the others, step; report when its steps
    started and ended (``time.perf_counter``: the system's monotonic clock, one for all
    processes)."""
    env = vector_env(scenario, mode=level, num_envs=num)
    act = _actor(env, level, expert, seed)
    obs, _ = env.reset(seed=seed)
    barrier.wait()
    start = time.perf_counter()
    _play(env, obs, steps, act)
    out.put((start, time.perf_counter()))


def run(level: str, scenario: str, worlds: int, procs: int, steps: int,
        expert: str | None = None) -> float:  # fmt: skip
    """Aggregate world-steps per wall-clock second of ``worlds`` worlds over ``procs`` processes
    (``worlds`` split as evenly as ``numpy.array_split`` splits)."""
    ctx = mp.get_context("spawn")  # (fresh interpreters: nothing inherited from this one)
    barrier, out = ctx.Barrier(procs + 1), ctx.Queue()
    ps = [
        ctx.Process(target=_shard, args=(level, scenario, hi - lo, steps, lo, barrier, out, expert))
        for lo, hi in shard_bounds(worlds, procs)
    ]
    for p in ps:
        p.start()
    barrier.wait()
    spans = [out.get() for _ in ps]
    start, end = min(s for s, _ in spans), max(e for _, e in spans)
    for p in ps:
        p.join()
    return worlds * steps / (end - start)


def sharded(level: str, scenario: str, worlds: int, procs: int, steps: int, copy: bool,
            expert: str | None = None) -> float:  # fmt: skip
    """World-steps per wall-clock second of a :class:`ShardedVectorEnv` of ``worlds`` worlds
    over ``procs`` processes."""
    env = vector_env(scenario, mode=level, num_envs=worlds, processes=procs, copy=copy,
                     context="spawn")  # fmt: skip
    try:
        act = _actor(env, level, expert, 0)
        obs, _ = env.reset(seed=0)
        start = time.perf_counter()
        _play(env, obs, steps, act)
        return worlds * steps / (time.perf_counter() - start)
    finally:
        env.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--level", choices=("motion", "task"), default="motion")
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--worlds", type=int, default=256, help="worlds B in all")
    ap.add_argument("--procs", type=int, nargs="+", default=[1, 2], help="process counts P")
    ap.add_argument("--steps", type=int, default=None, help="steps (default: 300 at the "
                    "motion level, 20 at the task level)")  # fmt: skip
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--expert", default=None, help="act by this scheduler's plans (e.g. greedy)")
    args = ap.parse_args(argv)
    steps = args.steps or (300 if args.level == "motion" else 20)
    procs = sorted({1, *args.procs})
    acts = f"actions of the {args.expert} expert" if args.expert else "random actions"
    print(f"# {args.level} level, scenario #{args.scenario}, B={args.worlds} worlds in all, "
          f"{steps} steps, {acts}; Python {platform.python_version()}, {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.2f}; median of {args.rounds} interleaved round(s)")  # fmt: skip
    rows = [("independent", p) for p in procs]
    rows += [(kind, p) for p in procs if p > 1 for kind in ("sharded", "sharded copy=False")]
    rates: dict[tuple[str, int], list[float]] = {r: [] for r in rows}
    for _ in range(args.rounds):
        for kind, p in rows:
            if kind == "independent":
                rate = run(args.level, args.scenario, args.worlds, p, steps, args.expert)
            else:
                copy = kind == "sharded"
                rate = sharded(args.level, args.scenario, args.worlds, p, steps, copy, args.expert)
            rates[kind, p].append(rate)
    base = np.array(rates["independent", 1])
    print(f"{'env':<20} {'processes':>9} {'world-steps/s':>14} {'ratio':>6}  [min, max]  (wall)")
    for kind, p in rows:
        r = np.array(rates[kind, p]) / base
        label = "one process" if p == 1 else kind
        print(f"{label:<20} {p:>9} {np.median(rates[kind, p]):>14.0f} {np.median(r):>6.2f}  "
              f"[{r.min():.2f}, {r.max():.2f}]")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
