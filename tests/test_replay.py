"""Tests of replay frames, videos and the `fcplan replay` command (fcplan.replay, fcplan.video)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image, ImageSequence

from fcplan import run_episode
from fcplan.cli import main
from fcplan.recording import load_recording
from fcplan.render import panel_width, render_frame
from fcplan.video import GifStream, VideoError, replay_ticks, write_video
from tests.traced import traced_call


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    """A recorded greedy episode of scenario #1."""
    path = tmp_path_factory.mktemp("replay") / "one.npz"
    run_episode(1, "greedy", seed=0, record=path)
    return path


def test_frames_render_headless(rec_path):
    """Every replay frame renders to an image of the expected size, showing known fire at some
    point and pruned cells at the end."""
    rec = load_recording(rec_path)
    frames = list(rec.frames(1, None, 100))
    assert [f.tick for f in frames] == list(range(1, rec.n_ticks + 1, 100))
    assert any(f.known.any() for f in frames)
    assert frames[-1].pruned.sum() == rec.arrays["pruned"][frames[-1].tick - 1]
    img = render_frame(rec.scenario, frames[5], size=160)
    assert img.shape == (160, 160 + panel_width(160), 3)
    assert "final score" in frames[5].scores


@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_short_video_is_written_and_readable(rec_path, tmp_path, suffix):
    """A short MP4 and a GIF are written and read back with the right frame count and size."""
    iio = pytest.importorskip("imageio.v3")
    rec = load_recording(rec_path)
    out = tmp_path / f"clip{suffix}"
    n = write_video(rec, out, fps=10, speed=10, size=128, start_s=10, end_s=20)
    assert n == 11
    frames = iio.imread(out, index=None, **({"mode": "RGB"} if suffix == ".gif" else {}))
    assert frames.shape[0] == n
    assert frames.shape[1] == 128
    assert frames.shape[2] in (128 + panel_width(128), 128 + panel_width(128) + 1)


def test_gif_frames_match_the_renderer(rec_path, tmp_path):
    """GIF frames (one palette, unchanged pixels transparent) decode close to the rendered
    images."""
    iio = pytest.importorskip("imageio.v3")
    rec = load_recording(rec_path)
    out = tmp_path / "c.gif"
    write_video(rec, out, fps=10, speed=5, size=128, start_s=30, end_s=33)
    got = iio.imread(out, index=None, mode="RGB")
    want = [render_frame(rec.scenario, f, size=128) for f in rec.frames(300, 330, 5)]
    assert len(got) == len(want)
    for g, w in zip(got, want, strict=True):
        assert np.abs(g.astype(int) - w).mean() < 4.0


@given(
    st.integers(1, 5000),
    st.sampled_from([1, 5, 10, 20]),
    st.floats(0.5, 60),
    st.floats(0.1, 50),
)
def test_replay_ticks_stay_in_the_recording(n_ticks, tps, fps, speed):
    """Chosen ticks are increasing, inside 1..T, and start at the first tick."""
    ticks = replay_ticks(n_ticks, tps, fps=fps, speed=speed)
    assert ticks.start == 1 and ticks.step >= 1
    assert len(ticks) >= 1 and ticks[-1] <= n_ticks


def test_bad_windows_and_suffixes(rec_path, tmp_path):
    """An empty time window or an unknown video suffix raises VideoError."""
    rec = load_recording(rec_path)
    with pytest.raises(VideoError, match="time window"):
        write_video(rec, tmp_path / "a.gif", start_s=200)
    with pytest.raises(VideoError, match="mp4"):
        write_video(rec, tmp_path / "a.avi")


def test_cli_video(rec_path, tmp_path, capsys):
    """`fcplan replay --video` writes the file and reports its frames."""
    out = tmp_path / "r.gif"
    assert (
        main(
            [
                "replay",
                str(rec_path),
                "--video",
                str(out),
                "--size",
                "96",
                "--speed",
                "30",
                "--end",
                "30",
                "--truth",
            ]
        )
        == 0
    )
    assert out.exists() and "frames" in capsys.readouterr().out


def test_cli_without_display(rec_path, monkeypatch, capsys):
    """Without a display the command fails in one line suggesting --video (exit 2)."""
    for var in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setattr("sys.platform", "linux")
    assert main(["replay", str(rec_path)]) == 2
    err = capsys.readouterr().err
    assert "--video" in err and err.count("\n") == 1


def test_cli_window_headless(rec_path, monkeypatch):
    """The pygame window path plays a short window to its end under SDL's dummy driver."""
    pytest.importorskip("pygame")
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    args = ["replay", str(rec_path), "--size", "96", "--fps", "100", "--speed", "50", "--end", "10"]
    assert main(args) == 0


