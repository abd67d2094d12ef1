"""Benchmark the motion-level environment: steps per second with random legal and scheduler actions.

For scenarios #1 and #24 (``fcplan.env.motion.MotionEnv``) and the presets ``base``,
``cmplx1``, ``cmplx2`` it plays whole episodes with random legal actions (drawn from each
agent's ``action_mask``), and on #1 and #24 also with the greedy scheduler's plans followed move
by move (``greedy`` rows: :class:`fcplan.env.motion_expert.PlanFollower`, whose belief updates,
replans and action choices are the ``policy us`` column), and prints, per env step:

* ``steps/s``: ``env.step`` calls per second (choosing the actions is timed apart, ``policy us``);
* for the scenario envs, ``world us`` (the ``World.step`` inside) and ``env overhead us`` (the rest:
  action decoding, observation crops, masks and agent vectors for the whole team, reward);
* ``step+policy us``: choosing the actions and stepping, the whole cost of a step of the loop.
  Compare the ``greedy`` rows of two versions by this column: where the follower's belief update
  is counted (in ``policy us`` before the :class:`fcplan.mission.Mission` loop, inside
  ``env.step`` since, as the env's mission keeps the belief) moves time between the others;
* ``overhead, world stubbed``: the same episode replayed with ``World.step`` replaced by a stub
  that returns the recorded tick results, so ``env.step`` times the environment's own work
  alone (the figure least disturbed by other load on the machine).

Timings are the median over blocks of 100 steps (``best`` is the fastest block: on a loaded
machine it is the better estimate of the code's own cost). The baseline measured in the same run
is PettingZoo's MPE ``simple_spread`` (3 agents, random actions, the same timing), if ``mpe2``
(or an old ``pettingzoo.mpe``) is importable; otherwise the script says it skipped it. Install it
with ``pip install --no-deps mpe2`` (it asks for pygame-ce, which would replace the game's
pygame; it runs with either).

``--cpu`` times with the thread's CPU clock instead of the wall clock: time spent waiting for a
core is left out, so on a machine loaded by other processes the figures stay close to the quiet
machine's (cache and frequency effects remain). The issue's figures are wall-clock ones.

Usage::

    python bench/bench_env_motion.py            # about 30 s
    python bench/bench_env_motion.py --quick    # one episode each, shorter
    python bench/bench_env_motion.py --cpu      # CPU-time clock (a loaded machine)
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from fcplan.env.motion import MotionEnv, parallel_env
from fcplan.env.motion_expert import PlanFollower

BLOCK = 100
_CLOCKS = {"wall": time.perf_counter_ns, "cpu": time.thread_time_ns}
_clock = _CLOCKS["wall"]


class Timed:
    """Per-step timer of ``env.step``, and of ``World.step`` inside it when there is one."""

    def __init__(self) -> None:
        self.step_ns: list[int] = []
        self.world_ns: list[int] = []
        self.policy_ns: list[int] = []


def _sampler(env, rng: np.random.Generator):
    def draw(obs):
        out = {}
        for a in env.agents:
            o = obs[a]
            if isinstance(o, dict) and "action_mask" in o:
                legal = np.flatnonzero(o["action_mask"])
                out[a] = int(legal[rng.integers(legal.size)])
            else:
                out[a] = int(rng.integers(env.action_space(a).n))
        return out

    return draw


def run_env(make, episodes: int, max_steps: int, seed: int = 0, expert: str | None = None) -> Timed:
    """Play ``episodes`` episodes (at most ``max_steps`` steps each) and time every step, with
    random legal actions or, given a scheduler name, a :class:`PlanFollower` of its plans."""
    rec = Timed()
    env = make()
    follower = PlanFollower(env, expert) if expert else None
    draw = follower.actions if follower else _sampler(env, np.random.default_rng(seed))
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        if follower:
            follower.reset()
        world = getattr(env, "world", None)
        if world is not None:
            inner = type(world).step

            def timed(commands=None, _inner=inner, _world=world):
                t = _clock()
                out = _inner(_world, commands)
                rec.world_ns.append(_clock() - t)
                return out

            world.step = timed
        steps = 0
        while env.agents and steps < max_steps:
            t0 = _clock()
            actions = draw(obs)
            t1 = _clock()
            obs, *_ = env.step(actions)
            rec.step_ns.append(_clock() - t1)
            rec.policy_ns.append(t1 - t0)
            steps += 1
        if world is not None:
            del world.step
    env.close()
    return rec


def overhead_stubbed(make, seed: int = 0, repeats: int = 3) -> tuple[float, float]:
    """(median, best-block) us of ``env.step`` with ``World.step`` replaced by recorded results."""
    env = make()
    draw = _sampler(env, np.random.default_rng(seed))
    obs, _ = env.reset(seed=seed)
    world = env.world
    inner = type(world).step
    infos, actions = [], []

    def recording(commands=None):
        out = inner(world, commands)
        infos.append(out)
        return out

    world.step = recording
    while env.agents:
        actions.append(draw(obs))
        obs, *_ = env.step(actions[-1])
    del world.step
    ns: list[int] = []
    for _ in range(repeats):
        env.reset(seed=seed)
        world, replay = env.world, iter(infos)

        def stub(commands=None, _world=world, _replay=replay):
            _world.tick += 1
            return next(_replay)

        world.step = stub
        for a in actions[:-1]:  # the last step computes the final metrics
            t = _clock()
            env.step(a)
            ns.append(_clock() - t)
        del world.step
    return blocks_us(ns)


def blocks_us(ns: list[int]) -> tuple[float, float]:
    """(median, best) mean microseconds per step over blocks of BLOCK steps."""
    arr = np.asarray(ns, dtype=np.float64)
    k = max(len(arr) // BLOCK, 1)
    per = [float(b.mean()) / 1e3 for b in np.array_split(arr[: k * BLOCK] if k > 1 else arr, k)]
    return statistics.median(per), min(per)


def mpe_env():
    """MPE simple_spread (3 agents) as a parallel env, or None if MPE is not installed."""
    for mod in ("mpe2", "pettingzoo.mpe"):
        try:
            m = __import__(mod, fromlist=["simple_spread_v3"])
            return m.simple_spread_v3.parallel_env
        except Exception:  # noqa: BLE001 - any import failure means "not available"
            continue
    return None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one episode each")
    ap.add_argument("--cpu", action="store_true", help="time with the thread's CPU clock")
    args = ap.parse_args(argv)
    global _clock
    _clock = _CLOCKS["cpu" if args.cpu else "wall"]
    eps = 1 if args.quick else 3
    print(f"# motion env, random legal actions; Python {platform.python_version()}, numpy "
          f"{np.__version__}; load {os.getloadavg()[0]:.2f}")  # fmt: skip
    print(f"# us per step: median (best) over blocks of {BLOCK} steps; "
          f"clock: {'thread CPU time' if args.cpu else 'wall'}")  # fmt: skip
    header = (
        f"{'env':22s} {'agents':>6s} {'steps':>6s} {'steps/s':>14s} {'env.step us':>14s} "
        f"{'world us':>14s} {'env overhead us':>16s} {'policy us':>9s} {'step+policy us':>14s}"
    )
    print(header)
    rows = {}
    cases = [
        ("motion #1", lambda: MotionEnv(1), 1800),
        ("motion #24", lambda: MotionEnv(24), 1800),
        ("motion #1 greedy", lambda: MotionEnv(1), 1800),
        ("motion #24 greedy", lambda: MotionEnv(24), 1800),
        ("preset base", lambda: parallel_env(preset="base"), 1000),
        ("preset cmplx1", lambda: parallel_env(preset="cmplx1"), 200),
        ("preset cmplx2", lambda: parallel_env(preset="cmplx2"), 200),
    ]
    for name, make, cap in cases:
        n_eps = eps if cap >= 1000 else eps * 3
        rec = run_env(make, n_eps, cap, expert="greedy" if name.endswith("greedy") else None)
        st_med, st_best = blocks_us(rec.step_ns)
        pol, _ = blocks_us(rec.policy_ns)
        both, _ = blocks_us([s + p for s, p in zip(rec.step_ns, rec.policy_ns, strict=True)])
        n_agents = len(make().possible_agents)
        if rec.world_ns:
            w_med, w_best = blocks_us(rec.world_ns)
            over = [s - w for s, w in zip(rec.step_ns, rec.world_ns, strict=True)]
            o_med, o_best = blocks_us(over)
            wcol = f"{w_med:7.1f} ({w_best:5.1f})"
            ocol = f"{o_med:7.1f} ({o_best:5.1f})"
        else:
            wcol = ocol = "-"
        rate = f"{1e6 / st_med:7.0f} ({1e6 / st_best:5.0f})"
        print(
            f"{name:22s} {n_agents:6d} {len(rec.step_ns):6d} {rate:>14s} "
            f"{st_med:7.1f} ({st_best:5.1f}) {wcol:>14s} {ocol:>16s} {pol:9.1f} {both:14.1f}"
        )
        rows[name] = st_med
    for name, sc in (("motion #1", 1), ("motion #24", 24)):
        med, best = overhead_stubbed(lambda sc=sc: MotionEnv(sc))
        print(f"{name}: env overhead with World.step stubbed {med:.1f} us ({best:.1f} best block)")
    make_mpe = mpe_env()
    if make_mpe is None:
        print(
            "MPE simple_spread: skipped (pip install --no-deps mpe2: its pygame-ce dependency "
            "would replace the game's pygame)"
        )
    else:
        rec = run_env(lambda: make_mpe(N=3, max_cycles=25), 40 * eps, 25)
        st_med, st_best = blocks_us(rec.step_ns)
        print(
            f"{'MPE simple_spread':22s} {3:6d} {len(rec.step_ns):6d} "
            f"{1e6 / st_med:7.0f} ({1e6 / st_best:5.0f}) {st_med:7.1f} ({st_best:5.1f})"
        )
        for name, med in rows.items():
            print(f"  {name}: {st_med / med:.2f}x MPE simple_spread's steps/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
