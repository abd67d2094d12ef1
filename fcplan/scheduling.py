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

Time limits. A scheduler honours ``time_limit`` (wall seconds per call) itself: model building
counts, its solver gets the time left, an anytime search looks at the clock. :func:`solve`
reports the limit the call was held to (:func:`effective_time_limit`) and any overrun. A Python
call cannot be interrupted from outside, so each scheduler has a *floor*: what it does before it
can look at the clock, plus greedy's plan when it gives up (``bench/bench_time_limits.py``).

A time-out is a fallback, never an idle team. A plan **comes from a time-out** when the
scheduler says so (``status="time_limit"``, or ``partial=True``: it knows the plan is
unfinished) or when a scheduler whose plans may depend on the clock (it does not declare
``deterministic = True``) used up its limit; raising ``TimeoutError`` is a time-out with no plan.
Such a plan is replaced by greedy's
(``status="fallback"``, ``timed_out=True``, the reason in ``message``) if it is ``partial`` or
leaves the **team idle** (:func:`idle_team`): agents have work but none gets a route. An agent
has work when it is available (not ``HOMING``) and can reach (:attr:`fcplan.taskgraph.TaskGraph.
reachable`) a fire task, if it has water, or else a task of positive value, if it has a camera.
A plan that routes some agents with work is the scheduler's answer (a scheduler that knows it
stopped before planning some role says ``partial``); without a time-out an idle team is a
decision and stands (``idle`` does that on purpose).

Schedulers are found by name: built-ins and third-party packages register a factory in the
``fcplan.schedulers`` entry-point group (``name = "module:Factory"``); :func:`register_scheduler`
adds one at run time (handy in notebooks). The built-ins are listed once, in the entry-point
table of fcplan's ``pyproject.toml``: an installed fcplan reads it from its package metadata, a
source checkout without metadata (``PYTHONPATH=.``) from the ``pyproject.toml`` next to the package.

Settings. :func:`make_scheduler` is the one place where a scheduler spec (``"name:key=value"``
or a name plus keyword settings) becomes a scheduler, for every command and API: an unknown
name, an unknown setting, a malformed spec, and *any* exception a factory raises while checking
its settings become one :class:`~fcplan.errors.FcplanError` line naming the scheduler, the
setting and the reason (``scheduler 'milp': bad setting slots=0: slots must be >= 1``).
Factories check their settings at construction with the helpers of :mod:`fcplan.settings`
(:func:`int_setting`, :func:`float_setting`, :func:`~fcplan.settings.altitude_setting`,
:func:`bool_setting`, :func:`choice_setting`: types, ranges, NaN; re-exported here), which raise
:class:`SettingError`. A scheduler whose plans may depend on the wall clock offers a
``deterministic`` setting (work limits instead of time limits, fixed seeds, one worker);
:func:`supports_deterministic` tells whether a factory takes it, and
:func:`deterministic_settings` / :func:`deterministic_spec` turn it on unless the settings set
it: the one rule by which comparisons, sweeps, demonstrations and the env's experts
(:class:`~fcplan.env.motion_expert.PlanFollower`, its batched form) run schedulers in their
deterministic modes by default. :func:`make_scheduler` itself (and so ``run_episode``) uses the
scheduler's own defaults.

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
import inspect
import math
import re
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
from fcplan.settings import (
    SettingError,
    bool_setting,
    choice_setting,
    float_setting,
    int_setting,
)
from fcplan.settings import show_value as _show
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode

__all__ = [
    "Scheduler", "SolveStats", "STATUSES", "SettingError", "make_scheduler", "scheduler_factory",
    "supports_deterministic", "deterministic_settings", "deterministic_spec", "int_setting",
    "float_setting", "bool_setting", "choice_setting",
    "parse_scheduler_spec", "register_scheduler", "available_schedulers", "solve", "settle",
    "effective_time_limit", "idle_team",
]  # fmt: skip

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
        The limit the call was held to: the caller's, else the scheduler's own default
        (:func:`effective_time_limit`; None: no limit).
    overrun_s : float
        Wall time beyond ``time_limit_s`` (0 when within it), measured by :func:`solve`.
    solver_s : float
        Wall time of the scheduler's own call (no validation, no fallback), by :func:`solve`.
    timed_out : bool
        The clock stopped the scheduler (module docstring, or it raised ``TimeoutError``).
    partial : bool
        The scheduler's limit stopped it before its plan was complete (:func:`solve` falls back).
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
    solver_s: float = 0.0
    timed_out: bool = False
    partial: bool = False

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


