"""The scheduling contract: the ``Scheduler`` protocol, solve statistics and the name registry.

A scheduler turns a :class:`fcplan.taskgraph.TaskGraph` into a :class:`fcplan.plan.Plan`::

    class Scheduler(Protocol):
        name: str
        def plan(self, graph, *, time_limit, rng) -> Plan: ...

It may attach a :class:`SolveStats` to the plan (``plan.with_stats(...)``). :func:`solve` is how
the episode loop calls a scheduler: it measures the wall time, validates the plan, and if the
scheduler raises, returns something that is not a valid plan, it falls back to ``greedy`` for that
replan and records why in the stats (``status="fallback"``). An episode never dies because a
solver did.

Schedulers are found by name: built-ins and third-party packages register a factory in the
``fcplan.schedulers`` entry-point group (``name = "module:Factory"``); :func:`register_scheduler`
adds one at run time (handy in notebooks). The built-ins are listed once, in the entry-point table
of fcplan's ``pyproject.toml``: an installed fcplan reads it from its package metadata, a source
checkout without metadata (``PYTHONPATH=.``) from the ``pyproject.toml`` next to the package.

Examples
--------
>>> from fcplan.scheduling import make_scheduler, available_schedulers
>>> {"greedy", "idle", "random"} <= set(available_schedulers())
True
>>> make_scheduler("greedy").name
'greedy'
"""

from __future__ import annotations

import functools
import time
import tomllib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from importlib.metadata import EntryPoint, PackageNotFoundError, distribution, entry_points
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np

from fcplan.errors import FcplanError, UnknownNameError
from fcplan.plan import Plan, validate_plan
from fcplan.taskgraph import TaskGraph

__all__ = [
    "Scheduler",
    "SolveStats",
    "STATUSES",
    "make_scheduler",
    "parse_scheduler_spec",
    "register_scheduler",
    "available_schedulers",
    "solve",
]

#: Possible :attr:`SolveStats.status` values.
STATUSES = ("optimal", "feasible", "time_limit", "fallback", "heuristic")

#: The entry-point group schedulers register in.
GROUP = "fcplan.schedulers"
_PYPROJECT = Path(__file__).resolve().parents[1] / "pyproject.toml"
_RUNTIME: dict[str, Callable[..., Any]] = {}


@dataclass(frozen=True, slots=True)
class SolveStats:
    """How one replan's plan was found.

    Attributes
    ----------
    status : str
        ``optimal`` (proved), ``feasible`` (stopped early with a plan), ``time_limit`` (the limit
        stopped the solver), ``heuristic`` (a method that proves nothing, e.g. greedy), or
        ``fallback`` (the scheduler failed; greedy's plan was used).
    objective, bound, gap : float
        Objective of the plan, best proven bound and relative gap (NaN when not applicable).
    wall_time_s : float
        Wall time of the whole call, measured by :func:`solve`.
    size : dict
        Model size (e.g. variables, constraints, agents, tasks).
    message : str
        Why a fallback happened, or solver remarks.
    time_limit_s : float or None
        The limit the call was given.
    overrun_s : float
        Wall time beyond the limit (0 when within it), measured by :func:`solve`.
    """

    status: str = "heuristic"
    objective: float = float("nan")
    bound: float = float("nan")
    gap: float = float("nan")
    wall_time_s: float = 0.0
    size: dict = field(default_factory=dict)
    message: str = ""
    time_limit_s: float | None = None
    overrun_s: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        """Plain dict (for tables and JSON)."""
        return asdict(self)


@runtime_checkable
class Scheduler(Protocol):
    """What the episode loop needs from a scheduler."""

    name: str

    def plan(
        self, graph: TaskGraph, *, time_limit: float | None, rng: np.random.Generator
    ) -> Plan:  # pragma: no cover - protocol
        """Return a plan for ``graph`` within ``time_limit`` seconds (None: no limit)."""
        ...


