"""Play one sweep episode in a worker and return its result row (plain, JSON-able values).

:func:`play_episode` is the function every backend runs (in-process, a process pool, a Dask
worker). It never raises for a failing episode: any exception escaping
:func:`fcplan.run_episode` (or the scheduler's construction) is caught and returned as a row with
``status = "failed"`` and the ``error`` text, so the sweep records it and runs on.

Row columns (one per episode; :func:`fcplan.experiments.load_results` reads them back):

* identity: ``key``, ``scenario`` (as named in the sweep), ``difficulty``, ``scheduler`` (the
  variant's label), ``scheduler_name``, ``settings`` and ``overrides`` (JSON text), ``seed``,
  ``replan_period``, ``time_limit`` (NaN: the scheduler's own);
* problem size: ``n_agents``, ``n_perception``, ``n_action``, ``n_hybrid``, ``n_fronts``,
  ``world_size``, ``duration_s``, ``tasks_mean``/``tasks_max`` (task-graph nodes per replan,
  from :attr:`fcplan.SolveStats.size`);
* every key of :meth:`fcplan.EpisodeResult.summary` (``manual.*`` and ``reference2020.*``
  metrics, ``ticks``, ``wall_time_s``, ``replans``, ``fallbacks``, ``optimal_replans``,
  ``time_limit_replans``, ``solve_p50_ms``, ``solve_p95_ms``, ``bounded_replans``, ``gap_p50``,
  ``gap_max``, ``rounds_per_replan``, ``messages_per_replan``) plus ``solve_mean_ms``,
  ``solve_max_ms``;
* ``deterministic`` (the scheduler ran in a mode whose plans do not depend on the wall clock:
  its ``deterministic`` attribute) and ``fallback_majority`` (it fell back to greedy on more than
  half of its replans, so the scores are mostly greedy's);
* per replan (lists): ``replan_solve_ms``, ``replan_gap`` (the scheduler's proven relative
  optimality gap on its own model, NaN where it proves none), ``replan_tasks``, ``replan_agents``;
* ``status`` (``ok`` | ``failed``), ``error`` (``""`` or ``"ExcType: message"``),
  ``episode_wall_s`` (including scheduler construction), ``host``, ``finished_at`` (UTC ISO
  time), ``versions`` (JSON: fcplan, python, numpy and the solver libraries in this worker),
  ``code`` (JSON: the source digest, git commit and dirty flag of the code that played it,
  :func:`fcplan.provenance.code_identity`).

Examples
--------
>>> from fcplan.experiments.config import load_sweep_config
>>> spec = load_sweep_config({"scenarios": ["practice"], "schedulers": ["idle"], "seeds": [0],
...                           "overrides": {"duration_s": 5}}).episodes()[0]
>>> row = play_episode(spec)
>>> row["status"], row["scheduler"], row["seed"], row["ticks"]
('ok', 'idle', 0, 50)
"""

from __future__ import annotations

import datetime as _dt
import functools
import json
import math
import socket
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from fcplan import provenance

__all__ = ["play_episode", "library_versions", "code_version"]

_LIBRARIES = ("fcplan", "numpy", "scipy", "networkx", "ortools", "highspy", "cvxpy")


@functools.cache
def library_versions() -> str:
    """JSON text: the Python version and installed versions of fcplan and solver libraries."""
    return json.dumps(provenance.library_versions(_LIBRARIES), sort_keys=True)


@functools.cache
def code_version() -> str:
    """JSON text: :func:`fcplan.provenance.code_identity` (source digest, git commit, dirty)."""
    return json.dumps(provenance.code_identity(), sort_keys=True)


def _base_row(spec: Any) -> dict[str, Any]:
    s = spec.scenario
    counts = s.team_counts
    return {
        "key": spec.key,
        "scenario": spec.base_scenario,
        "difficulty": s.difficulty,
        "scheduler": spec.label,
        "scheduler_name": spec.scheduler,
        "settings": json.dumps(spec.settings, sort_keys=True),
        "overrides": json.dumps(spec.overrides, sort_keys=True),
        "seed": int(spec.seed),
        "replan_period": float(spec.replan_period),
        "time_limit": math.nan if spec.time_limit is None else float(spec.time_limit),
        "n_agents": len(s.agents),
        "n_perception": counts["perception"],
        "n_action": counts["action"],
        "n_hybrid": counts["hybrid"],
        "n_fronts": int(sum(r.fronts for r in s.regions)),
        "world_size": int(s.world_size),
        "duration_s": float(s.duration_s),
    }


def run_episode(*args: Any, **kwargs: Any) -> Any:
    """:func:`fcplan.run_episode` (a module-level name, so tests can substitute a failing one)."""
    from fcplan.episode import run_episode as _run

    return _run(*args, **kwargs)


def play_episode(spec: Any, runtime: dict[str, Callable[..., Any]] | None = None) -> dict[str, Any]:
    """Play the episode ``spec`` (an :class:`~fcplan.experiments.config.EpisodeSpec`).

    Parameters
    ----------
    spec : EpisodeSpec
    runtime : dict, optional
        Schedulers registered at run time in the parent (name -> factory), registered here
        first if this process does not know them (Dask workers).

    Returns
    -------
    dict
        The result row (see the module docstring); never raises for a failing episode.
    """
    from fcplan.experiments.tables import fallback_majority
    from fcplan.experiments.workers import register_runtime

    t0 = time.perf_counter()
    row = _base_row(spec)
    try:
        if runtime:
            register_runtime(runtime)
        from fcplan.scheduling import make_scheduler

        scheduler = make_scheduler(spec.scheduler, **spec.settings)
        res = run_episode(
            spec.scenario,
            scheduler,
            seed=spec.seed,
            replan_period=spec.replan_period,
            time_limit=spec.time_limit,
        )
        summary = res.summary()
        for k in ("scenario", "scheduler", "seed"):
            summary.pop(k, None)
        row.update(summary)
        row.update(
            deterministic=bool(getattr(scheduler, "deterministic", False)),
            fallback_majority=fallback_majority(summary),
        )
        ms = res.solve_times_s * 1e3
        tasks = [int(st.size.get("tasks", -1)) for st in res.solves]
        agents = [int(st.size.get("agents", -1)) for st in res.solves]
        known = [t for t in tasks if t >= 0]
        row.update(
            solve_mean_ms=float(ms.mean()) if ms.size else math.nan,
            solve_max_ms=float(ms.max()) if ms.size else math.nan,
            tasks_mean=float(np.mean(known)) if known else math.nan,
            tasks_max=float(max(known)) if known else math.nan,
            replan_solve_ms=[float(x) for x in ms],
            replan_gap=[float(x) for x in res.solve_gaps],
            replan_tasks=tasks,
            replan_agents=agents,
            status="ok",
            error="",
        )
    except Exception as exc:  # noqa: BLE001 - a failing episode is a result, not a crash
        row.update(status="failed", error=f"{type(exc).__name__}: {exc}".replace("\n", " "))
    row.update(
        episode_wall_s=time.perf_counter() - t0,
        host=socket.gethostname(),
        finished_at=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        versions=library_versions(),
        code=code_version(),
    )
    return row