@functools.cache
def _entry_points() -> dict[str, EntryPoint]:
    """Scheduler name -> entry point, for every entry point in :data:`GROUP`.

    Without fcplan's package metadata (a source checkout on ``PYTHONPATH``) the built-ins come
    from ``pyproject.toml``; installed third-party entry points are added either way.

    Read once per process: ``importlib.metadata.entry_points`` reads every installed
    distribution's metadata, milliseconds a call (``bench/README.md``, "The scheduler registry
    is read once per process"). A name not found is looked up again once
    (:func:`scheduler_factory`), so a plug-in installed while the process runs (a notebook's
    ``pip install``) is still found.
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


def scheduler_factory(name: str) -> Callable[..., Scheduler]:
    """The factory registered under ``name`` (run-time registrations first).

    Raises
    ------
    fcplan.errors.UnknownNameError
        If no scheduler has that name (the message lists the known ones).
    """
    if not isinstance(name, str):
        raise FcplanError(f"schedulers are given by registered name, got {_show(name)}")
    if name in _RUNTIME:
        return _RUNTIME[name]
    eps = _entry_points()
    if name not in eps:  # installed since the table was read?
        _entry_points.cache_clear()
        eps = _entry_points()
    if name not in eps:
        raise UnknownNameError(
            f"unknown scheduler {name!r}; known schedulers: {', '.join(available_schedulers())}"
        )
    try:
        return eps[name].load()
    except Exception as exc:  # noqa: BLE001 - a broken plug-in is one line too
        raise FcplanError(
            f"scheduler {name!r} cannot be loaded: {type(exc).__name__}: {_show(str(exc))}"
        ) from None


def _accepted(factory: Callable[..., Any]) -> tuple[str, ...] | None:
    """Keyword settings ``factory`` accepts, or None when it takes ``**kwargs`` (or hides its
    signature)."""
    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return None
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return None
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return tuple(p.name for p in params if p.kind in kinds)


def supports_deterministic(name: str) -> bool:
    """Whether the scheduler ``name`` takes a ``deterministic`` setting.

    A factory says so with a ``supports_deterministic`` attribute, or else by having a
    ``deterministic`` parameter. Comparisons and sweeps pass ``deterministic=True`` to exactly
    these schedulers unless the wall-time mode is chosen.

    Examples
    --------
    >>> supports_deterministic("routing"), supports_deterministic("greedy")
    (True, False)
    """
    factory = scheduler_factory(name.split(":")[0].strip())
    flag = getattr(factory, "supports_deterministic", None)
    if isinstance(flag, bool):
        return flag
    accepted = _accepted(factory)
    return accepted is not None and "deterministic" in accepted


def deterministic_settings(name: str, settings: dict[str, Any]) -> dict[str, Any]:
    """``settings`` with ``deterministic=True`` added when the scheduler ``name`` has a
    deterministic mode (:func:`supports_deterministic`) and ``settings`` do not set it: the one
    rule by which comparisons, sweeps, demonstrations and the experts run schedulers in their
    deterministic modes by default.

    Examples
    --------
    >>> deterministic_settings("routing", {"time_limit": 0.05})
    {'time_limit': 0.05, 'deterministic': True}
    >>> deterministic_settings("routing", {"deterministic": False})
    {'deterministic': False}
    >>> deterministic_settings("greedy", {})
    {}
    """
    if "deterministic" in settings or not supports_deterministic(name):
        return dict(settings)
    return {**settings, "deterministic": True}


def deterministic_spec(spec: str) -> str:
    """The scheduler spec ``spec`` in its deterministic mode (:func:`deterministic_settings`):
    ``":deterministic=true"`` appended when that adds the setting, else ``spec`` itself.

    Examples
    --------
    >>> deterministic_spec("cbba:max_rounds=50"), deterministic_spec("greedy")
    ('cbba:max_rounds=50:deterministic=true', 'greedy')
    """
    name, settings = parse_scheduler_spec(spec)
    if (
        "deterministic" in deterministic_settings(name, settings)
        and "deterministic" not in settings
    ):
        return f"{spec}:deterministic=true"
    return spec


def make_scheduler(name: str, **settings: Any) -> Scheduler:
    """Create a scheduler by registered name, passing ``settings`` to its factory.

    ``name`` may carry settings as a spec, ``"routing:deterministic=true"``
    (:func:`parse_scheduler_spec`); keyword ``settings`` override those. This is the one
    validation path of scheduler specs (see the module docstring).

    Raises
    ------
    fcplan.errors.UnknownNameError
        If no scheduler has that name (the message lists the known ones).
    SettingError
        An unknown setting, or one the factory refuses (any exception it raises), named with
        the scheduler and the reason, on one line.
    fcplan.errors.FcplanError
        A malformed spec.

    Examples
    --------
    >>> make_scheduler("greedy:route_length=0")
    Traceback (most recent call last):
    ...
    fcplan.settings.SettingError: scheduler 'greedy': bad setting route_length=0: must be an integer in 1..1000
    """
    if not isinstance(name, str):
        raise FcplanError(f"schedulers are given by registered name, got {_show(name)}")
    if ":" in name:
        name, spec_settings = parse_scheduler_spec(name)
        settings = {**spec_settings, **settings}
    name = name.strip()
    factory = scheduler_factory(name)
    accepted = _accepted(factory)
    if accepted is not None:
        for key, value in settings.items():
            if key not in accepted:
                known = ", ".join(accepted) or "none"
                raise SettingError(
                    key, f"unknown setting; {name} takes: {known}", value=value, scheduler=name
                )
    try:
        return factory(**settings)
    except SettingError as exc:
        raise exc.for_scheduler(name) from None
    except Exception as exc:  # noqa: BLE001 - any refusal of the settings is one line
        raise _setting_error(name, settings, exc) from None


def _setting_error(name: str, settings: dict[str, Any], exc: Exception) -> FcplanError:
    """A factory's exception as a :class:`SettingError` naming the setting it is about: the
    first setting its message mentions, else the only one given (a plain one-line
    :class:`~fcplan.errors.FcplanError` when no setting was given)."""
    reason = " ".join(str(exc).split()) or type(exc).__name__
    if len(reason) > 200:
        reason = reason[:197] + "..."
    if not settings:
        return FcplanError(f"scheduler {name!r} cannot be created: {type(exc).__name__}: {reason}")
    if not isinstance(exc, (ValueError, TypeError)):  # say what kind of failure it was
        reason = f"{type(exc).__name__}: {reason}"
    named = [k for k in settings if re.search(rf"(?<![\w]){re.escape(k)}(?![\w])", reason)]
    if named or len(settings) == 1:
        key = (named or list(settings))[0]
        return SettingError(key, reason, value=settings[key], scheduler=name)
    given = ", ".join(f"{k}={_show(v)}" for k, v in settings.items()) or "none"
    return SettingError(f"settings ({given})", reason, scheduler=name)


@functools.cache
def _fallback_scheduler() -> Scheduler:
    """The greedy scheduler that stands in for a failed one (stateless: one per process)."""
    return make_scheduler("greedy")


def effective_time_limit(scheduler: Scheduler, time_limit: float | None) -> float | None:
    """The wall-time limit a call of ``scheduler`` is held to: ``time_limit``, else the
    scheduler's own default (a finite positive ``time_limit`` attribute), else None.

    Examples
    --------
    >>> effective_time_limit(make_scheduler("routing"), None)
    0.1
    >>> effective_time_limit(make_scheduler("greedy"), None) is None
    True
    """
    if time_limit is not None:
        return float(time_limit)
    own = getattr(scheduler, "time_limit", None)
    if not isinstance(own, (int, float)) or isinstance(own, bool):
        return None
    return float(own) if math.isfinite(own) and own > 0 else None


def idle_team(plan: Plan, graph: TaskGraph) -> str:
    """ "" if ``plan`` routes some agent with work or no agent has work (module docstring), else
    what the idle team could have done, per role (for a message).

    Examples
    --------
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(4, 12, np.random.default_rng(0))
    >>> idle_team(Plan(), g)
    '2 action agents (6 fire tasks reachable) and 2 perception agents (12 tasks reachable)'
    >>> idle_team(make_scheduler("greedy").plan(g, time_limit=None, rng=None), g)
    ''
    """
    free = graph.agent_mode != Mode.HOMING
    useful = graph.reachable & (graph.task_value > 0)[None, :]
    fire = graph.task_kind == TaskKind.FIRE
    water = graph.agent_can_act & (graph.agent_tank > 0)
    routed = np.array([bool(plan.routes.get(a)) for a in graph.agent_ids], dtype=bool)
    roles = (
        ("action", free & water & useful[:, fire].any(axis=1), useful[:, fire], "fire tasks"),
        ("perception", free & graph.agent_can_sense & ~water & useful.any(axis=1), useful, "tasks"),
    )
    if routed[roles[0][1] | roles[1][1]].any():
        return ""
    said = [f"{int(m.sum())} {role} agents ({int(t[m].any(axis=0).sum())} {what} reachable)"
            for role, m, t, what in roles if m.any()]  # fmt: skip
    return " and ".join(said)


def _timeout_fallback(
    scheduler: Scheduler, plan: Plan, graph: TaskGraph, wall: float, limit: float | None
) -> tuple[bool, str]:
    """``(timed_out, reason)``: whether the clock stopped ``scheduler`` on this call, and why
    its plan must be replaced by greedy's ("" when it stands; module docstring)."""
    stats = plan.stats if isinstance(plan.stats, SolveStats) else SolveStats()
    clock_bound = getattr(scheduler, "deterministic", False) is not True
    used_up = limit is not None and wall >= limit and clock_bound
    timed_out = stats.status == "time_limit" or stats.partial or used_up
    if not timed_out:
        return False, ""
    why = f"time-out ({stats.status}, {wall:.4g} s of {limit if limit is not None else 'no'} s)"
    if stats.partial:
        return True, f"{why}: the scheduler reported a partial plan"
    idle = idle_team(plan, graph)
    return True, f"{why}: the plan left the team idle: {idle}" if idle else ""


