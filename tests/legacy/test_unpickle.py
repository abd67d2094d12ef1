"""Tests of fcplan.legacy.unpickle: the restricted unpickler refuses code and loads plain data."""

from __future__ import annotations

import os
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.legacy import LEGACY_FILES, LegacyError, import_legacy, restricted_loads
from tests.legacy.folders import dump_pickle, write_legacy_folder


@pytest.fixture(scope="module")
def legacy(tmp_path_factory):
    """A synthetic legacy folder made from a practice episode, and the world that made it."""
    folder = tmp_path_factory.mktemp("legacy") / "Tim"
    world = write_legacy_folder(str(folder))
    return folder, world


class _Call:
    """Pickles as a call of ``func(*args)``: what an attacker would put in a .pkl file."""

    def __init__(self, func, *args):
        self.func, self.args = func, args

    def __reduce__(self):
        return (self.func, self.args)


def _payloads(marker):
    import builtins
    import subprocess

    return {
        "os.system": _Call(os.system, f"touch {marker}"),
        "builtins.eval": _Call(builtins.eval, f"open({str(marker)!r}, 'w')"),
        "builtins.open": _Call(builtins.open, str(marker), "w"),
        "subprocess.Popen": _Call(subprocess.Popen, ["touch", str(marker)]),
        "in an object array": np.array([_Call(os.system, f"touch {marker}")], dtype=object),
        "numpy.load": _Call(np.load, str(marker)),
    }


@pytest.mark.parametrize("kind", list(_payloads("x")))
def test_malicious_pickles_are_refused(legacy, tmp_path, kind):
    """A legacy file that tries to call a function is refused with a LegacyError naming the file
    and the global, and the call never happens."""
    folder, _ = legacy
    bad = tmp_path / "bad"
    bad.mkdir()
    for name in LEGACY_FILES:
        (bad / name).write_bytes((folder / name).read_bytes())
    marker = tmp_path / "pwned"
    dump_pickle(bad, "Lake_info.pkl", [[1, 2], _payloads(marker)[kind]])
    with pytest.raises(LegacyError, match="refused to load") as err:
        import_legacy(bad)
    assert "Lake_info.pkl" in str(err.value)
    assert not marker.exists()


def test_unknown_globals_are_refused_without_import():
    """A global naming a module that does not exist is refused as such (it is never imported)."""
    data = b"\x80\x02cno_such_module\nsomething\nq\x00)\x81q\x01."
    with pytest.raises(LegacyError, match="no_such_module.something"):
        restricted_loads(data)


@given(
    st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(),
        lambda inner: (
            st.lists(inner, max_size=4)
            | st.tuples(inner, inner)
            | st.dictionaries(st.text(max_size=5), inner, max_size=3)
        ),
        max_leaves=20,
    )
)
def test_plain_data_round_trips(value):
    """Lists, tuples, dicts, numbers and strings load exactly as pickle would load them."""
    for protocol in (2, 4):
        assert restricted_loads(pickle.dumps(value, protocol=protocol)) == value


def test_numpy_arrays_and_scalars_load():
    """numpy arrays of every plain dtype and numpy scalars load (protocols 2 and 4)."""
    value = [
        np.arange(6.0).reshape(2, 3),
        np.array([1, 2], np.int16),
        np.float64(2.5),
        np.int64(7),
        np.array(["ab", "c"]),
        np.zeros((0, 4)),
    ]
    for protocol in (2, 4):
        got = restricted_loads(pickle.dumps(value, protocol=protocol))
        for g, v in zip(got, value, strict=True):
            assert np.array_equal(g, v) and np.asarray(g).dtype == np.asarray(v).dtype
