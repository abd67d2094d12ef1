"""Optional libraries: import them lazily, or fail with the extra that installs them.

Examples
--------
>>> require("math", "plot").sqrt(4.0)
2.0
>>> require("no_such_module_xyz", "plot")
Traceback (most recent call last):
...
fcplan.experiments.optional.MissingDependencyError: this needs no_such_module_xyz: pip install "fcplan[plot]" (from a checkout: pip install -e ".[plot]")
"""

from __future__ import annotations

import importlib
from types import ModuleType

from fcplan.errors import FcplanError, install_hint

__all__ = ["MissingDependencyError", "require"]


class MissingDependencyError(FcplanError, ImportError):
    """An optional library is not installed; the message names the extra to install."""


def require(module: str, extra: str) -> ModuleType:
    """Import ``module`` or raise :class:`MissingDependencyError` naming ``fcplan[extra]``."""
    try:
        return importlib.import_module(module)
    except ImportError:
        top = module.split(".")[0]
        raise MissingDependencyError(f"this needs {top}: {install_hint(extra)}") from None