@functools.cache
def _source_table(pyproject: Path) -> dict[str, str]:
    """The ``fcplan.schedulers`` entry-point table of a source checkout's ``pyproject.toml``
    (empty when there is none)."""
    try:
        doc = tomllib.loads(pyproject.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return {}
    return dict(doc.get("project", {}).get("entry-points", {}).get(GROUP, {}))


def _entry_points() -> dict[str, EntryPoint]:
    """Scheduler name -> entry point, for every entry point in :data:`GROUP`.

    Without fcplan's package metadata (a source checkout on ``PYTHONPATH``) the built-ins come
    from ``pyproject.toml``; installed third-party entry points are added either way.
    """
    table = {ep.name: ep for ep in entry_points(group=GROUP)}
    try:
        distribution("fcplan")
    except PackageNotFoundError:
        source = _source_table(_PYPROJECT)
        table = {**{n: EntryPoint(n, v, GROUP) for n, v in source.items()}, **table}
    return table


def available_schedulers() -> list[str]:
    """Names of every known scheduler (entry points, built-ins and run-time registrations)."""
    return sorted(set(_entry_points()) | set(_RUNTIME))


def register_scheduler(name: str, factory: Callable[..., Scheduler]) -> None:
    """Register ``factory(**settings) -> Scheduler`` under ``name`` for this process."""
    _RUNTIME[name] = factory


def parse_scheduler_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """Split ``"name:key=value:key=value"`` into the name and its settings.

    Values are read as ``true``/``false``, integers, floats, or else strings. This is how the
    CLI (``fcplan run -s``, ``fcplan compare --schedulers``) passes settings to a scheduler.

    Examples
    --------
    >>> parse_scheduler_spec("routing:deterministic=true:time_limit=0.05")
    ('routing', {'deterministic': True, 'time_limit': 0.05})
    >>> parse_scheduler_spec("greedy")
    ('greedy', {})
    """
    name, *parts = spec.split(":")
    settings: dict[str, Any] = {}
    for part in parts:
        key, sep, text = part.partition("=")
        if not sep or not key.strip():
            raise FcplanError(
                f"scheduler spec {spec!r}: settings are written name:key=value[:key=value...]"
            )
        settings[key.strip()] = _parse_value(text.strip())
    return name.strip(), settings


def _parse_value(text: str) -> Any:
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return text


def make_scheduler(name: str, **settings: Any) -> Scheduler:
    """Create a scheduler by registered name, passing ``settings`` to its factory.

    ``name`` may carry settings as a spec, ``"routing:deterministic=true"``
    (:func:`parse_scheduler_spec`); keyword ``settings`` override those.

    Raises
    ------
    fcplan.errors.UnknownNameError
        If no scheduler has that name (the message lists the known ones).
    """
    if ":" in name:
        name, spec_settings = parse_scheduler_spec(name)
        settings = {**spec_settings, **settings}
    if name in _RUNTIME:
        factory = _RUNTIME[name]
    else:
        eps = _entry_points()
        if name not in eps:
            raise UnknownNameError(
                f"unknown scheduler {name!r}; known schedulers: {', '.join(available_schedulers())}"
            )
        factory = eps[name].load()
    try:
        return factory(**settings)
    except TypeError as exc:
        raise FcplanError(f"scheduler {name!r}: bad settings {settings}: {exc}") from None


_FALLBACK: Scheduler | None = None


def _fallback_scheduler() -> Scheduler:
    global _FALLBACK
    if _FALLBACK is None:
        _FALLBACK = make_scheduler("greedy")
    return _FALLBACK


def solve(
    scheduler: Scheduler,
    graph: TaskGraph,
    *,
    time_limit: float | None,
    rng: np.random.Generator,
) -> Plan:
    """Run ``scheduler`` on ``graph``; always return a valid plan carrying :class:`SolveStats`.

    A scheduler that raises or returns an invalid plan is replaced by ``greedy`` for this
    replan (``status="fallback"``, the reason in ``message``).
    """
    t0 = time.perf_counter()
    message = ""
    try:
        plan = scheduler.plan(graph, time_limit=time_limit, rng=rng)
        validate_plan(plan, graph)
    except Exception as exc:  # noqa: BLE001 - an episode must survive any solver failure
        message = f"{type(exc).__name__}: {exc}"
        plan = None
    if plan is None:
        plan = _fallback_scheduler().plan(graph, time_limit=None, rng=rng)
        validate_plan(plan, graph)
        stats = SolveStats(status="fallback", message=message)
    else:
        stats = plan.stats if isinstance(plan.stats, SolveStats) else SolveStats()
    wall = time.perf_counter() - t0
    overrun = max(wall - time_limit, 0.0) if time_limit is not None else 0.0
    stats = replace(stats, wall_time_s=wall, time_limit_s=time_limit, overrun_s=overrun)
    return plan.with_stats(stats)
