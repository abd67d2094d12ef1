"""Benchmark the task-level environment (issue 4): steps per second and where the time goes.

For scenarios #1 and #24, whole episodes (180 steps of 1 s = 10 ticks each):

* ``random``: uniformly random legal actions (drawn from the masks);
* ``greedy``: the greedy scheduler's plans mapped to actions (as ``fcplan.env.demonstrations``
  does); the scheduler's own time is reported apart and excluded from env steps/s.

Time per step is split into: the simulator (``World.step`` + ``Belief.update`` for the step's
ticks, plus the reward sum), the task graph (``TaskGraphBuilder.build``), and the env's own code
(candidates with the graph's distance tables, masks, feature tables, decoding actions, the
validity check, commands, observation and info dicts). Baseline measured in the same run: the bare replan loop
without any env (the same ticks and graph builds, commands from the same recorded plans), whose
steps/s is the ceiling the env can reach; the env's overhead is also measured with
``validate=False``.

Usage::

    python bench/bench_env.py            # 2 episodes per case
    python bench/bench_env.py --quick    # 1 episode per case
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from fcplan import load_scenario, make_scheduler
from fcplan.belief import Belief
from fcplan.env.task import TaskEnv
from fcplan.env.task_actions import plan_to_actions
from fcplan.plan import plan_commands
from fcplan.taskgraph import TaskGraphBuilder
from fcplan.world import World


class _Timer:
    """Accumulates the wall time of wrapped calls."""

    def __init__(self) -> None:
        self.total = 0.0

    def wrap(self, fn):
        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.total += time.perf_counter() - t0

        return timed


def run_env(scenario, policy: str, episodes: int, *, validate: bool = True) -> dict:
    """Play ``episodes`` episodes; return totals (s) and step counts."""
    sim, graph, sched_t = _Timer(), _Timer(), _Timer()
    orig_build, orig_adv = TaskGraphBuilder.build, TaskEnv._advance
    TaskGraphBuilder.build = graph.wrap(orig_build)  # type: ignore[method-assign]
    TaskEnv._advance = sim.wrap(orig_adv)
    try:
        env = TaskEnv(scenario, k=8, validate=validate)
        sched = make_scheduler("greedy")
        steps = 0
        wall = reset_t = step_t = 0.0
        for ep in range(episodes):
            rng = np.random.default_rng(ep)
            t0 = time.perf_counter()
            env.reset(seed=ep)
            reset_t += time.perf_counter() - t0
            ids = env.possible_agents
            while env.agents:
                if policy == "random":
                    u = rng.random(env._mask.shape) * env._mask
                    act = np.argmax(u, axis=1)
                else:
                    t1 = time.perf_counter()
                    plan = sched.plan(env.graph, time_limit=None, rng=env.world.controller_rng)
                    act = plan_to_actions(plan, env.graph, env.candidates)
                    sched_t.total += time.perf_counter() - t1
                actions = dict(zip(ids, act.tolist(), strict=True))
                t2 = time.perf_counter()
                env.step(actions)
                step_t += time.perf_counter() - t2
                steps += 1
            wall += time.perf_counter() - t0
    finally:
        TaskGraphBuilder.build, TaskEnv._advance = orig_build, orig_adv  # type: ignore[method-assign]
    return {
        "steps": steps,
        "wall": wall,
        "sim": sim.total,
        "graph": graph.total,
        "sched": sched_t.total,
        "reset": reset_t,
        "step": step_t,
    }


def run_bare(scenario, episodes: int) -> dict:
    """The replan loop without the env: world + belief every tick, a graph every 10 ticks,
    the greedy plan's commands (scheduler time excluded)."""
    sched = make_scheduler("greedy")
    steps, wall, sched_t = 0, 0.0, 0.0
    for ep in range(episodes):
        t0 = time.perf_counter()
        world = World().reset(scenario, ep)
        belief = Belief(scenario)
        builder = TaskGraphBuilder(scenario)
        while not world.done:
            g = builder.build(world.team, belief)
            t1 = time.perf_counter()
            plan = sched.plan(g, time_limit=None, rng=world.controller_rng)
            sched_t += time.perf_counter() - t1
            commands = plan_commands(plan, g)
            for _ in range(10):
                if world.done:
                    break
                belief.update(world.step(commands))
                commands = None
            steps += 1
        wall += time.perf_counter() - t0
    return {"steps": steps, "wall": wall - sched_t}


