"""``fcplan replay PATH``: watch a recording in a window, or write it as an MP4 or GIF video.

::

    fcplan replay PATH [--video out.mp4|out.gif] [--fps N] [--speed X] [--size PX] [--truth]
                       [--start S] [--end S]

Without ``--video`` the episode plays in a pygame window (:func:`fcplan.replay.play_window`:
Space pauses, Left/Right step while paused, Esc quits); it needs a display and ``fcplan[game]``.
With ``--video`` the frames are rendered and encoded one at a time (:func:`fcplan.video.write_video`:
memory stays bounded whatever the episode's length), with a progress bar on stderr when it takes
more than two seconds, and the command prints the frame count and the file's size.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> args = p.parse_args(["replay", "run.npz", "--video", "run.gif", "--speed", "4"])
>>> args.path, args.video, args.speed, args.fps
('run.npz', 'run.gif', 4.0, 10.0)
"""

from __future__ import annotations

import argparse
import os
from typing import TYPE_CHECKING, Any

from fcplan.cli.util import (
    CliError,
    SubParsers,
    check_input,
    check_output,
    positive_float,
    positive_int,
)

if TYPE_CHECKING:
    from fcplan.recording import Recording

__all__ = ["add_parser", "run"]

#: Smallest map side (px) a frame is drawn at.
MIN_SIZE = 64


def _non_negative(text: str) -> float:
    """Seconds >= 0 (finite)."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds >= 0, got {text!r}") from None
    if not 0 <= v < float("inf"):
        raise argparse.ArgumentTypeError(f"expected seconds >= 0, got {text!r}")
    return v


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan replay`` to the ``fcplan`` sub-parsers ``sub``."""
    p = sub.add_parser("replay", help="watch a recording, or write it as an MP4/GIF video")
    p.add_argument("path", help="recording (.npz) from fcplan run --record or fcplan play")
    p.add_argument("--video", metavar="OUT", help="write OUT (.mp4 or .gif) instead of a window")
    p.add_argument(
        "--fps", type=positive_float, default=10.0, metavar="N", help="frames per second (10)"
    )
    p.add_argument("--speed", type=positive_float, default=1.0, help="times real time (default 1)")
    p.add_argument(
        "--size",
        type=positive_int,
        default=512,
        metavar="PX",
        help=f"map size in px, at least {MIN_SIZE} (512)",
    )
    p.add_argument("--truth", action="store_true", help="also show fire the team has not seen")
    p.add_argument(
        "--start", type=_non_negative, default=0.0, metavar="S", help="start at S simulated s"
    )
    p.add_argument(
        "--end", type=_non_negative, default=None, metavar="S", help="stop at S simulated s"
    )
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Play or write the recording ``args.path`` (a regular file: checked before it is opened)."""
    from fcplan.recording import load_recording
    from fcplan.replay import has_display, play_window
    from fcplan.video import VIDEO_SUFFIXES

    check_input(args.path, "recording")
    if args.size < MIN_SIZE:
        raise CliError(f"--size must be at least {MIN_SIZE} px, got {args.size}")
    if args.video:
        check_output(args.video, "--video")
        if os.path.splitext(args.video)[1].lower() not in VIDEO_SUFFIXES:
            raise CliError(f"--video {args.video}: the file must end in .mp4 or .gif")
    rec = load_recording(args.path)  # a bad file is the first thing to report
    window = dict(fps=args.fps, speed=args.speed, start_s=args.start, end_s=args.end)
    if args.video:
        return _write(rec, args, window)
    if not has_display():
        raise CliError(
            "no display to open a replay window; write a video instead: "
            f"fcplan replay {args.path} --video out.mp4"
        )
    return play_window(rec, size=args.size, show_truth=args.truth, **window)


def _write(rec: Recording, args: argparse.Namespace, window: dict[str, Any]) -> int:
    """Write the video with a progress bar; print what was written."""
    from fcplan.cli.progress import progress_bar
    from fcplan.video import replay_ticks, write_video

    total = len(replay_ticks(rec.n_ticks, rec.scenario.ticks_per_second, **window))
    with progress_bar(total, desc=os.path.basename(args.video), unit="frame") as bar:
        n = write_video(
            rec,
            args.video,
            size=args.size,
            show_truth=args.truth,
            progress=lambda done, _total: bar.update(done - bar.n),
            **window,
        )
    size_kb = os.path.getsize(args.video) / 1024
    print(f"wrote {args.video}: {n} frames at {args.fps:g} fps ({size_kb:.0f} KB)")
    return 0