def test_cli_errors(rec_path, tmp_path, capsys):
    """A foreign file and a bad suffix are one-line errors with exit status 2."""
    bad = tmp_path / "x.npz"
    bad.write_bytes(b"nope")
    assert main(["replay", str(bad), "--video", str(tmp_path / "o.gif")]) == 2
    assert main(["replay", str(rec_path), "--video", str(tmp_path / "o.avi")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and all(line.startswith("fcplan: error:") for line in err)


PALETTE = np.array([(0, 0, 0), (255, 72, 24), (84, 190, 255), (226, 228, 234)], np.uint8)


def _gif(frames, fps, colors=PALETTE):
    buf = io.BytesIO()
    gif = GifStream(buf, fps, colors=[tuple(c) for c in colors])
    for f in frames:
        gif.add(f)
    gif.close()
    buf.seek(0)
    return Image.open(buf)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.integers(0, 2**32 - 1), min_size=1, max_size=10),
    st.sampled_from([5, 10, 20, 25]),
    st.data(),
)
def test_gif_stream_decodes_to_the_frames_it_was_given(seeds, fps, data):
    """Frames whose colours are all in the palette decode exactly, each shown for 1/fps s
    (identical neighbours merged into one longer frame), whatever changed between frames."""
    frames = []
    for s in seeds:
        rng = np.random.default_rng(s)
        if frames and data.draw(st.booleans()):
            frame = frames[-1].copy()  # a repeat or a small change of the previous frame
            frame[rng.integers(0, 6), rng.integers(0, 9)] = PALETTE[rng.integers(0, 4)]
        else:
            frame = PALETTE[rng.integers(0, 4, size=(6, 9))]
        frames.append(frame)
    im = _gif(frames, fps)
    shown = []
    for frame in ImageSequence.Iterator(im):
        assert frame.info["duration"] % (1000 // fps) == 0
        shown += [np.asarray(frame.convert("RGB"))] * (frame.info["duration"] * fps // 1000)
    assert len(shown) == len(frames)
    for got, want in zip(shown, frames, strict=True):
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("fps", [3, 7.5, 30])
def test_gif_delays_follow_the_clock(fps):
    """Delays are whole 1/100 s that add up to the clip's length at ``fps`` (30 fps: 3, 3, 4,
    ...), instead of each frame's delay rounded on its own (30 fps would run 10 % slow)."""
    frames = [PALETTE[np.full((4, 4), k % 4)] for k in range(30)]
    im = _gif(frames, fps)
    total = sum(f.info["duration"] for f in ImageSequence.Iterator(im))
    assert total == 10 * round(100 * 30 / fps)


def test_gif_still_frames_longer_than_a_gif_delay_keep_their_length():
    """A picture that stays the same for longer than one GIF delay can say (655.35 s) is
    continued by frames that change nothing, so the clip keeps its length."""
    frames = [PALETTE[np.zeros((4, 4), int)]] * 700
    im = _gif(frames, fps=1)
    durations = [f.info["duration"] for f in ImageSequence.Iterator(im)]
    assert sum(durations) == 700_000 and max(durations) <= 655_350


class _Sink(io.RawIOBase):  # a file that keeps nothing (the output is not the point)
    def write(self, b):
        return len(b)


def _gif_of(n: int) -> None:
    """Write an ``n``-frame GIF of a scrolling picture to a sink (run in the traced helper)."""
    base = PALETTE[np.random.default_rng(0).integers(0, 4, size=(96, 128))]
    gif = GifStream(_Sink(), 10, colors=[tuple(c) for c in PALETTE])
    for k in range(n):
        gif.add(np.roll(base, k, axis=1))
    gif.close()


def test_gif_memory_does_not_grow_with_the_clip():
    """Writing ten times more frames does not raise the peak of traced memory: frames are
    encoded and written as they come, none is kept."""
    (_, small), (_, large) = traced_call(_gif_of, 20), traced_call(_gif_of, 200)
    assert large < 1.5 * small, (small, large)


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_a_failed_video_leaves_no_file(rec_path, tmp_path, suffix, monkeypatch):
    """A write interrupted half-way (here a frame that fails to render) leaves neither the video
    nor its temporary file behind."""
    if suffix == ".mp4":
        pytest.importorskip("imageio_ffmpeg")
    import fcplan.render as render

    calls = []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return render_frame(*args, **kwargs)

    monkeypatch.setattr(render, "render_frame", failing)
    with pytest.raises(KeyboardInterrupt):
        write_video(load_recording(rec_path), tmp_path / f"v{suffix}", size=96, speed=20)
    assert list(tmp_path.iterdir()) == []


def test_cli_bounds_what_a_frame_and_a_gif_can_hold(rec_path, capsys):
    """--fps outside 0.01..1000 (a GIF delay of 1e302 cs), --size beyond 4096 px (a frame numpy
    cannot allocate) and an infinite --start or --end are one-line errors naming the range; the
    command's fps range is the library's."""
    from fcplan.cli.replay import _fps
    from fcplan.video import FPS_RANGE

    assert _fps(str(FPS_RANGE[0])) == FPS_RANGE[0] and _fps(str(FPS_RANGE[1])) == FPS_RANGE[1]
    for option, value, named in [
        ("--fps", "1e-300", "0.01..1000"),
        ("--fps", "1001", "0.01..1000"),
        ("--size", "99999999999999999999", "64..4096"),
        ("--size", "63", "64..4096"),
        ("--start", "inf", "seconds >= 0"),
        ("--end", "1e999", "seconds >= 0"),
    ]:
        assert main(["replay", str(rec_path), "--video", "x.gif", option, value]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and named in err and repr(value) in err, err
    with pytest.raises(VideoError, match="fps must be in"):
        replay_ticks(1800, 10, fps=1e-300)
