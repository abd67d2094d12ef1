"""The game's screens (fcplan.game.screens) and the open-world designer, without pygame."""

from __future__ import annotations

import pytest

from fcplan import load_scenario
from fcplan.game.designer import PAGES, Design
from fcplan.game.screens import SCREENS, TUTORIAL, App


def test_welcome_navigation_reaches_every_menu_screen():
    """Welcome -> scenario mode / open-world / tutorial and back, Escape and quit."""
    app = App()
    assert app.screen == "welcome"
    ids = {b.id for b in app.buttons()}
    assert {"scenario_mode", "open_world", "tutorial", "quit"} <= ids
    app.press("scenario_mode")
    labels = [b.label for b in app.buttons() if b.id.startswith("play:")]
    assert labels == ["Practice"] + [f"#{n}" for n in range(1, 25)]
    titles = [t for t, _ in app.scenario_groups()]
    assert titles == ["Practice", "Easy", "Moderate", "Hard"]
    app.key("escape")
    assert app.screen == "welcome"
    app.press("tutorial")
    for _ in range(len(TUTORIAL) + 2):
        app.press("tutorial:next")
    assert app.tutorial_page == len(TUTORIAL) - 1
    app.press("back")
    app.press("open_world")
    assert app.screen == "designer"
    app.key("escape")
    app.key("escape")
    assert not app.running
    assert set(SCREENS) >= {"welcome", "scenarios", "tutorial", "designer", "game", "evaluation"}


def test_clicks_hit_buttons_by_position():
    """A click at a button's centre does what the button does; elsewhere nothing happens; the
    mouse over a scenario button shows its summary."""
    app = App()
    app.click(5, 5)
    assert app.screen == "welcome"
    target = next(b for b in app.buttons() if b.id == "scenario_mode")
    app.click(*target.center)
    assert app.screen == "scenarios"
    seed_plus = next(b for b in app.buttons() if b.id == "seed:+1")
    app.click(*seed_plus.center)
    assert app.seed == 1
    twelve = next(b for b in app.buttons() if b.id == "play:12")
    app.handle({"type": "move", "pos": twelve.center})
    assert app.hover_summary().startswith("#12  moderate")


@pytest.mark.parametrize(
    ("key", "text", "expected"),
    [
        ("world_size", "900", "choose 800 / 1000 / 1200"),
        ("duration_s", "100", "choose 60 / 120 / 180"),
        ("regions", "6", "outside the manual limit 1..5"),
        ("houses", "-1", "outside the manual limit 0..5"),
        ("fronts", "31", "outside the manual limit 1..30"),
        ("fuel", "1", "outside the manual limit 2..20"),
        ("wind_speed", "11", "outside the manual limit 2..10 m/s"),
        ("wind_dir_deg", "400", "0..360 deg"),
        ("temporal_exponent", "3", "0..2"),
        ("perception.battery", "900", "200..800"),
        ("action.speed", "5", "10..30"),
        ("action.tank", "16", "1..15"),
        ("action.prune_confidence", "5", "10..100 %"),
        ("perception", "9", "at most 9"),
        ("action", "0", "at least one agent must sense"),
        ("fronts", "abc", "is not a number"),
        ("region.0.cell", "Z-99", "is not a cell of the map"),
        ("lake.0.cell", "L-12", "does not fit"),
    ],
)
def test_designer_refuses_out_of_limit_values_with_a_message(key, text, expected):
    """Every field refuses values beyond the manual's limits; the app shows the message."""
    app = App()
    app.press("open_world")
    before = dict(app.design.values)
    problem = app.edit(key, text)
    assert problem is not None and expected in problem
    assert app.message == problem and app.error
    assert app.design.values == before


def test_designer_pages_build_a_scenario_within_the_manual_limits():
    """Walking through the pages (with edits and +/- presses) builds a valid scenario whose
    manual-limit report is empty, previews it, shows the tutorial and starts a game."""
    app = App(fast=True)
    app.press("open_world")
    assert app.edit("world_size", "1000") is None
    app.press("nudge:regions:+1")
    app.press("nudge:hybrid:+1")
    app.press("design:next")
    assert app.design.page == "fire"
    assert app.edit("fronts", "7") is None
    assert app.edit("region.1.cell", "C-03") is None
    app.press("design:next")
    app.press("design:next")
    assert app.design.page == PAGES[-1]
    assert app.edit("hybrid.alt_lo", "15") is None
    app.press("design:next")
    assert app.screen == "preview", app.message
    sc = app.preview_scenario
    assert sc.world_size == 1000 and [r.fronts for r in sc.regions] == [7, 7]
    assert sc.regions[1].cell == "C-03" and sc.team_counts["hybrid"] == 1
    assert sc.manual_limit_violations() == []
    assert app.preview_image(200).shape == (200, 200, 3)
    app.press("preview:start")  # the manual's tutorial page comes before the game
    assert app.screen == "tutorial"
    app.press("tutorial:start")
    assert app.screen == "game" and app.session.scenario is sc


