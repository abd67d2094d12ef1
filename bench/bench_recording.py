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

Usage::

    python bench/bench_recording.py           # about a minute
    python bench/bench_recording.py --quick   # fewer repeats
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time

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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
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
