"""Benchmark recordings and replays (issue 6).

Prints, for scenarios #1 and #24 (greedy, seed 0, 180 s = 1,800 ticks):

* recording overhead per tick: the world loop (``World.step`` + ``Belief.update`` with the team
  following greedy commands replayed from a recording, no scheduler) with and without the
  :class:`fcplan.recording.Recorder` hooks, in us per tick, and the time spent inside the hooks
  (plus building the arrays at the end) per tick, measured directly (robust on a loaded
  machine) and as a share of the plain loop; plus the whole
  ``run_episode`` with and without ``record=`` (scheduler included), and the time to save;
* the recording's file size (the issue's budget: 5 MB for #24);
* replay rendering: frames per second of ``Recording.frames`` (rebuilding the frame data from
  the fire events), of ``render_frame`` alone at 512 and 320 px, and of the whole
  ``fcplan replay --video`` path to MP4 (512 px) and GIF (320 px).

``--memory`` instead measures the peak resident memory (``ru_maxrss`` of the child, from
``os.wait4``) of whole ``fcplan replay REC --video OUT`` processes on #24 (greedy, seed 0,
recorded by the same tree) at 512 px, 1x speed (one frame per tick), for a 30-s, a 90-s and the
whole 180-s episode, GIF and MP4: bounded memory means the peak does not grow with the clip. ``--old PATH`` runs the same
commands from another source tree (e.g. an export of ``main`` before streaming) for before/after;
``python -c "import fcplan.video, fcplan.render, fcplan.recording"`` is the baseline (the
interpreter and the libraries alone).

Usage::

    python bench/bench_recording.py           # about a minute
    python bench/bench_recording.py --quick   # fewer repeats
    python bench/bench_recording.py --memory [--old PATH]   # a few minutes
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fcplan import World, load_scenario, run_episode
from fcplan.belief import Belief
from fcplan.recording import Recorder, load_recording
from fcplan.render import render_frame
from fcplan.video import write_video


def _best(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def _world_loop(sc, commands, recorder: bool) -> float:
    """Run the episode's world loop; return the seconds spent inside the recorder's hooks."""
    world, belief = World().reset(sc, 0), Belief(sc)
    rec = Recorder(sc, 0, source="bench", settings={}) if recorder else None
    clock = time.perf_counter
    hooks = 0.0
    while not world.done:
        cmds = commands.get(world.tick)
        if rec is not None:
            t0 = clock()
            rec.on_commands(world.tick, cmds)
            hooks += clock() - t0
        info = world.step(cmds)
        belief.update(info)
        if rec is not None:
            t0 = clock()
            rec.on_step(world, info)
            hooks += clock() - t0
    if rec is not None:
        t0 = clock()
        rec.recording()
        hooks += clock() - t0
    return hooks


def _bench_scenario(name, tmp: str, repeats: int):
    """Print one row of the overhead table; return the recording."""
    sc = load_scenario(name)
    path = os.path.join(tmp, f"{name}.npz")
    run_episode(sc, "greedy", seed=0, record=path)
    rec = load_recording(path)
    commands = rec.commands()
    ticks = rec.n_ticks
    plain = _best(lambda: _world_loop(sc, commands, False), repeats) / ticks * 1e6
    with_rec = _best(lambda: _world_loop(sc, commands, True), repeats) / ticks * 1e6
    hooks = min(_world_loop(sc, commands, True) for _ in range(repeats)) / ticks * 1e6
    ep = _best(lambda: run_episode(sc, "greedy", seed=0), repeats)
    ep_rec = _best(lambda: run_episode(sc, "greedy", seed=0, record=path), repeats)
    save_ms = _best(lambda: rec.save(path), repeats) * 1e3
    kb = os.path.getsize(path) / 1024
    print(
        f"{name:>8} {plain:13.1f} {with_rec:13.1f} {hooks:14.1f} {hooks / plain:9.1%} "
        f"{ep:10.3f} {ep_rec:10.3f} {save_ms:8.1f} {kb:8.0f}"
    )
    return rec


def peak_rss(args: list[str], tree: Path) -> tuple[float, float]:
    """Peak resident MiB and wall seconds of one ``python args`` process run from ``tree``."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as err:  # progress bars and errors, shown only on failure
        child = subprocess.Popen(
            [sys.executable, *args], cwd=tree, env=env, stdout=subprocess.DEVNULL, stderr=err
        )
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode:
            err.seek(0)
            raise SystemExit(f"{' '.join(args)}: status {child.returncode}: {err.read().decode()}")
    return usage.ru_maxrss / 1024, time.perf_counter() - t0  # Linux: ru_maxrss in KiB


