"""Hypothesis over mutated valid files: the legacy pickle reader, the legacy folder importer and
the recording reader give a value or their own error for every input (never another exception),
each input within a time bound.

The default run is small and derandomized (a few seconds, the same inputs every run); the
``slow`` variants run thousands of inputs (``pytest -m slow tests/fuzz``). Crashes, hangs outside
Python code and memory are measured out of process by ``tests/fuzz/campaign.py`` (see
bench/README.md) and ``test_fuzz_adversarial.py``.
"""

from __future__ import annotations

import os
import pickle
import shutil
import tempfile
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fcplan.errors import LegacyError
from fcplan.legacy import LEGACY_FILES, import_legacy, restricted_loads
from fcplan.recording import RecordingError, load_recording
from tests.deadline import deadline
from tests.fuzz.cases import (
    EDIT_KINDS,
    ODD_VALUES,
    make_npz,
    mini_legacy_folder,
    mutate_bytes,
    mutate_value,
    npz_entries,
    outcome,
    pickle_seeds,
    short_recording,
)

#: seconds one input may take (the readers take milliseconds; generous for a loaded machine)
TIME_BOUND_S = 20.0
_COMMON = {
    "database": None,
    "deadline": None,
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.data_too_large],
}
FAST = settings(derandomize=True, **_COMMON)  # type: ignore[arg-type]
SLOW = settings(**_COMMON)  # type: ignore[arg-type]

EDITS = st.lists(
    st.tuples(
        st.sampled_from(EDIT_KINDS), st.integers(0, 2**31), st.binary(min_size=1, max_size=8)
    ),
    min_size=1,
    max_size=4,
)
SEEDS = pickle_seeds()


class _TooSlowError(Exception):
    pass


def check_clean(call: Callable[[], Any], clean: type[Exception]) -> str:
    """Run ``call`` within :data:`TIME_BOUND_S`; fail on any exception but ``clean``."""
    try:
        with deadline(TIME_BOUND_S, _TooSlowError):
            kind, message = outcome(call, clean)
    except _TooSlowError:
        pytest.fail(f"an input took more than {TIME_BOUND_S} s")
    assert kind != "traceback", message
    return kind


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A 12-s synthetic legacy folder."""
    path = str(tmp_path_factory.mktemp("fuzzlegacy") / "game")
    mini_legacy_folder(path)
    return path


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """The bytes of a 3-s recording."""
    return short_recording(str(tmp_path_factory.mktemp("fuzzrec") / "seed.npz"))


# ------------------------------------------------------------------------------- pickles
def _pickle_property(name: str, edits: list) -> None:
    data = mutate_bytes(SEEDS[name], edits)
    check_clean(lambda: restricted_loads(data, source="fuzz.pkl"), LegacyError)


@settings(FAST, max_examples=300)
@given(st.sampled_from(sorted(SEEDS)), EDITS)
def test_mutated_pickles(name, edits):
    """restricted_loads of a byte-edited valid pickle returns a value or raises LegacyError."""
    _pickle_property(name, edits)


@pytest.mark.slow
@settings(SLOW, max_examples=20_000)
@given(st.sampled_from(sorted(SEEDS)), EDITS)
def test_mutated_pickles_long(name, edits):
    """The same property over 20 000 random inputs."""
    _pickle_property(name, edits)


# ------------------------------------------------------------------------------- folders
LEGACY_EDIT = st.one_of(
    st.tuples(st.just("value"), st.integers(0, 10**6), st.sampled_from(range(len(ODD_VALUES)))),
    st.tuples(st.just("bytes"), EDITS, st.just(0)),
)


def _legacy_property(seed_folder: str, file: str, edit: tuple) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        game = os.path.join(tmp, "game")
        shutil.copytree(seed_folder, game)
        path = os.path.join(game, file)
        with open(path, "rb") as f:
            data = f.read()
        if edit[0] == "value":
            data = pickle.dumps(
                mutate_value(pickle.loads(data), edit[1], ODD_VALUES[edit[2]]), protocol=2
            )
        else:
            data = mutate_bytes(data, edit[1])
        with open(path, "wb") as f:
            f.write(data)
        check_clean(lambda: import_legacy(game), LegacyError)


@settings(FAST, max_examples=12)
@given(st.sampled_from(LEGACY_FILES), LEGACY_EDIT)
def test_mutated_legacy_folders(folder, file, edit):
    """import_legacy of a folder with one file's values (NaN, infinities, huge or negative
    numbers, wrong types) or bytes edited returns a recording or raises LegacyError."""
    _legacy_property(folder, file, edit)


@pytest.mark.slow
@settings(SLOW, max_examples=1_500)
@given(st.sampled_from(LEGACY_FILES), LEGACY_EDIT)
def test_mutated_legacy_folders_long(folder, file, edit):
    """The same property over 1 500 random folders."""
    _legacy_property(folder, file, edit)


# ------------------------------------------------------------------------------- recordings
REC_EDIT = st.tuples(st.sampled_from(["archive", "entry"]), st.integers(0, 10**6), EDITS)


def _recording_property(seed: bytes, edit: tuple) -> None:
    mode, which, edits = edit
    if mode == "archive":
        data = mutate_bytes(seed, edits)
    else:  # one entry's .npy bytes edited, the archive valid around it
        entries = npz_entries(seed)
        name = sorted(entries)[which % len(entries)]
        entries[name] = mutate_bytes(entries[name], edits)
        data = make_npz(entries)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "fuzz.npz")
        with open(path, "wb") as f:
            f.write(data)
        check_clean(lambda: load_recording(path), RecordingError)


@settings(FAST, max_examples=150)
@given(REC_EDIT)
def test_mutated_recordings(recording, edit):
    """load_recording of a byte-edited recording (its archive, or one entry re-packed) returns a
    recording or raises RecordingError."""
    _recording_property(recording, edit)


@pytest.mark.slow
@settings(SLOW, max_examples=20_000)
@given(REC_EDIT)
def test_mutated_recordings_long(recording, edit):
    """The same property over 20 000 random recordings."""
    _recording_property(recording, edit)
