"""Benchmark the batched scheduling expert: world-steps per second of a motion-level rollout
driven by a scheduler's plans, batched against single, measured in the same run.

For a scenario (``--scenario``, default #1, ``--duration`` seconds per episode) it plays, in
``--rounds`` interleaved rounds (default 3):

* the single env with :class:`fcplan.env.motion_expert.PlanFollower` (``--episodes`` whole
  episodes, seeds 0, 1, ...), timing ``expert.actions`` and ``env.step``;
* :class:`fcplan.env.vector_motion.VectorMotionEnv` with
  :class:`fcplan.env.vector_expert.BatchPlanFollower` for every ``B`` of ``--sizes`` (one
  episode of every world), timing the same two calls;

and prints the median over the rounds of world-steps per CPU second (expert and env together),
the median ratio to the single rollout with its range over the rounds, and the expert's share of
the time (belief updates, replans with the scheduler, the move rule).

``--level task`` measures instead the task level's recorded rollouts, what
``demonstrations(..., num_envs=B)`` runs: :func:`fcplan.env.demo_episodes.rollout_episode` on
the single :class:`fcplan.env.task.TaskEnv` (a plan every step) against
:func:`fcplan.env.demo_episodes.batched_rollouts` on a
:class:`fcplan.env.vector_task.VectorTaskEnv` of ``B`` worlds (one episode each), whole calls
timed (no expert share).

``--apart`` adds, for every ``B``, a row with one scheduler instance per world, each world's
graph planned by its own call, as before greedy planned the worlds together
(:func:`fcplan.scheduling_batch.solve_batch`): what the batched call gains, in the same run.

Usage::

    python bench/bench_vector_expert.py                   # about 2 minutes
    python bench/bench_vector_expert.py --scheduler greedy --sizes 16 256 --rounds 5
    python bench/bench_vector_expert.py --level task --duration 30 --sizes 16 64
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from typing import Any

import numpy as np

from fcplan.env.demo_episodes import batched_rollouts, rollout_episode
from fcplan.env.motion import MotionEnv
from fcplan.env.motion_expert import PlanFollower
from fcplan.env.task import TaskEnv
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.scenario import load_scenario
from fcplan.scheduling import make_scheduler
from fcplan.scheduling_batch import instances

_CPU = time.thread_time


def single(sc: object, scheduler: str, episodes: int) -> tuple[float, float]:
    """(world-steps per CPU second, expert's share) of ``episodes`` single-env rollouts."""
    env = MotionEnv(sc)  # type: ignore[arg-type]
    expert = PlanFollower(env, scheduler)
    clock = [0.0, 0.0]
    steps = 0
    for ep in range(episodes):
        obs, _ = env.reset(seed=ep)
        expert.reset()
        while env.agents:
            obs = _step(expert, env, obs, clock)
            steps += 1
    return steps / clock[0], clock[1] / clock[0]


def _step(expert: Any, env: Any, obs: Any, clock: list[float]) -> Any:
    """One timed step: the expert's actions, then the env's step; add the CPU seconds of both
    to ``clock[0]`` and of the expert to ``clock[1]``; return the observations."""
    c = _CPU()
    act = expert.actions(obs)
    p = _CPU()
    obs = env.step(act)[0]
    clock[0] += _CPU() - c
    clock[1] += p - c
    return obs


def batched(sc: object, scheduler: str, num: int, apart: bool = False) -> tuple[float, float]:
    """(world-steps per CPU second, expert's share) of one episode of ``num`` worlds."""
    env = VectorMotionEnv(sc, num)  # type: ignore[arg-type]
    per_world = [make_scheduler(scheduler) for _ in range(num)]
    expert = BatchPlanFollower(env, per_world if apart else scheduler)
    obs, _ = env.reset(seed=0)
    clock = [0.0, 0.0]
    n_ticks = env.scenario.n_ticks
    for _ in range(n_ticks):
        obs = _step(expert, env, obs, clock)
    return num * n_ticks / clock[0], clock[1] / clock[0]


def single_task(sc: object, scheduler: str, episodes: int) -> tuple[float, float]:
    """(world-steps per CPU second, NaN) of ``episodes`` recorded task-level rollouts."""
    env = TaskEnv(sc)  # type: ignore[arg-type]
    sched = make_scheduler(scheduler)
    c, steps = _CPU(), 0
    for ep in range(episodes):
        steps += rollout_episode(env, sched, "bench", ep).steps
    return steps / (_CPU() - c), float("nan")


def batched_task(sc: object, scheduler: str, num: int, apart: bool = False) -> tuple[float, float]:
    """(world-steps per CPU second, NaN) of one recorded episode of ``num`` worlds."""
    env = VectorTaskEnv(sc, num, autoreset_mode="disabled")  # type: ignore[arg-type]
    scheds = (
        [make_scheduler(scheduler) for _ in range(num)]
        if apart
        else instances(lambda: make_scheduler(scheduler), num)
    )
    c = _CPU()
    steps = sum(r.steps for r in batched_rollouts(env, scheds, "bench", list(range(num))))
    return steps / (_CPU() - c), float("nan")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--scheduler", default="greedy")
    ap.add_argument("--duration", type=float, default=60.0, help="episode length (s)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[16, 64, 256])
    ap.add_argument("--episodes", type=int, default=2, help="single-env episodes per round")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--level", choices=["motion", "task"], default="motion")
    ap.add_argument("--apart", action="store_true",
                    help="also each B with one scheduler instance per world, called in turn")  # fmt: skip
    args = ap.parse_args(argv)
    one, many = (single, batched) if args.level == "motion" else (single_task, batched_task)
    sc = load_scenario(args.scenario).replace(duration_s=args.duration)
    rows_of = ["single"] + [f"B={n}" for n in args.sizes]
    if args.apart:
        rows_of += [f"B={n} apart" for n in args.sizes]
    runs: dict[str, list[tuple[float, float]]] = {k: [] for k in rows_of}
    for _ in range(args.rounds):
        runs["single"].append(one(sc, args.scheduler, args.episodes))
        for num in args.sizes:
            runs[f"B={num}"].append(many(sc, args.scheduler, num))
            if args.apart:
                runs[f"B={num} apart"].append(many(sc, args.scheduler, num, True))
    print(f"# scheduling expert ({args.scheduler}) on the {args.level} level, scenario "
          f"#{args.scenario}, {args.duration:g}-s episodes; Python {platform.python_version()}, "
          f"numpy {np.__version__}; load {os.getloadavg()[0]:.2f}; median of {args.rounds} "
          "interleaved round(s)")  # fmt: skip
    print(f"{'rollout':12s} {'world-steps/s':>14s} {'ratio':>6s} {'[min, max]':>12s} "
          f"{'expert share':>13s}")  # fmt: skip
    base = np.array([r for r, _ in runs["single"]])
    for label, rows in runs.items():
        r = np.array(rows)
        ratio = r[:, 0] / base
        print(f"{label:12s} {np.median(r[:, 0]):14.0f} {np.median(ratio):6.2f} "
              f"[{ratio.min():4.2f}, {ratio.max():4.2f}] {_share(r[:, 1]):>13s}")  # fmt: skip
    if args.apart:  # paired per round: the batched call against per-world calls
        pairs = []
        for n in args.sizes:
            q = np.array(runs[f"B={n}"])[:, 0] / np.array(runs[f"B={n} apart"])[:, 0]
            pairs.append(f"B={n} {np.median(q):.2f}x [{q.min():.2f}, {q.max():.2f}]")
        print("one batched call over one call per world, same round: " + ", ".join(pairs))
    return 0


def _share(shares: np.ndarray) -> str:
    return "-" if np.isnan(shares).any() else f"{100 * np.median(shares):.0f}%"


if __name__ == "__main__":
    raise SystemExit(main())
