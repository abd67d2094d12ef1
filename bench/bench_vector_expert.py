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

Usage::

    python bench/bench_vector_expert.py                   # about 2 minutes
    python bench/bench_vector_expert.py --scheduler greedy --sizes 16 256 --rounds 5
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from typing import Any

import numpy as np

from fcplan.env.motion import MotionEnv
from fcplan.env.motion_expert import PlanFollower
from fcplan.env.vector_expert import BatchPlanFollower
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.scenario import load_scenario

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


def batched(sc: object, scheduler: str, num: int) -> tuple[float, float]:
    """(world-steps per CPU second, expert's share) of one episode of ``num`` worlds."""
    env = VectorMotionEnv(sc, num)  # type: ignore[arg-type]
    expert = BatchPlanFollower(env, scheduler)
    obs, _ = env.reset(seed=0)
    clock = [0.0, 0.0]
    n_ticks = env.scenario.n_ticks
    for _ in range(n_ticks):
        obs = _step(expert, env, obs, clock)
    return num * n_ticks / clock[0], clock[1] / clock[0]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--scheduler", default="greedy")
    ap.add_argument("--duration", type=float, default=60.0, help="episode length (s)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[16, 64, 256])
    ap.add_argument("--episodes", type=int, default=2, help="single-env episodes per round")
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    sc = load_scenario(args.scenario).replace(duration_s=args.duration)
    runs: dict[int, list[tuple[float, float]]] = {0: [], **{n: [] for n in args.sizes}}
    for _ in range(args.rounds):
        runs[0].append(single(sc, args.scheduler, args.episodes))
        for num in args.sizes:
            runs[num].append(batched(sc, args.scheduler, num))
    print(f"# scheduling expert ({args.scheduler}) on the motion level, scenario "
          f"#{args.scenario}, {args.duration:g}-s episodes; Python {platform.python_version()}, "
          f"numpy {np.__version__}; load {os.getloadavg()[0]:.2f}; median of {args.rounds} "
          "interleaved round(s)")  # fmt: skip
    print(f"{'rollout':10s} {'world-steps/s':>14s} {'ratio':>6s} {'[min, max]':>12s} "
          f"{'expert share':>13s}")  # fmt: skip
    base = np.array([r for r, _ in runs[0]])
    for num, rows in runs.items():
        r = np.array(rows)
        ratio = r[:, 0] / base
        label = "single" if num == 0 else f"B={num}"
        print(f"{label:10s} {np.median(r[:, 0]):14.0f} {np.median(ratio):6.2f} "
              f"[{ratio.min():4.2f}, {ratio.max():4.2f}] {100 * np.median(r[:, 1]):12.0f}%")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
