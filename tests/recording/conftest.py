"""Shared fixtures of the recording tests."""

from __future__ import annotations

import pytest

from fcplan import run_episode


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Scenario #24 with greedy, seed 1, run once with a recording."""
    path = tmp_path_factory.mktemp("rec") / "24.npz"
    result = run_episode(24, "greedy", seed=1, record=path)
    return result, path
