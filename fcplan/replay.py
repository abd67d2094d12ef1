"""``fcplan replay``: watch a recording in a window, or write it as an MP4 or GIF video.

Frames are rebuilt from the recording alone (cumulative fire events, agent states, the routes of
the last commands) and drawn by :mod:`fcplan.render`, the renderer the environments and the game
use. Without ``--video`` a pygame window plays the episode (Space pauses, Left/Right step while
paused, Esc or closing the window quits); it needs a display.

Examples
--------
``fcplan replay run.npz --video run.mp4 --speed 4``
``fcplan replay run.npz --video run.gif --size 320 --speed 10 --start 20 --end 80 --truth``
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import TYPE_CHECKING, Any

from fcplan.cliutil import CliError, check_output, positive_float, positive_int

if TYPE_CHECKING:
    from fcplan.recording import Recording

__all__ = ["add_parser", "run", "has_display"]

_HISTORY = 100  # frames kept for stepping back while paused


def _non_negative(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds >= 0, got {text!r}") from None
    if not v >= 0:
        raise argparse.ArgumentTypeError(f"expected seconds >= 0, got {text!r}")
    return v


def add_parser(sub: Any) -> None:
    """Add the ``replay`` sub-command to ``sub``."""
    p = sub.add_parser("replay", help="watch a recording, or write it as an MP4/GIF video")
    p.add_argument("path", help="recording (.npz) from fcplan run --record or fcplan play")
    p.add_argument("--video", metavar="OUT", help="write OUT (.mp4 or .gif) instead of a window")
    p.add_argument(
        "--fps", type=positive_float, default=10.0, metavar="N", help="frames per second (10)"
    )
    p.add_argument("--speed", type=positive_float, default=1.0, help="times real time (default 1)")
    p.add_argument(
        "--size", type=positive_int, default=512, metavar="PX", help="map size in px (512)"
    )
    p.add_argument("--truth", action="store_true", help="also show fire the team has not seen")
    p.add_argument(
        "--start", type=_non_negative, default=0.0, metavar="S", help="start at S simulated s"
    )
    p.add_argument(
        "--end", type=_non_negative, default=None, metavar="S", help="stop at S simulated s"
    )
    p.set_defaults(run=run)


def has_display() -> bool:
    """Whether a window can be opened (Windows/macOS, or X11/Wayland on other systems)."""
    if os.environ.get("SDL_VIDEODRIVER", "") == "dummy":
        return True  # headless SDL (tests); windows open, nothing is shown
    if sys.platform in ("win32", "darwin"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def run(args: argparse.Namespace) -> int:
    """Run ``fcplan replay``."""
    from fcplan.recording import load_recording

    if args.size < 64:
        raise CliError(f"--size must be at least 64 px, got {args.size}")
    if args.video:
        check_output(args.video, "--video")
        suffix = os.path.splitext(args.video)[1].lower()
        if suffix not in (".mp4", ".gif"):
            raise CliError(f"--video {args.video}: the file must end in .mp4 or .gif")
    rec = load_recording(args.path)  # a bad file is the first thing to report
    if not args.video and not has_display():
        raise CliError(
            "no display to open a replay window; write a video instead: "
            f"fcplan replay {args.path} --video out.mp4"
        )
    if args.video:
        from fcplan.video import write_video

        progress = _Progress() if sys.stderr.isatty() else None
        n = write_video(
            rec,
            args.video,
            fps=args.fps,
            speed=args.speed,
            size=args.size,
            show_truth=args.truth,
            start_s=args.start,
            end_s=args.end,
            progress=progress,
        )
        if progress is not None:
            print(file=sys.stderr)
        size_kb = os.path.getsize(args.video) / 1024
        print(f"wrote {args.video}: {n} frames at {args.fps:g} fps ({size_kb:.0f} KB)")
        return 0
    return play_window(rec, args)


class _Progress:
    def __call__(self, done: int, total: int) -> None:
        print(f"\rrendering frame {done}/{total}", end="", file=sys.stderr, flush=True)


def play_window(rec: Recording, args: argparse.Namespace) -> int:
    """Play ``rec`` in a pygame window at ``args.fps`` and ``args.speed``."""
    try:
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        import pygame
    except ImportError:
        raise CliError('the replay window needs pygame: pip install "fcplan[game]"') from None
    from fcplan.render import render_frame
    from fcplan.video import replay_ticks

    sc = rec.scenario
    ticks = replay_ticks(
        rec.n_ticks,
        sc.ticks_per_second,
        fps=args.fps,
        speed=args.speed,
        start_s=args.start,
        end_s=args.end,
    )
    headless = os.environ.get("SDL_VIDEODRIVER", "") == "dummy"
    pygame.display.init()
    try:
        frames = rec.frames(ticks.start, ticks.stop - 1, ticks.step)
        first = render_frame(sc, next(frames), size=args.size, show_truth=args.truth)
        screen = pygame.display.set_mode((first.shape[1], first.shape[0]))
        pygame.display.set_caption(f"fcplan replay - {sc.name} - {rec.source}")
        clock = pygame.time.Clock()
        shown = {0: first}  # the last _HISTORY rendered frames, so Left can step back
        k, paused, more, n = 0, False, True, 1
        while True:
            for ev in pygame.event.get():
                if ev.type == pygame.QUIT or (
                    ev.type == pygame.KEYDOWN and ev.key in (pygame.K_ESCAPE, pygame.K_q)
                ):
                    return 0
                if ev.type == pygame.KEYDOWN and ev.key == pygame.K_SPACE:
                    paused = not paused
                if ev.type == pygame.KEYDOWN and paused and ev.key == pygame.K_LEFT:
                    k = max(k - 1, min(shown))
                if ev.type == pygame.KEYDOWN and paused and ev.key == pygame.K_RIGHT:
                    k += 1
            if not paused:
                k += 1
            while more and k >= n:
                frame = next(frames, None)
                if frame is None:
                    more = False
                    break
                shown[n] = render_frame(sc, frame, size=args.size, show_truth=args.truth)
                shown.pop(n - _HISTORY, None)
                n += 1
            if k >= n:
                k = n - 1
                if headless:
                    return 0
                paused = True  # hold the last frame until the window is closed
            surf = pygame.surfarray.make_surface(shown[k].swapaxes(0, 1))
            screen.blit(surf, (0, 0))
            pygame.display.flip()
            clock.tick(args.fps)
    finally:
        pygame.display.quit()
