"""Benchmark the batched motion level: world-steps per second against the single env, same run.

For scenarios #1 and #24 it plays, with random legal actions (drawn from the action masks; the
draw is not timed):

* the single env (:class:`fcplan.env.motion.MotionEnv`), ``--episodes`` whole episodes, timing
  ``env.step`` only (resets excluded), and inside it the simulator (``Mission.step``);
* :class:`fcplan.env.vector_motion.VectorMotionEnv` with ``B`` worlds for every ``B`` of
  ``--sizes`` (default 1, 16, 64, 256, 1024), one whole episode of every world (the worlds start
  together: ``n_ticks`` steps, next-step autoreset of all of them at the end included), timing
  ``env.step`` and inside it the batched simulator (``BatchWorld.step``);
* for every ``B`` of ``--sync-sizes`` (default 4, 16), what a learner gets without the batched
  simulator: Gymnasium's ``SyncVectorEnv`` of the single env (``gymnasium.make_vec(...,
  vectorization_mode="sync")``, the same worlds), one whole episode of every world, timing its
  ``step``.

The measurements are interleaved in ``--rounds`` rounds (default 3): each round plays every
``B``, then the sync vector envs, with a run of the single env before each of them and one after
the last, and every ratio is taken against the mean of the two single-env runs that bracket it,
so that a change of the machine's speed during the run (it is shared: the single env's own rate
was seen to vary 1.7x between two runs of the same command, and a round's ratio at ``B`` = 256
to range from 4.2x to 8.5x when one single-env run at the start of each round was the only
baseline) reaches both sides of a ratio. It prints the median over the rounds of world-steps
per second (``B`` x steps / time; the single env's over all its runs) on the thread's CPU clock
and on the wall clock with the load average, the median of the rounds' ratios to the single env
of the same scenario with their range, the simulator alone (its ratio too), the batched env
over the sync one at the same ``B``, where the time of a batched step goes at the largest ``B`` (simulator parts, observations,
action decoding, rewards), and the memory per world of each level: allocated (``tracemalloc``:
the growth from 16 to 256 worlds after 5 steps, per added world; the tables every world shares
are the rest) and resident (the growth of the peak resident size of a fresh process playing one
whole episode, from 16 to 256 worlds: the batched belief's maps are paged in only where written).

Usage::

    python bench/bench_vector.py                       # about 8 minutes on a quiet 2-core machine
    python bench/bench_vector.py --rounds 1            # one round, about 3 minutes
    python bench/bench_vector.py --quick               # 30-s episodes, sizes 1, 16, 256
    python bench/bench_vector.py --plot vector.png     # also plot throughput against B
    python bench/bench_vector.py --duration 60         # 60-s episodes (a loaded machine)
"""

from __future__ import annotations

import argparse
import collections
import gc
import os
import platform
import subprocess
import sys
import time
import tracemalloc
from collections.abc import Callable
from typing import Any

import gymnasium
import numpy as np

import fcplan.batch.fire as bfire
import fcplan.batch.world as bworld
import fcplan.env  # noqa: F401  (registers the fcplan/ ids for the sync vector envs)
import fcplan.env.vector_motion as vmotion
import fcplan.env.vector_obs as vobs
import fcplan.env.vector_task as vtask
from fcplan.env.gym_view import TaskGymEnv
from fcplan.env.motion import MotionEnv
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.scenario import load_scenario

_CPU, _WALL = time.thread_time, time.perf_counter


class Clock:
    """CPU and wall seconds of timed sections."""

    def __init__(self) -> None:
        self.cpu: collections.Counter = collections.Counter()
        self.wall: collections.Counter = collections.Counter()

    def wrap(self, owner: Any, name: str, label: str) -> Callable[[], None]:
        """Time every call of ``owner.name`` under ``label``; return the undo function."""
        inner = getattr(owner, name)

        def timed(*a: Any, **k: Any) -> Any:
            c, w = _CPU(), _WALL()
            out = inner(*a, **k)
            self.cpu[label] += _CPU() - c
            self.wall[label] += _WALL() - w
            return out

        setattr(owner, name, timed)
        return lambda: setattr(owner, name, inner)

    def step(self, fn: Callable[..., Any], *args: Any) -> Any:
        """``fn(*args)``, timed under ``"step"``."""
        c, w = _CPU(), _WALL()
        out = fn(*args)
        self.cpu["step"] += _CPU() - c
        self.wall["step"] += _WALL() - w
        return out


