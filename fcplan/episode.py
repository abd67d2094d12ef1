"""The replan loop: run a scheduler on a scenario for one episode and score it.

Every ``replan_period`` simulated seconds, and at once when the team senses fire outside every
fire task of the current plan, the loop builds the task graph from the belief, asks the scheduler
for a plan (:func:`fcplan.scheduling.solve`: validated, with a greedy fallback), and turns it into
agent commands. Between replans the world runs on the last plan. The episode ends after the
scenario's duration and is scored with both metric definitions.

Examples
--------
>>> from fcplan import run_episode
>>> result = run_episode("practice", "greedy", seed=0)
>>> result.ticks
1800
>>> sorted(result.metrics)
['manual', 'reference2020']
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fcplan.belief import Belief
from fcplan.metrics import Metrics, compute_all
from fcplan.plan import plan_commands
from fcplan.scheduling import Scheduler, SolveStats, make_scheduler, solve
from fcplan.taskgraph import TaskGraphParams, TaskKind, build_task_graph
from fcplan.trace import Trace
from fcplan.world import World

__all__ = ["run_episode", "EpisodeResult"]


@dataclass(frozen=True, eq=False)
class EpisodeResult:
    """Outcome of one episode.

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
    def fallbacks(self) -> int:
        """Number of replans where the scheduler failed and greedy stood in."""
        return sum(s.status == "fallback" for s in self.solves)

    def summary(self) -> dict:
        """Flat dict of the headline numbers (for tables)."""
        out = {"scenario": self.scenario, "scheduler": self.scheduler, "seed": self.seed}
        for name, m in self.metrics.items():
            for k, v in m.as_dict().items():
                if k != "definition":
                    out[f"{name}.{k}"] = v
        st = self.solve_times_s
        statuses = [s.status for s in self.solves]
        rounds = [s.size["rounds"] for s in self.solves if "rounds" in s.size]
        messages = [s.size["messages"] for s in self.solves if "messages" in s.size]
        out.update(
            ticks=self.ticks,
            wall_time_s=self.wall_time_s,
            replans=len(self.solves),
            fallbacks=self.fallbacks,
            optimal_replans=statuses.count("optimal"),
            time_limit_replans=statuses.count("time_limit"),
            solve_p50_ms=float(np.median(st) * 1e3) if st.size else 0.0,
            solve_p95_ms=float(np.percentile(st, 95) * 1e3) if st.size else 0.0,
            rounds_per_replan=float(np.mean(rounds)) if rounds else float("nan"),
            messages_per_replan=float(np.mean(messages)) if messages else float("nan"),
        )
        return out


def run_episode(
    scenario,
    scheduler: Scheduler | str,
    seed: int | None = 0,
    *,
    replan_period: float = 1.0,
    time_limit: float | None = None,
    graph_params: TaskGraphParams | None = None,
    event_replans: bool = True,
    record=None,
) -> EpisodeResult:
    """Play one episode of ``scenario`` with ``scheduler``.

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

    Returns
    -------
    EpisodeResult
    """
    from fcplan.scenario import Scenario, load_scenario

    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if isinstance(scheduler, str):
        scheduler = make_scheduler(scheduler)
    if not replan_period > 0:
        raise ValueError(f"replan_period must be > 0 simulated seconds, got {replan_period!r}")
    t0 = time.perf_counter()
    world = World().reset(scenario, seed)
    belief = Belief(scenario)
    rng = world.controller_rng
    tps = scenario.ticks_per_second
    period = max(int(round(replan_period * tps)), 1)
    solves: list[SolveStats] = []
    replan_ticks: list[int] = []
    tile_keys = np.zeros(0, dtype=np.int64)
    tile = None
    commands = None
    next_periodic = 0
    new_fire = False
    recorder = None
    if record is not None:
        from fcplan.recording import Recorder, scheduler_settings

        settings = dict(
            replan_period=replan_period,
            time_limit=time_limit,
            event_replans=event_replans,
            graph_params=graph_params,
            scheduler=scheduler_settings(scheduler),
        )
        recorder = Recorder(
            scenario, seed, source=getattr(scheduler, "name", "?"), settings=settings
        )
    while not world.done:
        if world.tick >= next_periodic or new_fire:
            graph = build_task_graph(scenario, world.team, belief, graph_params)
            plan = solve(scheduler, graph, time_limit=time_limit, rng=rng)
            commands = plan_commands(plan, graph)
            solves.append(plan.stats)
            replan_ticks.append(world.tick)
            tile = graph.tile_px
            fires = graph.task_kind == TaskKind.FIRE
            tile_keys = _tile_keys(graph.task_pos[fires], tile, scenario.world_size)
            if world.tick >= next_periodic:
                next_periodic = world.tick + period
            new_fire = False
            if recorder is not None:
                recorder.on_replan(world.tick, plan)
        if recorder is not None:
            recorder.on_commands(world.tick, commands)
        info = world.step(commands)
        if recorder is not None:
            recorder.on_step(world, info)
        commands = None
        belief.update(info)
        if event_replans and info.newly_sensed.size and tile is not None:
            w = scenario.world_size
            xy = np.stack([info.newly_sensed // w, info.newly_sensed % w], axis=1)
            new_fire = bool((~np.isin(_tile_keys(xy, tile, w), tile_keys)).any())
    trace = world.trace()
    if recorder is not None:
        recorder.save(record)
    return EpisodeResult(
        scenario=scenario.name,
        scheduler=getattr(scheduler, "name", type(scheduler).__name__),
        seed=seed if isinstance(seed, (int, np.integer)) or seed is None else None,
        metrics=compute_all(trace),
        trace=trace,
        solves=solves,
        replan_ticks=np.asarray(replan_ticks, dtype=np.int64),
        wall_time_s=time.perf_counter() - t0,
        ticks=world.tick,
    )


def _tile_keys(xy: np.ndarray, tile: tuple[float, float], w: int) -> np.ndarray:
    ny = int(np.ceil(w / tile[1])) + 1
    return (xy[:, 0] // tile[0]).astype(np.int64) * ny + (xy[:, 1] // tile[1]).astype(np.int64)
