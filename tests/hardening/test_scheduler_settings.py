"""Every setting of every registered scheduler given hostile values (issue 17, specs): through
:func:`fcplan.make_scheduler`, the one validation path of ``run``, ``compare`` and ``sweep``, a
value is either refused with one line naming the scheduler and the setting, or accepted (a
scheduler is built); never another exception. ``bench/audit_hardening.py --only specs`` plays
the accepted ones and lists them (a value a scheduler accepts may still be meaningless: its
owner decides)."""

from __future__ import annotations

import inspect
import math

import pytest

from fcplan.errors import FcplanError
from fcplan.scheduling import available_schedulers, make_scheduler, scheduler_factory

VALUES = (math.nan, math.inf, -math.inf, -1, 0, 1e-300, 1e300, 10**20, "x", "", True, [1], None)


def _settings() -> list[tuple[str, str]]:
    out = []
    kinds = (inspect.Parameter.KEYWORD_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    for name in available_schedulers():
        try:
            params = inspect.signature(scheduler_factory(name)).parameters.values()
        except (TypeError, ValueError):  # a factory without a signature: nothing to enumerate
            continue
        out += [(name, p.name) for p in params if p.kind in kinds]
    return out


SETTINGS = _settings()


def test_the_settings_of_the_built_in_schedulers_are_enumerated():
    """Every built-in scheduler with settings contributes some (so the test below covers them)."""
    names = {n for n, _ in SETTINGS}
    assert {"greedy", "routing", "cbba", "milp", "random"} <= names


@pytest.mark.parametrize("scheduler, setting", SETTINGS)
def test_a_hostile_setting_is_refused_in_one_line_or_accepted(scheduler, setting):
    """make_scheduler(scheduler, setting=value) for each hostile value: a scheduler, or one
    FcplanError line that names the scheduler and the setting."""
    for value in VALUES:
        try:
            built = make_scheduler(scheduler, **{setting: value})
        except FcplanError as exc:
            message = str(exc)
            assert "\n" not in message and scheduler in message and setting in message, message
        else:
            assert callable(getattr(built, "plan", None))
