"""Import games recorded by the original FireCommander GUI (its 13 ``.pkl`` files).

The 2020 GUI saved each game as 13 pickle files (FIRECOMMANDER.md section 7). Pickles can run
arbitrary code when loaded, so they are never given to :mod:`pickle`: :class:`RestrictedUnpickler`
interprets the opcode stream itself and builds only numbers, strings, bytes, lists, tuples, dicts,
sets and numeric/bool/string numpy arrays, dtypes and scalars (from plain arguments, shapes and
sizes checked before allocating; object arrays element by element). Any other global
(``os.system``, ``builtins.eval``, a class) is refused with :class:`~fcplan.errors.LegacyError`
before it is looked up, so it is never executed. Work and memory are bounded per file by
:class:`LegacyLimits` (bytes, values built, tree size of shared references, nesting, memo), and
every failure, hostile or accidental, is a ``LegacyError`` naming the file.

:func:`import_legacy` converts a folder into an fcplan recording (:mod:`fcplan.recording`), so the
same replay, video and metrics tools work on old data.

Modules: :mod:`~fcplan.legacy.unpickle` (reading files), :mod:`~fcplan.legacy.machine` (the
opcode interpreter), :mod:`~fcplan.legacy.arrays` (numpy values from plain arguments),
:mod:`~fcplan.legacy.limits` (the bounds),
:mod:`~fcplan.legacy.background` (the scenario of ``Background_Info.pkl``) and
:mod:`~fcplan.legacy.convert` (:func:`import_legacy`: fire events, agents and inputs on fcplan's
tick grid). The ``fcplan import-legacy`` command is :mod:`fcplan.cli.import_legacy`.

Examples
--------
>>> import io, pickle
>>> import numpy as np
>>> restricted_loads(pickle.dumps([1, "a", np.arange(3)]))[2].tolist()
[0, 1, 2]
>>> restricted_loads(pickle.dumps(print))
Traceback (most recent call last):
...
fcplan.errors.LegacyError: <bytes>: refused to load builtins.print: legacy files may only hold lists, tuples, numbers, strings and numpy arrays
"""

from __future__ import annotations

from fcplan.errors import LegacyError
from fcplan.legacy.background import scenario_dict_from_background
from fcplan.legacy.convert import LEGACY_FILES, TICKS_PER_SECOND, import_legacy
from fcplan.legacy.limits import DEFAULT_LIMITS, LegacyLimits
from fcplan.legacy.unpickle import RestrictedUnpickler, restricted_load, restricted_loads

__all__ = [
    "DEFAULT_LIMITS",
    "LEGACY_FILES",
    "LegacyError",
    "LegacyLimits",
    "RestrictedUnpickler",
    "TICKS_PER_SECOND",
    "import_legacy",
    "restricted_load",
    "restricted_loads",
    "scenario_dict_from_background",
]
