"""One scored episode: run a scheduler on a scenario and score it.

:func:`run_episode` plays a :class:`fcplan.mission.Mission` to its end: every ``replan_period``
simulated seconds, and at once when the team senses fire outside every fire task of the current
plan, it builds the task graph from the belief, asks the scheduler for a plan
(:func:`fcplan.scheduling.solve`: validated, with a greedy fallback), and turns it into agent
commands; between replans the world runs on the last plan. The episode ends after the scenario's
duration and is scored with both metric definitions (:func:`fcplan.metrics.compute_all`) into an
:class:`EpisodeResult`.

Examples
--------
>>> from fcplan import run_episode
>>> result = run_episode("practice", "greedy", seed=0)
>>> result.ticks
1800
>>> sorted(result.metrics)
['manual', 'reference2020']

A run whose scheduler fell back to greedy on more than half of its replans is flagged
(:attr:`EpisodeResult.fallback_majority`, also in :meth:`EpisodeResult.summary`): its score is
mostly greedy's, not the named scheduler's, and tables must say so.

>>> result.fallback_majority, fell_back_mostly(fallbacks=6, replans=10)
(False, True)
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.metrics import Metrics, Outcomes, compute_all, compute_outcomes
from fcplan.mission import EpisodeObserver, Mission, ScenarioLike, as_scenario
from fcplan.scenario import Scenario
from fcplan.scheduling import Scheduler, SolveStats, make_scheduler
from fcplan.taskgraph import TaskGraphParams
from fcplan.trace import Trace

if TYPE_CHECKING:
    from fcplan.recording import Recorder

__all__ = ["run_episode", "EpisodeResult", "fell_back_mostly"]


def fell_back_mostly(fallbacks: int, replans: int) -> bool:
    """Whether ``fallbacks`` are more than half of ``replans`` (none: False).

    The rule behind :attr:`EpisodeResult.fallback_majority` and the ``fallback_majority``
    column of comparisons, sweeps and reports.
    """
    return bool(replans > 0 and fallbacks > replans / 2)


@dataclass(frozen=True, eq=False)
class EpisodeResult:
    """Outcome of one episode.

    :attr:`fallbacks` counts the replans where greedy stood in; :attr:`fallback_majority` flags
    an episode where that happened on more than half of them.

    Attributes
    ----------
    scenario, scheduler : str
        Names.
    seed : int or None
    metrics : dict of str -> Metrics
        ``"manual"`` and ``"reference2020"``.
    trace : Trace
        Per-tick arrays (counts, facilities, agents).
    solves : list of SolveStats
        One per replan.
    replan_ticks : ndarray, (R,) int64
        Tick at which each replan happened.
    wall_time_s : float
        Wall time of the whole episode.
    ticks : int
    """

    scenario: str
    scheduler: str
    seed: int | None
    metrics: dict[str, Metrics]
    trace: Trace
    solves: list[SolveStats] = field(default_factory=list)
    replan_ticks: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    wall_time_s: float = 0.0
    ticks: int = 0

    @property
    def solve_times_s(self) -> np.ndarray:
        """(R,) wall seconds of each replan's scheduler call."""
        return np.array([s.wall_time_s for s in self.solves], dtype=np.float64)

    @property
    def solve_gaps(self) -> np.ndarray:
        """(R,) each replan's relative optimality gap, ``(bound - objective) / |objective|``,
        where its scheduler proved a bound on its own model (0: solved to optimality); NaN where
        it proved none (heuristics, auctions, fallbacks)."""
        return np.array([s.gap for s in self.solves], dtype=np.float64)

    @property
    def outcomes(self) -> Outcomes:
        """Time to containment, burned area and facility damage (:mod:`fcplan.metrics.outcomes`)."""
        return compute_outcomes(self.trace)

    @property
    def fallbacks(self) -> int:
        """Number of replans where the scheduler failed and greedy stood in."""
        return sum(s.status == "fallback" for s in self.solves)

    @property
    def fallback_majority(self) -> bool:
        """Whether the scheduler fell back to greedy on more than half of its replans (its score
        is then mostly greedy's; :func:`fell_back_mostly`)."""
        return fell_back_mostly(self.fallbacks, len(self.solves))

    def summary(self) -> dict[str, Any]:
        """Flat dict of the headline numbers (for tables)."""
        out: dict[str, Any] = {
            "scenario": self.scenario,
            "scheduler": self.scheduler,
            "seed": self.seed,
        }
        for name, m in self.metrics.items():
            for k, v in m.as_dict().items():
                if k != "definition":
                    out[f"{name}.{k}"] = v
        for k, v in self.outcomes.as_dict().items():
            out[f"outcome.{k}"] = v
        st = self.solve_times_s
        statuses = [s.status for s in self.solves]
        gaps = self.solve_gaps
        bounded = gaps[np.isfinite(gaps)]
        rounds = [s.size["rounds"] for s in self.solves if "rounds" in s.size]
        messages = [s.size["messages"] for s in self.solves if "messages" in s.size]
        out.update(
            ticks=self.ticks,
            wall_time_s=self.wall_time_s,
            replans=len(self.solves),
            fallbacks=self.fallbacks,
            fallback_majority=self.fallback_majority,
            optimal_replans=statuses.count("optimal"),
            time_limit_replans=statuses.count("time_limit"),
            solve_p50_ms=float(np.median(st) * 1e3) if st.size else 0.0,
            solve_p95_ms=float(np.percentile(st, 95) * 1e3) if st.size else 0.0,
            bounded_replans=int(bounded.size),
            gap_p50=float(np.median(bounded)) if bounded.size else float("nan"),
            gap_max=float(bounded.max()) if bounded.size else float("nan"),
            rounds_per_replan=float(np.mean(rounds)) if rounds else float("nan"),
            messages_per_replan=float(np.mean(messages)) if messages else float("nan"),
        )
        return out


