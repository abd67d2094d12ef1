"""The pygame game end to end, headless: posted events play the practice scenario to its end,
the recording re-simulates and its inputs replay to the same outcome; ``fcplan play`` CLI."""

from __future__ import annotations

import numpy as np
import pytest

pygame = pytest.importorskip("pygame")

from fcplan import load_scenario  # noqa: E402
from fcplan.cli import main  # noqa: E402
from fcplan.game.app import run_app  # noqa: E402
from fcplan.game.screens import App  # noqa: E402
from fcplan.game.session import replay_inputs  # noqa: E402
from fcplan.recording import load_recording  # noqa: E402


@pytest.fixture
def headless(monkeypatch):
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")


def _post_key(name: str) -> None:
    k = pygame.key.key_code(name)
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=k, unicode=name if len(name) == 1
                                         else "", mod=0, scancode=0))  # fmt: skip


def _post_click(pos) -> None:
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=pos))


def test_scripted_game_plays_practice_to_the_end_and_replays(headless, tmp_path):
    """Posted pygame events (select, goals, patrol loop, altitude keys, depot click) drive a
    headless fast game of the practice scenario to its end; the recording holds every input,
    re-simulates identically, and its inputs replayed through a fresh game (with and without the
    window) give equal metrics."""
    sc = load_scenario("practice")
    path = tmp_path / "human.npz"
    app = App(sc, seed=4, fast=True, frame_ticks=30, record=path, exit_at_end=True)
    depot = sc.depot.center
    script = {
        1: lambda: [_post_key("1"), *(_post_click(app.window_point(x, y))
                    for x, y in [(300, 300), (600, 300), (600, 600), (330, 320)]),
                    _post_key("up"), _post_key("up")],
        3: lambda: [_post_key("3"), _post_click(app.window_point(350, 350)),
                    _post_click(app.window_point(500, 450))],
        5: lambda: [_post_key("2"), _post_key("down"), _post_click(app.window_point(800, 800))],
        20: lambda: [_post_key("4"), _post_click(app.window_point(400, 400))],
        30: lambda: [_post_key("2"), _post_click(app.window_point(*depot))],
        40: lambda: [_post_click(app.agent_row_rect(0)[:2])],  # select P1 in the panel
    }  # fmt: skip
    frames = []

    def on_frame(a):
        frames.append(a.session.tick)
        action = script.get(len(frames))
        if action is not None:
            action()

    run_app(app, on_frame=on_frame)
    assert app.session.done and app.session.tick == sc.n_ticks
    assert not app.running and app.final is not None

    kinds = [(e["type"], e.get("key")) for e in app.session.inputs]
    assert kinds.count(("click", None)) == 9
    assert ("key", "up") in kinds and ("key", "down") in kinds
    assert any(e.get("via") == "panel" for e in app.session.inputs)
    cmd_sets = [c for _, cs in app.session.commands for c in cs.values()]
    assert any(c.patrol for c in cmd_sets) and any(c.home for c in cmd_sets)
    assert any(c.altitude is not None for c in cmd_sets)

    rec = load_recording(path)
    assert rec.source == "human" and rec.seed == 4 and rec.n_ticks == sc.n_ticks
    assert rec.settings["mode"] == "scenario" and rec.settings["fast"]
    assert rec.inputs == app.session.inputs
    assert rec.metrics() == app.final
    assert rec.resimulate().mismatches(rec) == []
    again = replay_inputs(rec.scenario, rec.seed, rec.inputs)
    assert again.final_metrics() == rec.metrics()
    assert np.array_equal(again.world.trace().active, rec.arrays["active"])

    # the game itself replays the recording's inputs (its scenario and seed by default)
    copy = tmp_path / "again.npz"
    argv = ["play", "--inputs", str(path), "--fast", "--frame-ticks", "90", "--exit-at-end"]
    assert main([*argv, "--record", str(copy)]) == 0
    replayed = load_recording(copy)
    assert replayed.seed == 4 and replayed.inputs == rec.inputs
    assert replayed.metrics() == rec.metrics()


def test_screenshot_and_cli(headless, tmp_path, capsys):
    """``fcplan play --scenario 1 --fast --screenshot`` saves a PNG of the game and a recording."""
    shot, rec = tmp_path / "game.png", tmp_path / "g.npz"
    status = main(["play", "--scenario", "1", "--fast", "--frame-ticks", "20", "--screenshot",
                   str(shot), "--screenshot-at", "3", "--record", str(rec)])  # fmt: skip
    assert status == 0
    img = pygame.image.load(str(shot))
    assert img.get_size() == (1140, 760)
    assert load_recording(rec).n_ticks >= 30
    assert "recorded to" in capsys.readouterr().out


def test_cli_without_display_is_one_line_exit_2(monkeypatch, capsys):
    """Without a display ``fcplan play`` prints one line suggesting SDL_VIDEODRIVER=dummy."""
    import sys

    monkeypatch.delenv("SDL_VIDEODRIVER", raising=False)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    assert main(["play", "--scenario", "practice"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "SDL_VIDEODRIVER=dummy" in err


def test_cli_rejects_bad_arguments(headless, tmp_path, capsys):
    """Bad speed, unknown scenario and malformed input scripts are one-line errors (exit 2)."""
    assert main(["play", "--speed", "0"]) == 2
    assert main(["play", "--scenario", "nope"]) == 2
    bad = tmp_path / "in.json"
    bad.write_text('[{"type": "click"}]')
    assert main(["play", "--scenario", "1", "--inputs", str(bad)]) == 2
    assert "needs an integer 'tick'" in capsys.readouterr().err
