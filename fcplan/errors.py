"""Exceptions raised at fcplan's boundaries.

Every error that bad input can cause is a subclass of :class:`FcplanError`. Its message is one line
that names where the problem is (file, field) and what is allowed, so the CLI can print it as is and
exit with status 2.

Examples
--------
>>> from fcplan.errors import ScenarioError
>>> str(ScenarioError("team.action.tank", "must be an integer in 1..15", got=0, source="my.toml"))
'my.toml: team.action.tank: must be an integer in 1..15 (got 0)'
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "FcplanError",
    "ScenarioError",
    "PlanError",
    "UnknownNameError",
    "EnvError",
    "LegacyError",
    "SeedError",
    "ArgumentError",
    "install_hint",
]

_MISSING = object()


def install_hint(extra: str) -> str:
    """How to install fcplan's optional ``extra``, from an index and from a source checkout.

    Examples
    --------
    >>> install_hint("video")
    'pip install "fcplan[video]" (from a checkout: pip install -e ".[video]")'
    """
    return f'pip install "fcplan[{extra}]" (from a checkout: pip install -e ".[{extra}]")'


class FcplanError(Exception):
    """Base class of every error fcplan raises for bad input."""


class ScenarioError(FcplanError, ValueError):
    """A scenario file or `Scenario` value is malformed or physically invalid.

    Parameters
    ----------
    field : str
        Dotted path of the offending field, e.g. ``"fire.regions[2].fuel"``.
    problem : str
        What is wrong and what is allowed, e.g. ``"must be a number in 2..20"``.
    got : Any, optional
        The offending value, shown in the message when given.
    source : str, optional
        The file (or scenario name) the value came from.
    """

    def __init__(self, field: str, problem: str, *, got: Any = _MISSING, source: str | None = None):
        self.field = field
        self.problem = problem
        self.got = None if got is _MISSING else got
        self.source = source
        self._got = got
        msg = f"{field}: {problem}"
        if got is not _MISSING:
            msg += f" (got {got!r})"
        if source:
            msg = f"{source}: {msg}"
        super().__init__(msg)

    def with_source(self, source: str) -> ScenarioError:
        """Return the same error attributed to ``source`` (a file path or scenario name)."""
        if self.source:
            return self
        return ScenarioError(self.field, self.problem, got=self._got, source=source)


class PlanError(FcplanError, ValueError):
    """A plan does not fit the task graph it was made for (unknown agent or task, wrong role,
    infeasible battery)."""


class UnknownNameError(FcplanError, KeyError):
    """A scenario or scheduler name is not known. The message lists the known names."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class EnvError(FcplanError, ValueError):
    """Bad environment argument or action (the message names the argument/agent and the
    allowed range). Also importable as ``fcplan.env.EnvError``."""


class LegacyError(FcplanError, ValueError):
    """A legacy file (the 2020 GUI's pickles) is unsafe, missing, or does not have the documented
    structure. Also importable as ``fcplan.legacy.LegacyError``."""


class SeedError(FcplanError, ValueError):
    """A seed that is not an integer >= 0, a ``numpy.random.SeedSequence``, a
    ``numpy.random.Generator`` (where one is taken) or None."""


class ArgumentError(FcplanError, ValueError):
    """A bad argument of a public function that no more specific class covers (the message
    names the argument, the allowed values and what it got)."""