def solve(
    scheduler: Scheduler, graph: TaskGraph, *, time_limit: float | None, rng: np.random.Generator
) -> Plan:
    """Run ``scheduler`` on ``graph``; always return a valid plan carrying :class:`SolveStats`.

    A scheduler that raises, returns an invalid plan, or returns a plan that comes from a
    time-out and is partial or leaves the team idle (module docstring) is replaced by ``greedy``
    for this replan (``status="fallback"``, the reason in ``message``). The stats record the
    wall time of the whole call, the limit it was held to and any overrun.
    """
    t0 = time.perf_counter()
    try:
        plan: Plan | Exception = scheduler.plan(graph, time_limit=time_limit, rng=rng)
    except Exception as exc:  # noqa: BLE001 - an episode must survive any solver failure
        plan = exc
    solver_s = time.perf_counter() - t0
    return settle(scheduler, graph, plan, t0, solver_s, time_limit=time_limit, rng=rng)


def settle(
    scheduler: Scheduler,
    graph: TaskGraph,
    plan: Plan | Exception,
    t0: float,
    solver_s: float,
    *,
    time_limit: float | None,
    rng: np.random.Generator,
) -> Plan:
    """:func:`solve` after the scheduler's call (``plan`` or what it raised; ``solver_s`` s of a
    call begun at ``perf_counter()`` ``t0``): validation, time-outs, the fallback, the stats."""
    limit = effective_time_limit(scheduler, time_limit)
    message, timed_out = "", False
    try:
        if isinstance(plan, Exception):
            raise plan
        validate_plan(plan, graph)
        timed_out, message = _timeout_fallback(scheduler, plan, graph, solver_s, limit)
        ok: Plan | None = None if message else plan
    except Exception as exc:  # noqa: BLE001 - an episode must survive any solver failure
        message = f"{type(exc).__name__}: {exc}"
        timed_out = isinstance(exc, TimeoutError)  # the scheduler says the clock stopped it
        ok = None
    if ok is None:
        ok = _fallback_scheduler().plan(graph, time_limit=None, rng=rng)
        validate_plan(ok, graph)
        stats = SolveStats(status="fallback", message=message)
    else:
        stats = ok.stats if isinstance(ok.stats, SolveStats) else SolveStats()
    wall = time.perf_counter() - t0
    overrun = max(wall - limit, 0.0) if limit is not None else 0.0
    # every replan records the graph's size (the scheduler's own size keys win)
    size = {"agents": graph.n_agents, "tasks": graph.n_tasks, **stats.size}
    return ok.with_stats(replace(stats, wall_time_s=wall, time_limit_s=limit, overrun_s=overrun,
                                 solver_s=solver_s, timed_out=timed_out, size=size))  # fmt: skip
