"""render_mode="human": frames in a pygame window (headless with SDL_VIDEODRIVER=dummy), and a
one-line install hint without pygame."""

from __future__ import annotations

import sys

import gymnasium
import numpy as np
import pytest

import fcplan.env  # noqa: F401 (registers the Gymnasium ids)
from fcplan.env import EnvError, parallel_env, task_v0
from fcplan.env.human import PYGAME_HINT, HumanWindow

pytest.importorskip("pygame")


@pytest.fixture
def headless(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")


@pytest.mark.parametrize(
    "make",
    [
        lambda: parallel_env(24, k=4, max_steps=2, render_mode="human"),
        lambda: parallel_env("practice", mode="motion", render_mode="human", render_size=64),
        lambda: parallel_env("base", mode="motion", render_mode="human", max_steps=3),
        lambda: task_v0.parallel_env(k=3, max_steps=2, render_mode="human", obs_layout="flat"),
    ],
)
def test_parallel_envs_show_their_frames(make, headless):
    """A human-mode parallel env opens a window of its rgb_array frame's size on reset,
    shows a frame on every step, and render() returns None."""
    env = make()
    assert env.render_mode == "human" and "human" in env.metadata["render_modes"]
    env.reset(seed=0)
    window = env.window
    frame = env.unwrapped.render()
    assert window.size == (frame.shape[1], frame.shape[0])
    env.step({})
    assert env.render() is None
    env.close()
    assert window.size is None


@pytest.mark.parametrize("env_id", ["fcplan/Task-v0", "fcplan/MotionCmplx2-v0"])
def test_gymnasium_ids_show_their_frames(env_id, headless):
    """gymnasium.make(id, render_mode="human") renders itself on reset and step."""
    env = gymnasium.make(env_id, render_mode="human", max_steps=2)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    assert env.unwrapped.window.size is not None and env.render() is None
    env.close()


def test_window_shows_any_frame(headless):
    """The window takes an (H, W, 3) uint8 frame and resizes to a frame of another size."""
    w = HumanWindow("test", fps=1000)
    w.show(np.zeros((30, 50, 3), dtype=np.uint8))
    assert w.size == (50, 30)
    w.show(np.full((20, 10, 3), 255, dtype=np.uint8))
    assert w.size == (10, 20)
    w.close()


def test_without_pygame_one_line_hint(monkeypatch):
    """Without pygame, asking for the human mode fails at construction with one line naming
    the extra in both install forms."""
    monkeypatch.setitem(sys.modules, "pygame", None)
    for make in (
        lambda: parallel_env(24, k=4, render_mode="human"),
        lambda: gymnasium.make("fcplan/MotionBase-v0", render_mode="human"),
    ):
        with pytest.raises(EnvError) as err:
            make()
        msg = str(err.value)
        assert msg == PYGAME_HINT and "\n" not in msg
        assert 'pip install "fcplan[game]"' in msg and 'pip install -e ".[game]"' in msg
