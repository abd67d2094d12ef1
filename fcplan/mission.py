"""The mission: one episode's world, the team's belief and the replan rule, in one loop.

Every way of playing fcplan (:func:`fcplan.run_episode` with a scheduler, the task and motion
environments, the scheduler-driven motion expert, a human game, the re-simulation of a recording)
is the same loop over simulator ticks, written once here:

1. **replan** when :meth:`Mission.replan_due` says so: build the task graph from the belief
   (:mod:`fcplan.taskgraph`), ask a scheduler for a plan (:func:`fcplan.scheduling.solve`:
   validated, with a greedy fallback, drawing from the world's controller generator) and turn the
   plan into agent commands (:meth:`Mission.commands_for`);
2. **step**: apply the commands and advance the world one tick (:meth:`fcplan.world.World.step`),
   then fold what the team sensed and put out into its :class:`fcplan.belief.Belief`.

Between replans the team flies the last plan. A learner (:mod:`fcplan.env`) or a human replaces
step 1 with its own commands; :meth:`Mission.step` and :meth:`Mission.advance` stay the same.

The replan rule
---------------
A replan is due

* **periodically**: every ``replan_period`` simulated seconds (rounded to whole ticks, at least
  one), counted from the tick of the last periodic replan, starting at tick 0;
* **on new fire** (``event_replans=True``): at the tick after the team first senses a burning cell
  that lies outside every fire task of the last task graph. Fire tasks are clusters of cells on a
  grid of ``graph.tile_px`` tiles (:class:`fcplan.taskgraph.TaskGraphParams`); a cell is
  "outside" when its tile holds no fire task's position. An event replan does not move the
  periodic schedule.

Observers
---------
Anything that watches an episode (the :class:`fcplan.recording.Recorder`, a progress display,
a test) is an :class:`EpisodeObserver`, passed as ``observers=[...]``; :class:`BaseObserver`
does nothing and can be subclassed for the hooks one needs. The mission calls, in this order:

=============================  =========================================================
hook                           called
=============================  =========================================================
``on_replan(tick, plan)``      after each scheduler call, with the plan and its stats
``on_commands(tick, cmds)``    before each tick, with the commands (None: no new orders)
``on_step(world, info)``       after each tick (and the belief update), with its StepInfo
``on_input(tick, event)``      for each raw human input (:meth:`Mission.notify_input`)
=============================  =========================================================

Examples
--------
>>> from fcplan import make_scheduler
>>> from fcplan.mission import BaseObserver, Mission
>>> class Ticks(BaseObserver):
...     def __init__(self) -> None:
...         self.seen = []
...     def on_step(self, world, info) -> None:
...         self.seen.append(info.tick)
>>> ticks = Ticks()
>>> mission = Mission("practice", seed=0, observers=[ticks])
>>> greedy = make_scheduler("greedy")
>>> while mission.tick < 25:
...     commands = None
...     if mission.replan_due():
...         graph, plan = mission.replan(greedy)
...         commands = mission.commands_for(plan, graph)
...     info = mission.step(commands)
>>> mission.replan_ticks.tolist(), ticks.seen[-1]
([0, 10, 20], 25)
>>> mission.run(greedy).done, mission.tick
(True, 1800)
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Mapping
from typing import Any, Protocol, cast, runtime_checkable

import numpy as np

from fcplan.belief import Belief, ClairvoyantBelief
from fcplan.errors import ArgumentError, FcplanError
from fcplan.plan import Plan, plan_commands
from fcplan.scenario import Scenario, load_scenario
from fcplan.scheduling import Scheduler, SolveStats, solve
from fcplan.settings import SettingError, float_setting
from fcplan.taskgraph import TaskGraph, TaskGraphBuilder, TaskGraphParams, TaskKind
from fcplan.team import Command
from fcplan.world import StepInfo, World

__all__ = ["Mission", "EpisodeObserver", "BaseObserver", "as_scenario", "Commands"]

#: Commands for one tick: per agent id (or team row), the :class:`fcplan.team.Command` it gets.
Commands = Mapping[Any, Command]

#: a scenario, or a name, number or path for :func:`fcplan.load_scenario`
ScenarioLike = Scenario | str | int | os.PathLike[str]

#: a seed as :meth:`fcplan.world.World.reset` takes it
Seed = int | np.integer | np.random.SeedSequence | np.random.Generator | None

_NO_TILES = np.zeros(0, dtype=np.int64)


@runtime_checkable
class EpisodeObserver(Protocol):
    """What a mission tells its observers (module docstring: when)."""

    def on_replan(self, tick: int, plan: Plan) -> None:
        """A scheduler returned ``plan`` (with its ``stats``) at ``tick``."""

    def on_commands(self, tick: int, commands: Commands | None) -> None:
        """``commands`` go to the world at ``tick`` (its tick before the step)."""

    def on_step(self, world: World, info: StepInfo) -> None:
        """The world advanced one tick; ``info`` is what happened."""

    def on_input(self, tick: int, event: Mapping[str, Any]) -> None:
        """A raw human input (a JSON-able dict) arrived at ``tick``."""


class BaseObserver:
    """An :class:`EpisodeObserver` whose hooks do nothing: subclass it for the hooks you need."""

    def on_replan(self, tick: int, plan: Plan) -> None:
        """Do nothing."""

    def on_commands(self, tick: int, commands: Commands | None) -> None:
        """Do nothing."""

    def on_step(self, world: World, info: StepInfo) -> None:
        """Do nothing."""

    def on_input(self, tick: int, event: Mapping[str, Any]) -> None:
        """Do nothing."""


def as_scenario(scenario: ScenarioLike) -> Scenario:
    """``scenario`` itself, or the scenario :func:`fcplan.load_scenario` loads for a name,
    number or path."""
    return scenario if isinstance(scenario, Scenario) else load_scenario(scenario)


def period_ticks(seconds: float, ticks_per_second: int) -> int:
    """Ticks between periodic replans every ``seconds`` simulated seconds (at least one): the
    one rounding rule of the mission, the task env and the batched expert.

    Examples
    --------
    >>> period_ticks(1.0, 10), period_ticks(0.04, 10), period_ticks(2.26, 10)
    (10, 1, 23)
    """
    return max(int(round(seconds * ticks_per_second)), 1)


class Mission:
    """One episode: world, belief and the replan rule (module docstring: the loop and the rule).

    Parameters
    ----------
    scenario : Scenario or str or int or path
        A scenario or a name/path for :func:`fcplan.load_scenario`.
    seed : int, numpy.random.SeedSequence or numpy.random.Generator, optional
        Seeds the world (fire, sensing, pruning, and the controller generator :attr:`rng`).
    replan_period : float
        Simulated seconds between periodic replans (> 0).
    event_replans : bool
        Also replan at once when fire is sensed outside every fire task of the last graph.
    graph_params : TaskGraphParams, optional
        Settings of the task graphs built for the replans.
    observers : iterable of EpisodeObserver
        Told about every replan, command, tick and input, in order.
    belief : bool
        Keep the team's belief (False: nothing to plan from until :meth:`track_belief`; spares
        the belief update of every tick for a loop that never plans).

    Attributes
    ----------
    scenario : Scenario
    world : World
    belief : Belief or None
    graph : TaskGraph or None
        The last task graph built.
    plan : Plan or None
        The last plan.
    solves : list of SolveStats
        One per replan since the reset.
    observers : list of EpisodeObserver
    """

    def __init__(
        self,
        scenario: ScenarioLike,
        seed: Seed = 0,
        *,
        replan_period: float = 1.0,
        event_replans: bool = True,
        graph_params: TaskGraphParams | None = None,
        observers: Iterable[EpisodeObserver] = (),
        belief: bool = True,
    ) -> None:
        self.scenario = as_scenario(scenario)
        self.graph_params = graph_params
        self.observers: list[EpisodeObserver] = list(observers)
        self._keep_belief = bool(belief)
        self.world = World()
        self._set_rule(replan_period, event_replans)
        self.reset(seed)

    # ------------------------------------------------------------------ setup
    def reset(self, seed: Seed = 0) -> Mission:
        """Start the episode again (same scenario, rule and observers) with ``seed``; return
        ``self``. The world object stays the same."""
        self.seed = seed
        self.world.reset(self.scenario, seed)
        self.belief: Belief | None = Belief(self.scenario) if self._keep_belief else None
        #: builds this episode's task graphs (holds the scenario's and team's constants)
        self.graph_builder = TaskGraphBuilder(self.scenario, self.graph_params)
        self.graph: TaskGraph | None = None
        self.plan: Plan | None = None
        self.solves: list[SolveStats] = []
        self._replan_ticks: list[int] = []
        self._next_periodic = self.world.tick
        self._new_fire = False
        self._tile: tuple[float, float] | None = None  # the last graph's fire tiles
        self._fire_tiles = _NO_TILES
        return self

    def set_replan_rule(self, replan_period: float, *, event_replans: bool) -> None:
        """Replan every ``replan_period`` simulated seconds, and on new fire if
        ``event_replans``; the next periodic replan is due at once.

        Raises
        ------
        ValueError
            If ``replan_period`` is not > 0.
        """
        self._set_rule(replan_period, event_replans)
        self._next_periodic = self.world.tick

    def _set_rule(self, replan_period: float, event_replans: bool) -> None:
        self.replan_period = check_replan_period(replan_period)
        #: ticks between periodic replans
        self.period = period_ticks(replan_period, self.scenario.ticks_per_second)
        self.event_replans = bool(event_replans)

    def set_graph_params(self, params: TaskGraphParams | None) -> None:
        """Build this episode's task graphs with ``params`` from now on (None: the defaults)."""
        self.graph_params = params
        self.graph_builder = TaskGraphBuilder(self.scenario, params)

    def track_belief(self) -> Belief:
        """Keep a belief from now on (a fresh one, knowing nothing yet) and return it."""
        self._keep_belief = True
        self.belief = Belief(self.scenario)
        return self.belief

    # ------------------------------------------------------------------ state
    @property
    def tick(self) -> int:
        """Ticks simulated since the reset."""
        return self.world.tick

    @property
    def done(self) -> bool:
        """True once the scenario's duration has been simulated."""
        return self.world.done

    @property
    def rng(self) -> np.random.Generator:
        """The world's controller generator (what schedulers draw from)."""
        return self.world.controller_rng

    @property
    def replan_ticks(self) -> np.ndarray:
        """(R,) int64 tick of each replan since the reset."""
        return np.asarray(self._replan_ticks, dtype=np.int64)

    # ------------------------------------------------------------------ replans
    def replan_due(self) -> bool:
        """Whether the replan rule (module docstring) asks for a replan at this tick."""
        return self.world.tick >= self._next_periodic or self._new_fire

    def task_graph(self, *, clairvoyant: bool = False) -> TaskGraph:
        """The task graph of the current tick, built from the belief (kept as :attr:`graph`).

        ``clairvoyant=True`` builds it from the belief plus the true fire
        (:class:`fcplan.belief.ClairvoyantBelief`): what the ``oracle`` reference plans on.
        """
        self.graph = graph = self._build_graph(clairvoyant)
        return graph

    def replan(
        self, scheduler: Scheduler, *, time_limit: float | None = None
    ) -> tuple[TaskGraph, Plan]:
        """Plan now: build the task graph, run ``scheduler`` on it through
        :func:`fcplan.scheduling.solve`, record the solve statistics, tell the observers.

        A scheduler whose ``clairvoyant`` attribute is true (the ``oracle`` reference) gets a
        graph built from the true fire as well as the belief (:meth:`task_graph`).

        Parameters
        ----------
        scheduler : Scheduler
        time_limit : float, optional
            Seconds the scheduler may take (passed to it).

        Returns
        -------
        (TaskGraph, Plan)
        """
        graph = self.task_graph(clairvoyant=bool(getattr(scheduler, "clairvoyant", False)))
        plan = solve(scheduler, graph, time_limit=time_limit, rng=self.world.controller_rng)
        tick = self.world.tick
        self.plan = plan
        self.solves.append(cast(SolveStats, plan.stats))  # (solve always sets them)
        self._replan_ticks.append(tick)
        self._tile = tile = graph.tile_px
        fires = graph.task_kind == TaskKind.FIRE
        self._fire_tiles = _tile_keys(graph.task_pos[fires], tile, self.scenario.world_size)
        if tick >= self._next_periodic:
            self._next_periodic = tick + self.period
        self._new_fire = False
        for o in self.observers:
            o.on_replan(tick, plan)
        return graph, plan

    def commands_for(self, plan: Plan, graph: TaskGraph) -> dict[str, Command]:
        """The commands that start ``plan`` (made on ``graph``): :func:`fcplan.plan_commands`."""
        return plan_commands(plan, graph)

    def _build_graph(self, clairvoyant: bool = False) -> TaskGraph:
        """Build the task graph of the current tick (the one place graphs are built)."""
        if self.belief is None:
            raise ValueError("this mission keeps no belief to plan from: call track_belief()")
        belief: Belief | ClairvoyantBelief = self.belief
        if clairvoyant:
            belief = ClairvoyantBelief(self.belief, self.world.fire.state.reshape(-1))
        return self.graph_builder.build(self.world.team, belief)

    # ------------------------------------------------------------------ ticks
    def step(self, commands: Commands | None = None) -> StepInfo:
        """Advance one tick with ``commands`` (None: the team keeps flying its orders).

        The observers hear ``on_commands`` before and ``on_step`` after the tick; the belief
        is updated in between, and the new-fire rule notes the newly sensed cells.
        """
        world = self.world
        observers = self.observers
        if observers:
            for o in observers:
                o.on_commands(world.tick, commands)
        info = world.step(commands)
        if self.belief is not None:
            self.belief.update(info)
        if observers:
            for o in observers:
                o.on_step(world, info)
        if self.event_replans and self._tile is not None and info.newly_sensed.size:
            newly = info.newly_sensed
            w = self.scenario.world_size
            xy = np.stack([newly // w, newly % w], axis=1)
            outside = ~np.isin(_tile_keys(xy, self._tile, w), self._fire_tiles)
            self._new_fire = bool(outside.any())
        return info

    def advance(self, ticks: int, commands: Commands | None = None) -> int:
        """Run up to ``ticks`` ticks (fewer at the end of the episode), giving ``commands`` on
        the first; return the number of ticks run."""
        n = min(int(ticks), self.scenario.n_ticks - self.world.tick)
        for _ in range(n):
            self.step(commands)
            commands = None
        return max(n, 0)

    def run(
        self,
        scheduler: Scheduler,
        *,
        time_limit: float | None = None,
        latency: str | None = None,
    ) -> Mission:
        """Play the rest of the episode with ``scheduler``, replanning by the rule; return
        ``self``.

        ``latency`` makes planning take time in the world (default None: the world waits for
        the scheduler, as in the manual's game):

        * ``"ticks:N"``: a plan made at tick ``t`` applies from tick ``t + N``; deterministic,
          so results stay reproducible;
        * ``"wall"``: it applies ``ceil(wall seconds of the scheduler call x ticks per second)``
          ticks later (what a real fleet would see; depends on the machine).

        Meanwhile the team keeps flying its last orders, and no new replan starts until the
        pending plan applies (one planner, busy while it thinks).
        """
        check_time_limit(time_limit)
        delay = latency_rule(latency, self.scenario.ticks_per_second)
        pending: tuple[int, Commands] | None = None
        while not self.world.done:
            commands: Commands | None = None
            if pending is not None and self.world.tick >= pending[0]:
                commands, pending = pending[1], None
            if pending is None and self.replan_due():
                graph, plan = self.replan(scheduler, time_limit=time_limit)
                ticks = delay(cast(SolveStats, plan.stats))
                if ticks == 0:
                    commands = self.commands_for(plan, graph)
                else:
                    pending = (self.world.tick + ticks, self.commands_for(plan, graph))
            self.step(commands)
        return self

    def notify_input(self, event: Mapping[str, Any]) -> None:
        """Tell the observers about one raw human input, at the current tick."""
        for o in self.observers:
            o.on_input(self.world.tick, event)


def _tile_keys(xy: np.ndarray, tile: tuple[float, float], w: int) -> np.ndarray:
    """(k,) int64 key of the ``tile``-sized tile holding each point of ``xy`` ((k, 2) px) on a
    ``w`` px map (one key per tile)."""
    ny = int(np.ceil(w / tile[1])) + 1
    return (xy[:, 0] // tile[0]).astype(np.int64) * ny + (xy[:, 1] // tile[1]).astype(np.int64)


def latency_rule(latency: str | None, ticks_per_second: int) -> Callable[[SolveStats], int]:
    """The ticks a plan waits before it applies, as a function of its solve statistics.

    Examples
    --------
    >>> latency_rule("ticks:3", 10)(SolveStats())
    3
    >>> latency_rule("wall", 10)(SolveStats(wall_time_s=0.25))
    3
    >>> latency_rule(None, 10)(SolveStats(wall_time_s=5.0))
    0
    """
    if latency is None:
        return lambda stats: 0
    if latency == "wall":
        return lambda stats: max(math.ceil(stats.wall_time_s * ticks_per_second - 1e-9), 0)
    kind, _, n = str(latency).partition(":")
    if kind == "ticks" and n.isdigit():
        ticks = int(n)
        return lambda stats: ticks
    raise ArgumentError(f"latency: must be None, 'wall' or 'ticks:N' with N >= 0 (got {latency!r})")


def check_time_limit(time_limit: Any) -> float | None:
    """``time_limit`` (wall seconds per scheduler call) as a float, or None; else a one-line
    :class:`~fcplan.errors.ArgumentError` (a NaN, an infinity, zero or less, a bool or a
    string would reach every scheduler call).

    Examples
    --------
    >>> check_time_limit(0.5), check_time_limit(None)
    (0.5, None)
    """
    if time_limit is None:
        return None
    return _positive("time_limit", time_limit, "None or a finite number > 0 of seconds")


def check_replan_period(replan_period: Any, *, error: type[FcplanError] = ArgumentError) -> float:
    """``replan_period`` (simulated seconds between periodic replans) as a finite float > 0,
    else a one-line ``error`` (:class:`~fcplan.errors.ArgumentError`; the envs pass
    :class:`~fcplan.errors.EnvError`): the one check of the mission, the task env and the plan
    followers, before :func:`period_ticks` rounds it.

    Examples
    --------
    >>> check_replan_period(2)
    2.0
    >>> check_replan_period(float("inf"))
    Traceback (most recent call last):
    ...
    fcplan.errors.ArgumentError: replan_period: must be a finite number > 0 of simulated seconds (got inf)
    """
    allowed = "a finite number > 0 of simulated seconds"
    return _positive("replan_period", replan_period, allowed, error)


def _positive(
    name: str, value: Any, allowed: str, error: type[FcplanError] = ArgumentError
) -> float:
    """``value`` as a finite float > 0 (the number check of
    :func:`fcplan.settings.float_setting`: bools, strings, NaN and infinities refused), else an
    ``error`` naming ``name`` and what is ``allowed``."""
    try:
        return float_setting(name, value, 0.0, lo_open=True)
    except SettingError:
        raise error(f"{name}: must be {allowed} (got {value!r:.40})") from None