def memory(old: Path | None) -> None:
    """Print peak RSS of ``fcplan replay --video`` by clip length, format and tree."""
    tmp = tempfile.mkdtemp()
    trees = {"new": Path(__file__).resolve().parents[1], **({"old": old.resolve()} if old else {})}
    base = ["-c", "import fcplan.video, fcplan.render, fcplan.recording"]
    print(f"load average {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} CPUs")
    print("peak RSS of fcplan replay r24.npz --video OUT --size 512 (1x: one frame per tick)")
    print(f"{'tree':<5} {'format':<7} {'clip s':>6} {'frames':>6} {'peak MiB':>9} {'wall s':>7}")
    for tree, path in trees.items():
        rec = os.path.join(tmp, f"r24_{tree}.npz")  # each tree replays its own recording format
        peak_rss(["-m", "fcplan", "run", "24", "--record", rec], path)
        mib, _ = peak_rss(base, path)
        print(f"{tree:<5} {'(none)':<7} {'-':>6} {'-':>6} {mib:>9.0f} {'-':>7}")
        for suffix in (".gif", ".mp4"):
            for end in (30, 90, 180):
                out = os.path.join(tmp, f"v{suffix}")
                cmd = ["-m", "fcplan", "replay", rec, "--video", out, "--end", str(end)]
                mib, wall = peak_rss(cmd, path)
                print(f"{tree:<5} {suffix[1:]:<7} {end:>6} {10 * end:>6} {mib:>9.0f} {wall:>7.1f}")
    print(f"load average {os.getloadavg()[0]:.2f} (1 min) at the end")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--memory", action="store_true", help="peak RSS of replay --video instead")
    ap.add_argument("--old", type=Path, help="with --memory: another source tree to compare")
    args = ap.parse_args()
    if args.memory:
        memory(args.old)
        return
    repeats = 2 if args.quick else 5
    tmp = tempfile.mkdtemp()
    print(f"load average {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} CPUs")
    print()
    print(f"recording overhead (greedy, seed 0, 1,800 ticks; best of {repeats})")
    hdr = (
        f"{'scenario':>8} {'loop us/tick':>13} {'+rec us/tick':>13} {'hooks us/tick':>14} "
        f"{'hooks/loop':>10} "
        f"{'episode s':>10} {'+record s':>10} {'save ms':>8} {'file KB':>8}"
    )
    print(hdr)
    recs = {name: _bench_scenario(name, tmp, repeats) for name in (1, 24)}
    print()
    print("replay rendering, scenario #24 (frames per second)")
    rec = recs[24]
    sc = rec.scenario
    n_frames = 180
    step = rec.n_ticks // n_frames

    def frames_only():
        for _ in rec.frames(1, None, step, scores=True):
            pass

    t = _best(frames_only, repeats)
    print(f"  Recording.frames (event replay + online scores): {n_frames / t:8.0f} frames/s")
    frames = list(rec.frames(1, None, step))
    for size in (512, 320):
        t = _best(lambda size=size: [render_frame(sc, f, size=size) for f in frames], repeats)
        print(f"  render_frame at {size} px (+ panel):               {n_frames / t:8.0f} frames/s")
    reps = max(1, repeats // 2)
    for suffix, size in ((".mp4", 512), (".gif", 320)):
        out = os.path.join(tmp, f"v{suffix}")
        times = []
        for _ in range(reps):
            t0 = time.perf_counter()
            n = write_video(rec, out, fps=10, speed=10, size=size)
            times.append(time.perf_counter() - t0)
        t = statistics.median(times)
        kb = os.path.getsize(out) / 1024
        print(
            f"  write_video {suffix} at {size} px (10x, 180 frames):    {n / t:8.0f} frames/s "
            f"({t:.2f} s, {kb:.0f} KB)"
        )


if __name__ == "__main__":
    main()