def single_env(sc: Any, episodes: int, seed: int = 0) -> tuple[int, Clock]:
    """Steps of ``episodes`` episodes of the single env with random legal actions, timed."""
    env = MotionEnv(sc)
    rng = np.random.default_rng(seed)
    clock, steps = Clock(), 0
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        undo = clock.wrap(env.mission, "step", "sim")
        while env.agents:
            act = {a: int(rng.choice(np.flatnonzero(obs[a]["action_mask"]))) for a in env.agents}
            obs, *_ = clock.step(env.step, act)
            steps += 1
        undo()
    return steps, clock


_PARTS = [
    (bworld.BatchWorld, "step", "sim"),
    (bworld.BatchWorld, "_fire_steps", "sim: fire"),
    (bfire.BatchFire, "_refill_worlds", "sim: fire: wind blocks"),
    (bfire.BatchFire, "_terrain", "sim: fire: terrain"),
    (bfire.BatchFire, "ignite", "sim: fire: ignition"),
    (bworld.BatchWorld, "_sense", "sim: sensing"),
    (bworld.BatchWorld, "_prune", "sim: dumps"),
    (bworld.BatchWorld, "_record", "sim: trace rows"),
    (vobs.BatchMotionObs, "update", "obs: map updates"),
    (vobs.BatchMotionObs, "observe", "obs: observe"),
    (vobs.BatchMotionObs, "agent_arrays", "obs: observe: agent vectors, masks"),
    (vmotion.VectorMotionEnv, "_decode", "actions"),
    (vmotion.VectorMotionEnv, "_rewards", "rewards"),
]


def batched_env(sc: Any, num: int, *, parts: bool, seed: int = 0) -> tuple[int, Clock]:
    """World-steps of one whole motion-level episode of ``num`` worlds (and the autoreset
    step), timed."""
    return _batched(VectorMotionEnv(sc, num), sc.n_ticks + 1, _PARTS if parts else _PARTS[:1], seed)


def sync_env(sc: Any, num: int, level: str, seed: int = 0) -> tuple[int, Clock]:
    """World-steps of one whole episode of ``num`` worlds of Gymnasium's ``SyncVectorEnv`` of the
    single env (``fcplan/Motion-v0`` or ``fcplan/Task-v1``), timed (``step`` only)."""
    env_id = "fcplan/Motion-v0" if level == "motion" else "fcplan/Task-v1"
    env = gymnasium.make_vec(env_id, num, vectorization_mode="sync", scenario=sc)
    n_steps = sc.n_ticks + 1 if level == "motion" else VectorTaskEnv(sc, 1).one.max_steps + 1
    return _batched(env, n_steps, [], seed)


def _batched(env: Any, n_steps: int, parts: list, seed: int) -> tuple[int, Clock]:
    """``n_steps`` steps of a batched env with random legal actions, ``parts`` timed too."""
    rng = np.random.default_rng(seed)
    clock = Clock()
    undo = [clock.wrap(o, n, lab) for o, n, lab in parts]
    obs, _ = env.reset(seed=seed)
    for _ in range(n_steps):
        m = obs["action_mask"]
        obs, *_ = clock.step(env.step, (rng.random(m.shape) * m).argmax(axis=2))
    for u in undo:
        u()
    clock.cpu["sim"] = clock.cpu["sim"] or np.nan  # (a sync env's simulator is not timed apart)
    return env.num_envs * n_steps, clock


def copy_floor(shape: tuple[int, ...], repeats: int = 20) -> float:
    """CPU seconds of copying one float32 array of ``shape`` into another (best of
    ``repeats``): the least a step can cost that writes an observation of that shape."""
    src = np.random.default_rng(0).random(shape, dtype=np.float32)
    dst = np.empty_like(src)
    best = np.inf
    for _ in range(repeats):
        c = _CPU()
        np.copyto(dst, src)
        best = min(best, _CPU() - c)
    return best


def memory_per_world(sc: Any, small: int, large: int, level: str = "motion") -> tuple[float, float]:
    """(bytes per added world, bytes of the rest) of a stepped batched env, by tracemalloc."""
    sizes = []
    make = VectorMotionEnv if level == "motion" else VectorTaskEnv
    for num in (small, large):
        gc.collect()
        tracemalloc.start()
        env = make(sc, num)
        obs, _ = env.reset(seed=0)
        for _ in range(5):
            m = obs["action_mask"]
            obs, *_ = env.step((m * np.arange(m.shape[2])).argmax(axis=2))
        sizes.append(tracemalloc.get_traced_memory()[0])
        tracemalloc.stop()
        del env, obs
    per = (sizes[1] - sizes[0]) / (large - small)
    return per, sizes[0] - small * per


