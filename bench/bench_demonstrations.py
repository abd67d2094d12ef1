"""Benchmark ``demonstrations(...)``: episodes per wall second with worker processes (``jobs``)
and batched envs (``num_envs``), against one process and one env measured in the same run.

It records the same dataset (``--scheduler`` on ``--scenarios``, seeds ``0 .. --seeds - 1``,
``--max-steps`` task-level steps per episode) under every (``num_envs``, ``jobs``) of
``--configs``, in ``--rounds`` interleaved rounds (default 3: each round runs every
configuration once, so that the machine's changes of speed reach both sides of a ratio), checks
that every configuration gave the baseline's dataset (the first configuration's arrays), and
prints the median wall time, episodes per second and the median of the rounds' ratios to the
first configuration with their range. Wall clock: worker processes run beside this one. The
pool's start-up (fork of the workers) is inside the timed call, as a user sees it; one untimed
episode before the rounds warms the process up.

Usage::

    python bench/bench_demonstrations.py                          # about 3 minutes
    python bench/bench_demonstrations.py --configs 1x1 1x2 8x1 8x2 --seeds 16
    python bench/bench_demonstrations.py --scenarios 24 --max-steps 40 --rounds 5
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from fcplan.env.demonstrations import demonstrations


def _config(text: str) -> tuple[int, int]:
    """``"<num_envs>x<jobs>"``."""
    try:
        b, j = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected <num_envs>x<jobs>, got {text!r}") from None
    if b < 1 or j < 1:
        raise argparse.ArgumentTypeError(f"num_envs and jobs must be >= 1, got {text!r}")
    return b, j


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scheduler", default="greedy")
    ap.add_argument("--scenarios", nargs="+", default=["1", "24"])
    ap.add_argument("--seeds", type=int, default=16, help="seeds 0 .. n-1 of every scenario")
    ap.add_argument("--max-steps", type=int, default=30, help="task-level steps per episode")
    ap.add_argument("--configs", nargs="+", type=_config, default=[(1, 1), (1, 2), (8, 1), (8, 2)],
                    help="<num_envs>x<jobs> (the first is the baseline)")  # fmt: skip
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    scenarios = [int(s) if s.isdigit() else s for s in args.scenarios]
    seeds = list(range(args.seeds))
    kw = {"max_steps": args.max_steps}
    n_ep = len(scenarios) * len(seeds)
    walls: dict[tuple[int, int], list[float]] = {c: [] for c in args.configs}
    demonstrations(
        args.scheduler, scenarios, seeds[:1], env_kwargs=kw, progress=False
    )  # (warm-up, not timed: imports, caches)
    base = None
    for _ in range(args.rounds):
        for c in args.configs:
            t0 = time.perf_counter()
            demo = demonstrations(args.scheduler, scenarios, seeds, env_kwargs=kw,
                                  num_envs=c[0], jobs=c[1], progress=False)  # fmt: skip
            walls[c].append(time.perf_counter() - t0)
            if base is None:
                base = demo.arrays
            elif any(not np.array_equal(demo.arrays[k], v) for k, v in base.items()):
                raise SystemExit(f"num_envs={c[0]} jobs={c[1]}: not the baseline's dataset")
    print(f"# demonstrations({args.scheduler!r}, {args.scenarios}, {args.seeds} seeds, "
          f"max_steps={args.max_steps}): {n_ep} episodes; Python {platform.python_version()}, "
          f"{os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}; median of {args.rounds} "
          "interleaved round(s); every configuration gave the baseline's dataset")  # fmt: skip
    print(f"{'num_envs':>8} {'jobs':>4} {'wall s':>8} {'episodes/s':>10}  ratio   [min, max]")
    first = np.array(walls[args.configs[0]])
    for c in args.configs:
        w = np.array(walls[c])
        r = first / w
        print(f"{c[0]:>8} {c[1]:>4} {np.median(w):>8.2f} {n_ep / np.median(w):>10.2f}  "
              f"{np.median(r):.2f} [{r.min():.2f}, {r.max():.2f}]")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
