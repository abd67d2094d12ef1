"""Tests for fcplan.settings: the setting checks every scheduler (and the task env's altitude
options) share, their one-line errors, and the one altitude range."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.errors import EnvError, FcplanError
from fcplan.scheduling import make_scheduler
from fcplan.settings import (
    MAX_ALTITUDE_M,
    SettingError,
    altitude_setting,
    bool_setting,
    choice_setting,
    float_setting,
    int_setting,
)

#: every built-in scheduler with altitude settings, and the ones it takes
ALTITUDES = {
    "greedy": ("watch_altitude", "search_altitude", "dump_altitude"),
    "routing": ("watch_altitude", "search_altitude", "dump_altitude"),
    "milp": ("watch_altitude", "search_altitude", "dump_altitude"),
    "cbba": ("watch_altitude", "search_altitude", "dump_altitude"),
    "oracle": ("watch_altitude", "search_altitude", "dump_altitude"),
}
BAD_ALTITUDES = (0, 0.0, -1.0, math.nan, math.inf, MAX_ALTITUDE_M + 1, True, "70", None)
GOOD_ALTITUDES = (1e-3, 35, 70.0, np.float32(100.0), MAX_ALTITUDE_M)


def test_setting_helpers_refuse_types_nan_and_ranges():
    """int_setting refuses bools, floats and out-of-range ints; float_setting refuses NaN, inf,
    bools, strings and values outside its (open or closed) interval; bool_setting and
    choice_setting accept only their values."""
    assert int_setting("n", np.int64(3), 1, 5) == 3
    for bad in (True, 2.0, "2", 0, 6, None):
        with pytest.raises(SettingError):
            int_setting("n", bad, 1, 5)
    assert float_setting("x", 1, 0, 1) == 1.0
    for bad in (float("nan"), float("inf"), True, "1", 0, 1.0):
        with pytest.raises(SettingError):
            float_setting("x", bad, 0, 1, lo_open=True, hi_open=True)
    assert bool_setting("d", np.bool_(True)) is True
    with pytest.raises(SettingError):
        bool_setting("d", 1)
    assert choice_setting("c", "a", ("a", "b")) == "a"
    with pytest.raises(SettingError, match="one of a, b"):
        choice_setting("c", "z", ("a", "b"))


def test_the_scheduling_module_re_exports_the_same_objects():
    """fcplan.scheduling's setting helpers and SettingError are these very objects (one
    definition, two import paths)."""
    import fcplan.scheduling as sch

    for name in ("SettingError", "int_setting", "float_setting", "bool_setting", "choice_setting"):
        assert getattr(sch, name) is globals()[name]


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_altitude_setting_is_the_open_closed_interval(z):
    """altitude_setting accepts exactly the finite numbers in (0, MAX_ALTITUDE_M] and returns
    them as floats; anything else is a one-line SettingError naming the setting and the range."""
    if math.isfinite(z) and 0.0 < z <= MAX_ALTITUDE_M:
        assert altitude_setting("watch_altitude", z) == z
    else:
        with pytest.raises(SettingError, match=r"^bad setting watch_altitude=.*: must be a "):
            altitude_setting("watch_altitude", z)


@pytest.mark.parametrize(("scheduler", "setting"),
                         [(s, a) for s, names in ALTITUDES.items() for a in names])  # fmt: skip
def test_every_scheduler_takes_the_same_altitudes(scheduler, setting):
    """Every built-in scheduler's watch, search and dump altitude settings take the same values,
    (0, 10000] m, and refuse the rest with the same one-line message naming the scheduler (a
    sweep that is valid for one scheduler's altitudes is valid for all)."""
    for z in GOOD_ALTITUDES:
        make_scheduler(scheduler, **{setting: z})
    for z in BAD_ALTITUDES:
        if z is None and setting in ("dump_altitude", "search_altitude"):
            continue  # (None is their default: the top of the bounds / the best detection)
        with pytest.raises(SettingError) as err:
            make_scheduler(scheduler, **{setting: z})
        msg = str(err.value)
        assert "\n" not in msg and msg.startswith(
            f"scheduler {scheduler!r}: bad setting {setting}="
        )
        assert isinstance(err.value, FcplanError)


@pytest.mark.parametrize("option", ["watch_altitude", "search_altitude", "dump_altitude"])
def test_the_task_env_takes_the_schedulers_altitudes(option):
    """The task env's altitude options take the schedulers' range too and refuse the rest with
    an EnvError naming the option (``dump_altitude`` also takes None and "watch")."""
    from fcplan.env.task import TaskEnv

    for z in GOOD_ALTITUDES:
        assert getattr(TaskEnv("practice", max_steps=1, **{option: z}), option) == float(z)
    for z in BAD_ALTITUDES:
        if z is None and option == "dump_altitude":
            continue
        with pytest.raises(EnvError, match=rf"^{option}: must be .*\(0, 10000\]"):
            TaskEnv("practice", max_steps=1, **{option: z})
