"""Tests of fcplan.cli.import_legacy: `fcplan import-legacy` writes a recording that replays."""

from __future__ import annotations

import pytest

from fcplan.cli import main
from fcplan.recording import load_recording
from tests.legacy.folders import write_legacy_folder


@pytest.fixture(scope="module")
def legacy(tmp_path_factory):
    """A synthetic legacy folder made from a practice episode, and the world that made it."""
    folder = tmp_path_factory.mktemp("legacy") / "Tim"
    world = write_legacy_folder(str(folder))
    return folder, world


def test_import_cli_and_replay(legacy, tmp_path, capsys):
    """`fcplan import-legacy` writes a recording that loads and replays to a GIF."""
    folder, _ = legacy
    out = tmp_path / "old.npz"
    assert main(["import-legacy", str(folder), "--out", str(out)]) == 0
    assert "cells burned" in capsys.readouterr().out
    rec = load_recording(out)
    assert rec.source == "legacy"
    gif = tmp_path / "old.gif"
    assert main(["replay", str(out), "--video", str(gif), "--size", "96", "--speed", "60"]) == 0
    with pytest.raises(Exception, match="seed"):
        rec.resimulate()
