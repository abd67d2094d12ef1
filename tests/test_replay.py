"""Tests of replay frames, videos and the `fcplan replay` command (fcplan.replay, fcplan.video)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan import run_episode
from fcplan.cli import main
from fcplan.recording import load_recording
from fcplan.render import panel_width, render_frame
from fcplan.video import VideoError, replay_ticks, write_video


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
