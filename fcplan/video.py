"""Videos of recorded episodes: MP4 (imageio + ffmpeg) or GIF (Pillow), drawn by fcplan.render.

:func:`replay_ticks` chooses which ticks become frames (a time window and a playback speed);
:func:`write_video` renders them with :func:`fcplan.render.render_frame` and encodes them one at a
time (MP4 streams to ffmpeg; GIF keeps one byte per pixel per frame and uses one palette for the
whole clip, so colours never flicker and unchanged areas cost nothing).

The encoders are optional: ``pip install "fcplan[video]"``.

Examples
--------
>>> replay_ticks(1800, 10, fps=10, speed=10.0)  # 10x real time: every 10th tick
range(1, 1801, 10)
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING

import numpy as np

from fcplan.errors import FcplanError

if TYPE_CHECKING:
    from fcplan.recording import Recording

#: called as ``progress(done, total)`` after each frame
Progress = Callable[[int, int], None]

__all__ = ["VideoError", "replay_ticks", "write_video", "VIDEO_SUFFIXES"]

VIDEO_SUFFIXES = (".mp4", ".gif")
_GIF_COLORS = 128  # palette entries for the picture; index 255 marks "unchanged" (transparent)
_GIF_CLEAR = 255


class VideoError(FcplanError, ValueError):
    """A video cannot be written (unknown suffix, missing encoder, bad time window)."""


def replay_ticks(
    n_ticks: int,
    ticks_per_second: int,
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    start_s: float = 0.0,
    end_s: float | None = None,
) -> range:
    """Ticks to show for a replay at ``fps`` frames per second and ``speed`` times real time.

    Parameters
    ----------
    n_ticks, ticks_per_second : int
        Length and rate of the recording.
    fps : float
        Frames per second of the output.
    speed : float
        Simulated seconds per second of output (10: ten times faster than real time).
    start_s, end_s : float
        Simulated time window (seconds); default the whole episode.

    Returns
    -------
    range
        Ticks in ``1..n_ticks``.
    """
    if not (fps > 0 and speed > 0):
        raise VideoError(f"--fps and --speed must be > 0 (got fps {fps}, speed {speed})")
    duration = n_ticks / ticks_per_second
    end_s = duration if end_s is None else end_s
    if not 0 <= start_s < end_s or start_s >= duration:
        raise VideoError(
            f"time window {start_s:g}..{end_s:g} s is empty or outside the recording "
            f"(0..{duration:g} s)"
        )
    step = max(1, int(round(speed * ticks_per_second / fps)))
    first = max(1, int(round(start_s * ticks_per_second)))
    last = min(n_ticks, int(round(end_s * ticks_per_second)))
    return range(first, last + 1, step)


def _pad(img: np.ndarray, multiple: int) -> np.ndarray:
    """Pad on the right and bottom (edge colour) so both sides are multiples of ``multiple``."""
    h, w = img.shape[:2]
    ph, pw = -h % multiple, -w % multiple
    if ph == 0 and pw == 0:
        return img
    return np.pad(img, ((0, ph), (0, pw), (0, 0)), mode="edge")


def write_video(
    recording: Recording,
    path: str | os.PathLike[str],
    *,
    fps: float = 10.0,
    speed: float = 1.0,
    size: int = 512,
    show_truth: bool = False,
    start_s: float = 0.0,
    end_s: float | None = None,
    progress: Progress | None = None,
) -> int:
    """Render a recording's ticks to an MP4 or GIF file; return the number of frames.

    Parameters
    ----------
    recording : fcplan.recording.Recording
    path : str or PathLike
        Output file; its suffix (``.mp4`` or ``.gif``) picks the encoder.
    fps, speed, start_s, end_s
        See :func:`replay_ticks`.
    size : int
        Map side in px (the information panel is added on the right).
    show_truth : bool
        Also draw the fire the team has not sensed.
    progress : callable, optional
        Called as ``progress(done, total)`` after each frame.
    """
    from fcplan.render import render_frame

    path = os.fspath(path)
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in VIDEO_SUFFIXES:
        raise VideoError(f"{path}: video must end in {' or '.join(VIDEO_SUFFIXES)}")
    sc = recording.scenario
    ticks = replay_ticks(
        recording.n_ticks, sc.ticks_per_second, fps=fps, speed=speed, start_s=start_s, end_s=end_s
    )
    frames = recording.frames(ticks.start, ticks.stop - 1, ticks.step)
    images = (render_frame(sc, f, size=size, show_truth=show_truth) for f in frames)
    encode = _write_mp4 if suffix == ".mp4" else _write_gif
    return encode(images, path, fps, len(ticks), progress)


def _write_mp4(
    images: Iterable[np.ndarray], path: str, fps: float, total: int, progress: Progress | None
) -> int:
    try:
        import imageio.v2 as imageio
        import imageio_ffmpeg  # noqa: F401  (the ffmpeg binary imageio needs)
    except ImportError:
        raise VideoError(
            'MP4 needs imageio and imageio-ffmpeg: pip install "fcplan[video]"'
        ) from None
    n = 0
    try:
        writer = imageio.get_writer(
            path,
            format="FFMPEG",
            mode="I",
            fps=fps,
            codec="libx264",
            pixelformat="yuv420p",
            quality=7,
            macro_block_size=1,
            ffmpeg_log_level="error",
        )
    except OSError as exc:
        raise VideoError(f"{path}: cannot write: {exc}") from None
    with writer:
        for img in images:
            writer.append_data(_pad(img, 2))
            n += 1
            if progress is not None:
                progress(n, total)
    return n


def _write_gif(
    images: Iterable[np.ndarray], path: str, fps: float, total: int, progress: Progress | None
) -> int:
    try:
        from PIL import Image
    except ImportError:
        raise VideoError('GIF needs Pillow: pip install "fcplan[video]"') from None
    palette = None
    frames = []
    prev = None
    for img in images:
        im = Image.fromarray(img)
        if palette is None:
            palette = im.quantize(colors=_GIF_COLORS, method=Image.Quantize.MEDIANCUT)
        idx = np.asarray(im.quantize(palette=palette, dither=Image.Dither.NONE))
        # pixels unchanged since the previous frame become transparent: long runs of one index
        # that LZW packs tightly (the previous frame shows through, disposal 1)
        out = idx if prev is None else np.where(idx == prev, _GIF_CLEAR, idx).astype(np.uint8)
        prev = idx
        frame = Image.fromarray(out, mode="P")
        colors = palette.getpalette()
        assert colors is not None  # (a quantized image has a palette)
        frame.putpalette(colors[: 3 * _GIF_COLORS] + [0, 0, 0] * (256 - _GIF_COLORS))
        frames.append(frame)
        if progress is not None:
            progress(len(frames), total)
    if not frames:
        raise VideoError(f"{path}: no frames to write")
    try:
        frames[0].save(
            path,
            save_all=True,
            append_images=frames[1:],
            duration=int(round(1000 / fps)),
            loop=0,
            optimize=False,
            disposal=1,
            transparency=_GIF_CLEAR,
        )
    except OSError as exc:
        raise VideoError(f"{path}: cannot write: {exc}") from None
    return len(frames)