#: the child of :func:`resident_per_world`: one whole episode, then its peak resident size
_PEAK_RSS = """
import resource, sys
import numpy as np
from fcplan.env.vector_motion import VectorMotionEnv
from fcplan.env.vector_task import VectorTaskEnv
from fcplan.scenario import load_scenario
name, duration, num, level = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
sc = load_scenario(name)
sc = sc.replace(duration_s=duration) if duration > 0 else sc
env = (VectorMotionEnv if level == "motion" else VectorTaskEnv)(sc, num)
rng = np.random.default_rng(0)
obs, _ = env.reset(seed=0)
while True:
    m = obs["action_mask"]
    obs, _, _, truncs, _ = env.step((rng.random(m.shape) * m).argmax(axis=2))
    if truncs.all():
        break
try:  # (Linux: this process's own peak; ru_maxrss keeps a larger parent's across fork and exec)
    status = open("/proc/self/status").read()
    print(int(status.split("VmHWM:")[1].split()[0]) * 1024)
except OSError:
    scale = 1 if sys.platform == "darwin" else 1024
    print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * scale)
"""


def resident_per_world(name: str, duration: float, small: int, large: int, level: str) -> float:
    """Bytes of peak resident memory per added world: a fresh process per size plays one whole
    episode of every world with random legal actions (its peak resident size: ``VmHWM`` of
    ``/proc/self/status``, else ``resource``'s ``ru_maxrss``, which on Linux a child inherits
    from a larger parent), and the growth from ``small`` to ``large`` worlds is divided by the
    worlds added. Unlike the traced figure, pages allocated but never written do not count."""
    peaks = []
    for num in (small, large):
        cmd = [sys.executable, "-c", _PEAK_RSS, name, str(duration), str(num), level]
        out = subprocess.run(cmd, capture_output=True, text=True, check=True)
        peaks.append(int(out.stdout.split()[-1]))
    return (peaks[1] - peaks[0]) / (large - small)


#: what the memory shared by the worlds of a level holds
_SHARED = {
    "motion": "terrain jump tables, maps, team constants",
    "task": "the motion level's and the task level's scenario tables",
}


def single_task(sc: Any, episodes: int, seed: int = 0) -> tuple[int, Clock]:
    """Steps of ``episodes`` episodes of ``fcplan/Task-v1`` with random legal actions, timed."""
    env = TaskGymEnv(sc)
    rng = np.random.default_rng(seed)
    clock, steps = Clock(), 0
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        undo = clock.wrap(env.env.mission.world, "step", "sim")
        done = False
        while not done:
            m = obs["action_mask"]
            obs, _, _, done, _ = clock.step(env.step, (rng.random(m.shape) * m).argmax(axis=1))
            steps += 1
        undo()
    return steps, clock


_TASK_PARTS = [
    (bworld.BatchWorld, "step", "sim"),
    (vtask.VectorTaskEnv, "_beliefs", "beliefs (batched)"),
    (vtask.VectorTaskEnv, "_observe", "graph, candidates, features"),
    (vtask.BatchBelief, "views", "  belief reads (coverage ages)"),
    (vtask, "build_graphs", "  graphs (build_graphs)"),
    (vtask.TaskGraphBuilder, "build", "  graphs: builder's own path (no fire)"),
    (vtask, "batch_observe", "  candidates, features (batched)"),
    (vtask.VectorTaskEnv, "_commands", "actions to commands (batched)"),
    (vtask.VectorTaskEnv, "_rewards", "rewards"),
]


def batched_task(sc: Any, num: int, *, parts: bool, seed: int = 0) -> tuple[int, Clock]:
    """World-steps of one whole task-level episode of ``num`` worlds (and the autoreset step)."""
    env = VectorTaskEnv(sc, num)
    return _batched(env, env.one.max_steps + 1, _TASK_PARTS if parts else _TASK_PARTS[:1], seed)