def hot_parts(scenario, steps: int = 60) -> dict[str, float]:
    """Best-of-7 microseconds of each part of the env's own code on one mid-episode state (hot
    caches: the robust figure on a loaded machine). Candidates are ranked on a freshly built
    graph each time (minus the build), so the graph's lazily computed distance tables are
    counted as they are in an episode."""
    from fcplan.env.task_actions import actions_commands, decode_actions
    from fcplan.env.task_candidates import agent_features, rank_candidates, task_features

    env = TaskEnv(scenario, k=8)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    for _ in range(steps):
        u = rng.random(env._mask.shape) * env._mask
        env.step(dict(zip(env.possible_agents, np.argmax(u, axis=1).tolist(), strict=True)))
    g, c, goal = env.graph, env.candidates, env._goal
    team, belief = env.world.team, env.belief
    act = np.argmax(rng.random(env._mask.shape) * env._mask, axis=1)
    rows = decode_actions(g, c, act)[0]
    sent = np.flatnonzero(rows >= 0)

    def best(fn, n: int = 300) -> float:
        out = []
        for _ in range(7):
            t0 = time.perf_counter()
            for _ in range(n):
                fn()
            out.append((time.perf_counter() - t0) / n * 1e6)
        return min(out)

    builder = env.mission.graph_builder
    build = best(lambda: builder.build(team, belief))
    fresh = best(lambda: rank_candidates(builder.build(team, belief), 8))
    return {
        "candidates": fresh - build,
        "task features": best(lambda: task_features(g, c, goal)),
        "agent features": best(lambda: agent_features(g, c, 0.5)),
        "mask": best(c.action_mask),
        "decode actions": best(lambda: decode_actions(g, c, act)),
        "validity check": best(lambda: c.legal[sent, rows[sent]].all()),
        "commands": best(lambda: actions_commands(g, rows)),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one episode per case")
    args = ap.parse_args()
    episodes = 1 if args.quick else 2
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"python {platform.python_version()}, numpy {np.__version__}, load {load:.2f}")
    print("task-level env (k=8, 1 s = 10 ticks per step), whole 180-step episodes")
    hdr = (
        f"{'scenario':>8} {'actions':>8} {'steps/s':>8} {'bare/s':>7} {'sim us':>7} "
        f"{'graph us':>8} {'env us':>7} {'env us*':>7} {'sched us':>8} {'env %':>6}"
    )
    print(hdr)
    for name in (1, 24):
        sc = load_scenario(name)
        TaskEnv(sc).reset(seed=0)  # warm imports and caches
        bare = run_bare(sc, episodes)
        for policy in ("random", "greedy"):
            r = run_env(sc, policy, episodes)
            nv = run_env(sc, policy, episodes, validate=False)
            n = r["steps"]
            env_wall = r["wall"] - r["sched"]
            # the env's own code inside step() (the reset's graph build is in "graph" too: 1/180)
            own = r["step"] - r["sim"] - r["graph"]
            own_nv = nv["step"] - nv["sim"] - nv["graph"]
            print(
                f"{name:>8} {policy:>8} {n / env_wall:8.0f} {bare['steps'] / bare['wall']:7.0f} "
                f"{r['sim'] / n * 1e6:7.0f} {r['graph'] / n * 1e6:8.0f} {own / n * 1e6:7.0f} "
                f"{own_nv / nv['steps'] * 1e6:7.0f} {r['sched'] / n * 1e6:8.0f} "
                f"{100 * own / env_wall:5.1f}% {r['reset'] / episodes * 1e3:8.1f}"
            )
    for name in (1, 24):
        parts = hot_parts(load_scenario(name))
        total = sum(parts.values())
        detail = ", ".join(f"{k} {v:.0f}" for k, v in parts.items())
        print(f"#{name} env code, hot caches (best of 7): {total:.0f} us/step = {detail}")
    print(
        "steps/s: env steps per second excluding the scheduler; bare/s: the same loop without "
        "the env (baseline, greedy commands); sim: World.step + Belief.update per step; graph: "
        "build_task_graph per step; env: the env's own code per step (env*: with validate=False); "
        "env %: share of the env's wall time spent in its own code; reset: ms per reset()"
    )


if __name__ == "__main__":
    main()
