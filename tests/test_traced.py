"""Tests of the traced helper (tests.traced): peaks, errors and a helper that dies."""

from __future__ import annotations

import os

import pytest

from tests.traced import HelperError, traced_call


def test_the_peak_counts_the_call_only():
    """The peak is the call's own: a large call's bytes do not carry over to a small one. (The
    peak is taken over the traced memory at the call's start, so objects of the helper freed
    during the call lower it a little: CI once saw 21 bytes short of the 50 MiB; 64 KiB of
    slack.)"""
    _, large = traced_call(bytes, 50 * 2**20)
    _, small = traced_call(bytes, 10)
    assert large >= 50 * 2**20 - 2**16
    assert 1000 * small < 50 * 2**20


def test_an_exception_is_raised_again_with_the_helpers_traceback():
    """What the call raised is raised here, with a note giving where in the helper."""
    with pytest.raises(ValueError, match="invalid literal") as info:
        traced_call(int, "x")
    assert any("traced helper" in note for note in info.value.__notes__)


def test_a_helper_that_dies_is_an_error_and_the_next_call_starts_a_new_one():
    """A call that kills the helper raises HelperError naming its exit code; the next call runs
    in a fresh helper."""
    with pytest.raises(HelperError, match="exit code 3"):
        traced_call(os._exit, 3)
    assert traced_call(len, "abc")[0] == 3


def test_the_call_runs_in_the_callers_working_folder(tmp_path, monkeypatch):
    """The helper follows this process's working folder at every call, so relative paths a call
    writes land where they would here (a hostile CLI case's outputs stay in the test's
    scratch folder, not in the checkout)."""
    traced_call(os.getcwd)  # a helper already running, started elsewhere
    monkeypatch.chdir(tmp_path)
    assert traced_call(os.getcwd)[0] == str(tmp_path)
    traced_call(_touch, "written-here")
    assert (tmp_path / "written-here").exists()


def _touch(name: str) -> None:
    with open(name, "w"):
        pass