def mpe_rate(steps: int = 5000, seed: int = 0) -> float | None:
    """Steps per CPU second of PettingZoo MPE ``simple_spread`` (3 agents, random actions,
    25-step episodes), or None when ``mpe2`` is not installed (``pip install --no-deps mpe2``)."""
    try:
        from mpe2 import simple_spread_v3
    except ImportError:
        return None
    env = simple_spread_v3.parallel_env(N=3, max_cycles=25)
    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    busy, n = 0.0, 0
    while n < steps:
        if not env.agents:
            env.reset()
        act = {a: int(rng.integers(env.action_space(a).n)) for a in env.agents}
        c = _CPU()
        env.step(act)
        busy += _CPU() - c
        n += 1
    return n / busy


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="30-s episodes, sizes 1, 16, 256")
    ap.add_argument("--duration", type=float, default=None, help="episode length (s)")
    ap.add_argument("--sizes", type=int, nargs="+", default=None, help="batch sizes B")
    ap.add_argument("--episodes", type=int, default=2, help="single-env episodes")
    ap.add_argument("--sync-sizes", type=int, nargs="*", default=[4, 16],
                    help="B of the SyncVectorEnv of the single env measured too")  # fmt: skip
    ap.add_argument("--scenarios", nargs="+", default=["1", "24"])
    ap.add_argument("--levels", nargs="+", default=["motion", "task"], choices=["motion", "task"])
    ap.add_argument("--task-max", type=int, default=256, help="largest B at the task level")
    ap.add_argument("--plot", default=None, help="write a plot of throughput against B here")
    ap.add_argument(
        "--rounds", type=int, default=3, help="interleaved rounds (the single env, then every B)"
    )
    args = ap.parse_args(argv)
    sizes = args.sizes or ([1, 16, 256] if args.quick else [1, 4, 16, 64, 256, 1024])
    print(f"# batched motion level, random legal actions; Python {platform.python_version()}, "
          f"numpy {np.__version__}; load average at start {os.getloadavg()[0]:.2f}")  # fmt: skip
    print("# world-steps/s on the thread CPU clock (wall clock); ratio = CPU-time world-steps/s "
          "over the single env's in this run")  # fmt: skip
    results: dict[str, list[tuple[int, float]]] = {}
    for level in args.levels:
        for name in args.scenarios:
            sc = load_scenario(name)
            if args.quick or args.duration:
                sc = sc.replace(duration_s=args.duration or 30)
            sizes_l = [n for n in sizes if level == "motion" or n <= args.task_max]
            results[f"{level} #{name}"] = _level(
                level, sc, name, sizes_l, args.episodes, args.rounds, args.sync_sizes
            )
    sc = load_scenario(args.scenarios[0])
    print()
    for level in args.levels:
        large = 64 if args.quick else 256
        if level == "task":
            large = min(large, args.task_max)
        per, rest = memory_per_world(sc, 16, large, level)
        print(
            f"memory, {level} level (#{args.scenarios[0]}, traced): {per / 1e6:.3f} MB per "
            f"world, {rest / 1e6:.1f} MB shared ({_SHARED[level]})"
        )
        dur = (args.duration or 30) if args.quick or args.duration else 0.0
        res = resident_per_world(args.scenarios[0], dur, 16, large, level)
        print(
            f"memory, {level} level (#{args.scenarios[0]}, resident): {res / 1e6:.3f} MB per "
            f"world (peak RSS of a whole {dur or sc.duration_s:g}-s episode, 16 against {large} worlds)"
        )
    mpe_runs = [r for r in (mpe_rate() for _ in range(args.rounds)) if r is not None]
    mpe = float(np.median(mpe_runs)) if mpe_runs else None
    if mpe is None:
        print("MPE simple_spread: skipped (pip install --no-deps mpe2)")
    else:
        print(
            f"MPE simple_spread (PettingZoo, 3 agents, random actions): {mpe:.0f} steps per "
            f"CPU second (median of {args.rounds}; load {os.getloadavg()[0]:.2f})"
        )
        for key, rows in results.items():
            num, rate = max(rows)
            print(f"  {key}: single env {rows[0][1] / mpe:.2f}x MPE, B={num} {rate / mpe:.1f}x MPE")
    if args.plot:
        _plot(results, args.plot)
        print(f"plot: {args.plot}")
    return 0