def test_designer_reports_overlaps_found_by_the_scenario_validation():
    """Two facilities on the same cells are reported by build() and block the preview."""
    app = App()
    app.press("open_world")
    d = app.design
    d.values["hospital.0.cell"] = d.values["house.0.cell"]
    app.press("design:next")
    app.press("page:team")
    app.press("design:next")
    assert app.screen == "designer" and app.error and "overlap" in app.message


def test_placing_a_cell_by_clicking_the_preview():
    """With a cell field focused, a click on the preview map places the object there."""
    from fcplan.game.screens import PREVIEW_RECT

    app = App()
    app.press("open_world")
    app.press("page:fire")
    app.press("focus:region.0.cell")
    px, py, pw, _ = PREVIEW_RECT
    app.click(px + pw * 0.45, py + pw * 0.2)  # 1200 px map: x 540, y 240 -> F-03
    assert app.design.values["region.0.cell"] == "F-03" and app.focus is None


def test_designer_loads_a_scenario_file_or_shows_the_error(tmp_path):
    """Loading a TOML file previews it; a bad file gives a one-line error in the UI."""
    from fcplan.scenario import dump_scenario

    good = tmp_path / "mine.toml"
    dump_scenario(load_scenario(5), good)
    bad = tmp_path / "bad.toml"
    bad.write_text(good.read_text().replace("world_size = 1200", "world_size = -3"))
    app = App()
    app.press("open_world")
    app.press("focus:__file__")
    app.typed = str(bad)
    app.press("design:load")
    assert app.screen == "designer" and app.error and "world_size" in app.message
    assert app.load_file(str(good)) and app.screen == "preview"
    assert app.preview_scenario == load_scenario(5)


def test_typing_into_a_field_with_keys():
    """Keys type into the focused field; Backspace deletes; Enter commits."""
    app = App()
    app.press("open_world")
    app.press("page:fire")
    app.press("focus:fronts")
    app.key("backspace")
    app.key("backspace")
    for ch in "15":
        app.key(ch, ch)
    app.key("return")
    assert app.design.values["fronts"] == 15 and app.focus is None


def test_game_runs_to_the_evaluation_page_and_records(tmp_path):
    """A game in fast mode ends after the scenario's ticks, shows the evaluation with a grade,
    writes its recording, and the playback page writes a GIF of it."""
    from fcplan.metrics import GRADES

    sc = load_scenario("practice").replace(duration_s=3)
    app = App(sc, fast=True, frame_ticks=7, record=tmp_path / "g.npz")
    app.key("2")
    app.click(*app.window_point(500, 500))
    while app.screen == "game":
        app.advance()
    assert app.screen == "evaluation" and app.final["manual"].grade in GRADES
    assert app.recording_path == tmp_path / "g.npz" and app.recording_path.exists()
    app.press("save_playback")
    assert app.screen == "playback"
    app.press("write_video")
    assert app.video_path == tmp_path / "g.gif" and app.video_path.stat().st_size > 0, app.message
    app.press("play_again")
    assert app.screen == "game" and app.session.tick == 0


def test_real_time_pace_follows_the_clock_and_speed():
    """Outside fast mode a wall second plays ticks_per_second x speed ticks; pause stops it."""
    sc = load_scenario("practice")
    app = App(sc, speed=2.0)
    assert app.advance(0.5) == 10
    app.key("space")
    assert app.advance(1.0) == 0


def test_default_recording_path_uses_the_data_dir(monkeypatch, tmp_path):
    """Without --record games go to $FCPLAN_DATA_DIR/recordings/."""
    from fcplan.game.screens import default_recording_path

    monkeypatch.setenv("FCPLAN_DATA_DIR", str(tmp_path))
    p = default_recording_path(load_scenario("practice"), 3)
    assert p.parent == tmp_path / "recordings" and p.name.startswith("practice-seed3-")


def test_design_defaults_fit_every_world_size():
    """The default design builds at 800, 1000 and 1200 px."""
    d = Design()
    for size in (800, 1000, 1200):
        assert d.set("world_size", size) is None
        sc, problems = d.build()
        assert problems == [] and sc.world_size == size


def test_preview_is_drawn_again_only_when_the_design_changes():
    """The designer's preview image is kept while the design builds an equal scenario, and drawn
    again once a field changes."""
    app = App()
    app.press("open_world")
    first = app.preview_image(120)
    assert app.preview_image(120) is first
    assert app.edit("world_size", "800") is None
    second = app.preview_image(120)
    assert second is not first and app.preview_target().world_size == 800
    assert app.preview_image(100).shape == (100, 100, 3)


def test_recording_is_saved_once_per_game(tmp_path):
    """Ending a game saves its recording; saving again writes nothing new until the next game."""
    sc = load_scenario("practice").replace(duration_s=1)
    app = App(sc, fast=True, frame_ticks=5, record=tmp_path / "g.npz")
    while app.screen == "game":
        app.advance()
    path = app.save_recording()
    assert path == tmp_path / "g.npz" and path.exists()
    path.unlink()
    assert app.save_recording() == path and not path.exists()  # already saved: not rewritten
