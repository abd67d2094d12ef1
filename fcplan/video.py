"""Videos of recorded episodes: MP4 (imageio + ffmpeg) or GIF (Pillow), drawn by fcplan.render.

:func:`replay_ticks` chooses which ticks become frames (a time window and a playback speed);
:func:`write_video` renders them with :func:`fcplan.render.render_frame` and streams them to the
encoder one at a time, so memory stays bounded whatever the episode's length: MP4 frames go down
ffmpeg's pipe, GIF frames are encoded and written by :class:`GifStream` as they come (one palette
for the whole clip, so colours never flicker; only the changed area of each frame is stored).
Nothing holds the clip's frames (a 180-s episode at 512 px held 1.6 GB as a GIF before;
``bench/bench_recording.py --memory`` measures the peak).

The file appears under its name only when complete: it is written beside it and renamed, so an
interrupted or failed write leaves nothing half-written. MP4 needs ``fcplan[video]``
(imageio and imageio-ffmpeg); GIF needs only Pillow, a core dependency.

Examples
--------
>>> replay_ticks(1800, 10, fps=10, speed=10.0)  # 10x real time: every 10th tick
range(1, 1801, 10)
"""

from __future__ import annotations

import contextlib
import os
import struct
from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np

from fcplan.errors import FcplanError, install_hint

if TYPE_CHECKING:
    from fcplan.recording import Recording

#: called as ``progress(done, total)`` after each frame
Progress = Callable[[int, int], None]

__all__ = ["GifStream", "VideoError", "replay_ticks", "write_video", "VIDEO_SUFFIXES"]

VIDEO_SUFFIXES = (".mp4", ".gif")
_GIF_COLORS = 128  # palette entries taken from the first frame; index 255 marks "unchanged"
_GIF_CLEAR = 255
_GIF_MAX_DELAY = 0xFFFF  # centiseconds, the largest delay of one GIF frame


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
        raise VideoError(f"MP4 needs imageio and imageio-ffmpeg: {install_hint('video')}") from None
    with _atomic(path) as tmp:
        return _encode_mp4(imageio, images, tmp, fps, total, progress)


def _encode_mp4(
    imageio: Any,
    images: Iterable[np.ndarray],
    path: str,
    fps: float,
    total: int,
    progress: Progress | None,
) -> int:
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
    from fcplan.render import COLORS

    n = 0
    try:
        with _atomic(path) as tmp, open(tmp, "wb") as fh:
            gif = GifStream(fh, fps, colors=COLORS.values())
            for img in images:
                gif.add(img)
                n += 1
                if progress is not None:
                    progress(n, total)
            if n == 0:
                raise VideoError(f"{path}: no frames to write")
            gif.close()
    except OSError as exc:
        raise VideoError(f"{path}: cannot write: {exc.strerror or exc}") from None
    return n


