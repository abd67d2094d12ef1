"""Benchmark copies of environments: ``copy.deepcopy`` and a ``pickle`` round trip of the single
and batched envs of both levels, against one step of the same env, measured in the same rounds.

For each configuration (single motion, single task, batched motion and batched task of
``--worlds`` worlds, on ``--scenario``), the env is reset and stepped ``--warm`` times with
random legal actions (so fires, beliefs and task graphs hold something), then each round times,
on the process's CPU clock and interleaved: one ``step`` (the median of ``--steps`` steps from
the copied state), one ``copy.deepcopy`` and one ``pickle.loads(pickle.dumps(...))``. The table
gives the medians over ``--rounds`` rounds, the copy's cost in env steps, and the pickle's size.
Every copy is checked to step as the original on the next step (the tests check many more
steps; ``tests/env/test_env_copies.py``).

Usage::

    python bench/bench_copies.py                     # about a minute
    python bench/bench_copies.py --worlds 256 --rounds 3
"""

from __future__ import annotations

import argparse
import copy
import os
import pickle
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from fcplan.env import parallel_env, vector_env


def _actions(env: Any, rng: np.random.Generator, obs: Any) -> Any:
    """Random legal actions from the masks (a batch's, or every agent's of a single env)."""
    if hasattr(env, "num_envs"):
        m = obs["action_mask"]
        return (rng.random(m.shape) * m).argmax(axis=2)
    return {a: int((rng.random(o["action_mask"].shape) * o["action_mask"]).argmax())
            for a, o in obs.items()}  # fmt: skip


def _cpu(fn: Callable[[], Any]) -> tuple[float, Any]:
    t = time.process_time()
    out = fn()
    return time.process_time() - t, out


def _same_step(a: Any, b: Any, act: Any) -> bool:
    """The original and a copy give the same rewards and observations on ``act``."""
    ra, rb = a.step(act), b.step(act)
    if hasattr(a, "num_envs"):
        return all(np.array_equal(ra[0][k], rb[0][k]) for k in ra[0]) and np.array_equal(
            ra[1], rb[1]
        )
    return ra[1] == rb[1] and all(
        np.array_equal(ra[0][g][k], rb[0][g][k]) for g in ra[0] for k in ra[0][g]
    )


def measure(make: Callable[[], Any], warm: int, steps: int, rounds: int) -> dict[str, float]:
    """Median CPU seconds of a step, a deep copy and a pickle round trip, and the pickle's
    bytes (module docstring)."""
    env = make()
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(warm):
        obs, *_ = env.step(_actions(env, rng, obs))
    step_t, deep_t, pick_t = [], [], []
    size = 0
    for _ in range(rounds):
        work = copy.deepcopy(env)
        o = obs
        ts = []
        for _ in range(steps):
            if hasattr(work, "agents") and not work.agents:
                break
            t, out = _cpu(lambda w=work, o=o: w.step(_actions(w, rng, o)))
            ts.append(t)
            o = out[0]
        step_t.append(float(np.median(ts)))
        t, twin = _cpu(lambda: copy.deepcopy(env))
        deep_t.append(t)
        t, blob = _cpu(lambda: pickle.dumps(env))
        t2, back = _cpu(lambda b=blob: pickle.loads(b))
        pick_t.append(t + t2)
        size = len(blob)
        act = _actions(env, rng, obs)
        if not (_same_step(copy.deepcopy(env), twin, act) and _same_step(env, back, act)):
            raise SystemExit("a copy did not step as the original")
    return {
        "step": float(np.median(step_t)),
        "deepcopy": float(np.median(deep_t)),
        "pickle": float(np.median(pick_t)),
        "bytes": float(size),
    }


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="1")
    ap.add_argument("--worlds", type=int, default=64)
    ap.add_argument("--warm", type=int, default=5, help="steps before the copies")
    ap.add_argument("--steps", type=int, default=5, help="steps timed per round")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args(argv)
    sc, b = args.scenario, args.worlds
    configs = {
        "single motion": lambda: parallel_env(sc, mode="motion"),
        "single task": lambda: parallel_env(sc, mode="task"),
        f"batched motion B={b}": lambda: vector_env(sc, mode="motion", num_envs=b),
        f"batched task B={b}": lambda: vector_env(sc, mode="task", num_envs=b),
    }
    print(f"# copies of envs, scenario #{sc}; Python {platform.python_version()}, numpy "
          f"{np.__version__}, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}; median of "
          f"{args.rounds} round(s), CPU ms")  # fmt: skip
    print(f"{'env':24s} {'step':>9s} {'deepcopy':>9s} {'(steps)':>8s} {'pickle':>9s} "
          f"{'(steps)':>8s} {'pickled MB':>11s}")  # fmt: skip
    for name, make in configs.items():
        m = measure(make, args.warm, args.steps, args.rounds)
        print(f"{name:24s} {m['step'] * 1e3:9.2f} {m['deepcopy'] * 1e3:9.2f} "
              f"{m['deepcopy'] / m['step']:8.1f} {m['pickle'] * 1e3:9.2f} "
              f"{m['pickle'] / m['step']:8.1f} {m['bytes'] / 1e6:11.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