def _level(level: str, sc: Any, name: str, sizes: list[int], episodes: int, rounds: int,
           sync_sizes: list[int]) -> list:  # fmt: skip
    """Print one level's table on one scenario; return ``[(0, single rate), (B, rate), ...,
    (-B, sync rate), ...]``
    (medians over ``rounds`` interleaved rounds: every ``B``, then the sync vector env of every
    ``B`` of ``sync_sizes``, each run bracketed by two runs of the single env, against whose
    mean its ratio is taken)."""
    single, batched, parts = (
        (single_env, batched_env, _PARTS)
        if level == "motion"
        else (single_task, batched_task, _TASK_PARTS)
    )
    runs: dict[int, list[tuple[float, float, float]]] = collections.defaultdict(list)
    # (the single env's rates around each run: the mean of the runs just before and after it)
    around: dict[int, list[tuple[float, ...]]] = collections.defaultdict(list)
    whole = Clock()  # (the breakdown at the largest B, summed over the rounds)
    n_steps = 0
    for _ in range(rounds):
        before = _rates(*single(sc, episodes))
        runs[0].append(before)
        for num in [*sizes, *(-n for n in sync_sizes)]:
            if num > 0:
                ws, clock = batched(sc, num, parts=num == sizes[-1])
                runs[num].append(_rates(ws, clock))
                if num == sizes[-1]:
                    whole.cpu.update(clock.cpu)
                    n_steps += ws // num
            else:
                runs[num].append(_rates(*sync_env(sc, -num, level)))
            after = _rates(*single(sc, episodes))
            runs[0].append(after)
            around[num].append(tuple((x + y) / 2 for x, y in zip(before, after, strict=True)))
            before = after
    print(f"\n## {level} level, #{name}  (load {os.getloadavg()[0]:.2f}; median of {rounds} "
          "interleaved round(s); ratio range over the rounds in brackets)")  # fmt: skip
    print(f"{'env':10s} {'world-steps/s':>22s} {'ratio':>6s} {'[min, max]':>12s} "
          f"{'sim world-steps/s':>18s} {'sim ratio':>9s} {'us/world-step':>13s}")  # fmt: skip
    rows = []
    for num in [0, *sizes, *(-n for n in sync_sizes)]:
        r = np.array(runs[num])
        base = np.array(around[num]) if num else r
        ratio, sim_ratio = r[:, 0] / base[:, 0], r[:, 2] / base[:, 2]
        cpu, wall, sim = np.median(r, axis=0)
        label = "single" if num == 0 else f"B={num}" if num > 0 else f"sync B={-num}"
        print(f"{label:10s} {cpu:10.0f} ({wall:9.0f}) {np.median(ratio):6.2f} "
              f"[{ratio.min():4.2f}, {ratio.max():4.2f}] {sim:18.0f} "
              f"{np.median(sim_ratio):9.2f} {1e6 / cpu:13.2f}")  # fmt: skip
        rows.append((num, float(cpu)))
    sync = {-n: c for n, c in rows if n < 0}
    if sync:
        print("batched over sync at the same B: " + ", ".join(
            f"B={n} {c / sync[n]:.2f}x" for n, c in rows if n in sync))  # fmt: skip
    print(f"where a step goes at B={sizes[-1]} (CPU ms per step; % of env.step):")
    for label in [lab for _, _, lab in parts]:
        ms = whole.cpu[label] / n_steps * 1e3
        print(f"  {label:40s} {ms:9.3f}  {100 * whole.cpu[label] / whole.cpu['step']:5.1f}%")
    if level == "motion":
        env = VectorMotionEnv(sc, 1)
        shape = (sizes[-1], *env.single_observation_space["fov"].shape)
        floor = copy_floor(shape) / sizes[-1]
        one = rows[0][1]
        print(f"observation floor at B={sizes[-1]}: {4 * np.prod(shape[1:]) / 1e3:.1f} KB of "
              f"crops per world-step; copying them once costs {1e6 * floor:.2f} us per "
              f"world-step ({1 / floor / one:.1f}x the single env at most, were nothing else "
              f"done; 20x leaves {1e6 / one / 20:.2f} us)")  # fmt: skip
    return rows


def _rates(steps: int, clock: Clock) -> tuple[float, float, float]:
    """(CPU, wall, simulator CPU) world-steps per second of one timed run."""
    return steps / clock.cpu["step"], steps / clock.wall["step"], steps / clock.cpu["sim"]


def _plot(results: dict[str, list[tuple[int, float]]], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for k, (name, rows) in enumerate(results.items()):
        batched = [(b, r) for b, r in rows if b > 0]
        sync = sorted((-b, r) for b, r in rows if b < 0)
        ax.plot(*zip(*batched, strict=True), "o-", color=f"C{k}", label=f"batched, {name}")
        if sync:
            ax.plot(*zip(*sync, strict=True), "x:", color=f"C{k}", label=f"sync, {name}")
        ax.axhline(rows[0][1], color=f"C{k}", ls="--", label=f"single env, {name}")
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel("worlds per batch B")
    ax.set_ylabel("world-steps per CPU second")
    ax.set_title("fcplan: batched, sync and single env (world-steps per CPU second)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    raise SystemExit(main())