class GifStream:
    """An animated GIF written frame by frame: memory holds two frames, whatever the length.

    One global palette, fixed at the first frame, serves the whole clip, so colours never flicker:
    the exact ``colors`` given (the renderer's named colours: fire that appears later keeps its
    colour) plus up to :data:`_GIF_COLORS` median-cut colours of the first frame (the shades of
    anti-aliased text and overlays); every frame is mapped to it without dithering. Each later frame stores only
    the bounding box of the pixels that changed, with unchanged pixels inside it set to the
    transparent index (the previous frame shows through: disposal 1), which LZW packs into long
    runs; a frame identical to the previous one lengthens the previous one's delay instead. Frame
    delays follow a clock at ``fps`` (GIF counts in 1/100 s: at 30 fps the delays run 3, 3, 4, ...
    so the clip keeps its length). The LZW image data is Pillow's encoder
    (``Image.tobytes("gif", "P")``); the file structure (GIF89a: screen descriptor, global colour
    table, NETSCAPE2.0 loop, per frame a graphic control extension and an image descriptor) is
    written here, so nothing is held between frames (Pillow's own writers keep every frame, or,
    through ``GifImagePlugin.getdata``, a class per frame until the garbage collector runs).

    Parameters
    ----------
    fh : binary file
        Open for writing.
    fps : float
        Frames per second.
    colors : iterable of (r, g, b)
        Colours the palette must hold exactly (at most 127 are used).

    Examples
    --------
    >>> import io
    >>> from PIL import Image
    >>> buf = io.BytesIO()
    >>> gif = GifStream(buf, fps=10, colors=[(255, 255, 255)])
    >>> frame = np.zeros((8, 12, 3), np.uint8)
    >>> gif.add(frame); frame[2, 3] = 255; gif.add(frame); gif.add(frame); gif.close()
    >>> im = Image.open(buf)
    >>> im.size, im.n_frames, im.info["duration"]
    ((12, 8), 2, 100)
    >>> im.seek(1); im.info["duration"]  # the third frame, identical, lengthened the second
    200
    """

    def __init__(
        self, fh: BinaryIO, fps: float, colors: Iterable[tuple[int, int, int]] = ()
    ) -> None:
        self.fh = fh
        self.fps = fps
        self.colors = list(dict.fromkeys(tuple(int(v) for v in c) for c in colors))[:127]
        self.frames = 0  # frames added
        self._palette: Any = None
        self._prev: np.ndarray | None = None  # palette indices of the last frame
        self._pending: tuple[np.ndarray, tuple[int, int], int] | None = None
        self._written_cs = 0  # centiseconds of delays written or pending

    def add(self, img: np.ndarray) -> None:
        """Append one RGB frame, ``(H, W, 3) uint8`` (the same size as the first)."""
        from PIL import Image

        im = Image.fromarray(img)
        if self._palette is None:
            self._palette = self._make_palette(im)
            self._header(im.size)
        idx = np.array(im.quantize(palette=self._palette, dither=Image.Dither.NONE))
        idx[idx == _GIF_CLEAR] = 0  # entry 255 repeats entry 0: a tie, never the transparent one
        self.frames += 1
        delay = round(100 * self.frames / self.fps) - self._written_cs
        self._written_cs += delay
        prev, self._prev = self._prev, idx
        if prev is None:
            self._pending = (idx, (0, 0), delay)
            return
        changed = idx != prev
        if not changed.any():
            assert self._pending is not None
            data, offset, cs = self._pending
            if cs + delay <= _GIF_MAX_DELAY:
                self._pending = (data, offset, cs + delay)
                return
            self._flush()  # a delay is 16 bits: go on with a 1-px frame that changes nothing
            self._pending = (np.full((1, 1), _GIF_CLEAR, np.uint8), (0, 0), delay)
            return
        rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
        box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
        crop = np.where(changed[box], idx[box], _GIF_CLEAR).astype(np.uint8)
        self._flush()
        self._pending = (crop, (int(cols[0]), int(rows[0])), delay)

    def close(self) -> None:
        """Write the last frame and the trailer (the file stays open: the caller's)."""
        self._flush()
        self.fh.write(b";")

    def _make_palette(self, first: Any) -> Any:
        """A ``P`` image holding the clip's 256-entry palette: ``colors``, then the first frame's
        median-cut colours, then repeats of entry 0 (entry 255 is the transparent index)."""
        from PIL import Image

        q = first.quantize(colors=_GIF_COLORS, method=Image.Quantize.MEDIANCUT)
        used = int(np.asarray(q).max()) + 1
        shades = np.asarray(q.getpalette()[: 3 * used], np.uint8).reshape(-1, 3)
        entries = list(dict.fromkeys([*self.colors, *map(tuple, shades.tolist())]))[:255]
        entries += [entries[0]] * (256 - len(entries))
        palette = Image.new("P", (1, 1))
        palette.putpalette([v for rgb in entries for v in rgb])
        return palette

    def _header(self, size: tuple[int, int]) -> None:
        table = bytes(self._palette.getpalette()[: 3 * 256])
        w, h = size
        self.fh.write(b"GIF89a" + struct.pack("<HHBBB", w, h, 0xF7, 0, 0) + table)
        self.fh.write(b"!\xff\x0bNETSCAPE2.0\x03\x01" + struct.pack("<H", 0) + b"\x00")

    def _flush(self) -> None:
        """Write the pending frame: graphic control extension (delay, disposal 1, transparent
        index), image descriptor (its box, no local table) and its LZW data (Pillow's encoder)."""
        if self._pending is None:
            return
        from PIL import Image

        data, (x, y), cs = self._pending
        self._pending = None
        h, w = data.shape
        lzw = Image.frombytes("P", (w, h), data.tobytes()).tobytes("gif", "P")
        self.fh.write(b"!\xf9\x04" + struct.pack("<BHBB", 0x05, cs, _GIF_CLEAR, 0))
        self.fh.write(b"," + struct.pack("<HHHHB", x, y, w, h, 0) + b"\x08" + lzw + b"\x00")


@contextlib.contextmanager
def _atomic(path: str) -> Iterator[str]:
    """A path beside ``path`` (same suffix) to write, renamed onto ``path`` once the block ends
    normally; removed if it fails or is interrupted, so nothing half-written is left."""
    head, tail = os.path.split(path)
    stem, suffix = os.path.splitext(tail)
    tmp = os.path.join(head, f".{stem}.{os.getpid()}.part{suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