def run_episode(
    scenario: ScenarioLike,
    scheduler: Scheduler | str,
    seed: int | None = 0,
    *,
    replan_period: float = 1.0,
    time_limit: float | None = None,
    graph_params: TaskGraphParams | None = None,
    event_replans: bool = True,
    record: str | os.PathLike[str] | None = None,
    latency: str | None = None,
    observers: Sequence[EpisodeObserver] = (),
) -> EpisodeResult:
    """Play one episode of ``scenario`` with ``scheduler`` (a :class:`fcplan.mission.Mission`).

    Parameters
    ----------
    scenario : Scenario or str or int
        A scenario or a name/path for :func:`fcplan.load_scenario`.
    scheduler : Scheduler or str
        A scheduler or a registered name.
    seed : int, optional
        Seeds the world (fire, sensing, pruning) and the scheduler's generator.
    replan_period : float
        Simulated seconds between periodic replans.
    time_limit : float, optional
        Seconds each scheduler call may take (passed to the scheduler).
    graph_params : TaskGraphParams, optional
    event_replans : bool
        Also replan at once when fire is sensed outside every current fire task.
    record : str or os.PathLike, optional
        Write a complete recording of the episode to this ``.npz`` file (:mod:`fcplan.recording`).
    latency : {None, "wall", "ticks:N"}
        Planning takes time in the world: a plan applies that many ticks after its replan, the
        team flying its last orders meanwhile (:meth:`fcplan.mission.Mission.run`). None (the
        default) stops the world while the scheduler thinks, as the manual's game does.
    observers : sequence of EpisodeObserver
        Also told about every replan, command and tick (:class:`fcplan.mission.BaseObserver`),
        e.g. a progress bar; they watch and change nothing.

    Returns
    -------
    EpisodeResult
    """
    scenario = as_scenario(scenario)
    if isinstance(scheduler, str):
        scheduler = make_scheduler(scheduler)
    t0 = time.perf_counter()
    recorder = None
    if record is not None:
        settings = dict(
            replan_period=replan_period,
            time_limit=time_limit,
            event_replans=event_replans,
            graph_params=graph_params,
            latency=latency,
        )
        recorder = _recorder(scenario, scheduler, seed, settings)
    mission = Mission(
        scenario,
        seed,
        replan_period=replan_period,
        event_replans=event_replans,
        graph_params=graph_params,
        observers=(*observers, *(() if recorder is None else (recorder,))),
    )
    mission.run(scheduler, time_limit=time_limit, latency=latency)
    trace = mission.world.trace()
    if recorder is not None and record is not None:
        recorder.save(record)
    return EpisodeResult(
        scenario=scenario.name,
        scheduler=getattr(scheduler, "name", type(scheduler).__name__),
        seed=seed if isinstance(seed, (int, np.integer)) or seed is None else None,
        metrics=compute_all(trace),
        trace=trace,
        solves=mission.solves,
        replan_ticks=mission.replan_ticks,
        wall_time_s=time.perf_counter() - t0,
        ticks=mission.tick,
    )


def _recorder(
    scenario: Scenario, scheduler: Scheduler, seed: int | None, settings: dict[str, Any]
) -> Recorder:
    """The recorder of an episode played with ``settings`` (plus the scheduler's own)."""
    from fcplan.recording import Recorder, scheduler_settings

    settings = dict(settings, scheduler=scheduler_settings(scheduler))
    return Recorder(scenario, seed, source=getattr(scheduler, "name", "?"), settings=settings)
