"""Fixtures shared by the hardening tests."""

from __future__ import annotations

import pytest

from tests.hardening.options import Fixtures


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    """Valid inputs of every command: a 3-s scenario, its sweep file and two-episode results
    folder, a 3-s recording, a 12-s legacy folder, and special files (tests.hardening.options)."""
    return Fixtures.make(tmp_path_factory.mktemp("fixtures"))


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """Relative outputs and recorded games land in a scratch folder; the game runs headless."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FCPLAN_DATA_DIR", str(tmp_path))
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    return tmp_path
