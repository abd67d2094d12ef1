"""Scheduler-driven expert for the motion-level environment: plans turned into per-tick moves.

The motion level has no scheduler of its own: a scheduler plans tasks, not moves. A
:class:`PlanFollower` bridges the two so that any registered scheduler can drive a
:class:`fcplan.env.motion.MotionEnv`, as a baseline to compare a learned motion policy with or
as the expert of imitation learning:

* **Belief and replans.** The env's episode is a :class:`fcplan.mission.Mission`; the follower
  asks it to keep the team's :class:`fcplan.belief.Belief` (updated every tick, exactly as in
  :func:`fcplan.run_episode`) and to replan every ``replan_period`` simulated seconds (periodic
  replans only). A replan is :meth:`Mission.replan <fcplan.mission.Mission.replan>`: the task
  graph, the scheduler through :func:`fcplan.scheduling.solve` (so a failing solver falls back to
  greedy), with the world's ``controller_rng``. Agents the plan does not mention keep their
  route; agents sent home stop (the simulator flies agents home by itself when their battery or
  tank runs out).
* **Moves.** One action per agent and tick. At a goal (both offsets within half a step) an
  action or hybrid agent dumps once on a fire task (as an arrival arms one dump in the
  simulator), then takes the next goal. Otherwise a perception or hybrid agent whose commanded
  altitude is off the plan's climbs or descends first (a wider view on the way), then the agent
  steps toward its next goal along the axis with the larger offset (the other
  axis if that move is masked); with nothing to do it stays. Only legal actions (by the
  observation's ``action_mask``) are chosen.

The follower reads the live world (``env.world``) for positions and modes, as a centralised
expert would; its actions depend only on the env's state, so episodes are deterministic for a
given seed.

Examples
--------
>>> from fcplan.env.motion import MotionEnv
>>> from fcplan.env.motion_expert import PlanFollower
>>> env = MotionEnv("practice")
>>> expert = PlanFollower(env, "greedy")
>>> obs, infos = env.reset(seed=0)
>>> expert.reset()
>>> for _ in range(30):
...     obs, rewards, terms, truncs, infos = env.step(expert.actions(obs))
>>> expert.replans
3
"""

from __future__ import annotations

from typing import Any

from fcplan.belief import Belief
from fcplan.env.motion import ACTION_NAMES, MotionEnv, role_letters
from fcplan.errors import EnvError
from fcplan.mission import Mission, check_replan_period
from fcplan.plan import Plan
from fcplan.scheduling import Scheduler, deterministic_spec, make_scheduler
from fcplan.taskgraph import TaskGraph, TaskGraphParams, TaskKind
from fcplan.team import Mode

__all__ = ["PlanFollower", "TeamRoutes"]

_FIRE = int(TaskKind.FIRE)
_RETURNING = int(Mode.RETURNING)


class PlanFollower:
    """Turn a scheduler's plans into motion-level actions (module docstring: the rules).

    Parameters
    ----------
    env : fcplan.env.motion.MotionEnv
        The environment to drive (a scenario env, not a preset).
    scheduler : str or Scheduler
        A registered scheduler name or spec (``"greedy"``, ``"milp:slots=2"``) or an instance.
        A spec runs in the scheduler's deterministic mode if it has one, unless it sets
        ``deterministic`` (:func:`fcplan.scheduling.deterministic_spec`: the same actions on any
        machine, as in ``compare``); an instance runs as it was built.
    replan_period : float
        Simulated seconds between replans (> 0).
    time_limit : float, optional
        Passed to the scheduler on every replan (None: its default).
    graph_params : fcplan.taskgraph.TaskGraphParams, optional
        Task-graph settings (None: the defaults of :func:`fcplan.taskgraph.build_task_graph`).

    Attributes
    ----------
    replans : int
        Plans made since :meth:`reset`.
    plan : fcplan.plan.Plan or None
        The last plan.
    """

    def __init__(
        self,
        env: MotionEnv,
        scheduler: str | Scheduler,
        *,
        replan_period: float = 1.0,
        time_limit: float | None = None,
        graph_params: TaskGraphParams | None = None,
    ) -> None:
        if not isinstance(env, MotionEnv):
            raise EnvError("PlanFollower: env must be a scenario MotionEnv (presets have no plans)")
        replan_period = check_replan_period(replan_period, error=EnvError)
        self.env = env
        self.scheduler = (
            make_scheduler(deterministic_spec(scheduler))
            if isinstance(scheduler, str)
            else scheduler
        )
        self.replan_period = float(replan_period)
        self.time_limit = time_limit
        self.graph_params = graph_params
        self._ids = list(env.possible_agents)
        self._plans = TeamRoutes(self._ids, env.scenario)
        self.mission: Mission | None = None
        self.belief: Belief | None = None
        self.plan: Plan | None = None
        self.replans = 0

    def reset(self) -> None:
        """Forget routes and belief, replan at once; call after ``env.reset()``."""
        mission = self.env.mission
        if mission is None:
            raise EnvError("PlanFollower.reset: reset the env first")
        self.mission = mission
        self.belief = mission.track_belief()
        mission.set_replan_rule(self.replan_period, event_replans=False)
        mission.set_graph_params(self.graph_params)
        self._plans = TeamRoutes(self._ids, self.env.scenario)
        self.plan = None
        self.replans = 0

    def actions(self, observations: dict[str, Any]) -> dict[str, int]:
        """One legal action per live agent for the current tick."""
        if self.mission is None:
            self.reset()
        mission = self.mission
        assert mission is not None
        if mission.replan_due():
            graph, plan = mission.replan(self.scheduler, time_limit=self.time_limit)
            self.plan = plan
            self.replans += 1
            self._plans.follow(plan, graph)
        team = mission.world.team
        masks = {a: o["action_mask"] for a, o in observations.items()}
        return self._plans.choose(
            masks, team.pos.tolist(), team.z_target.tolist(), team.mode.tolist(),
            team.speed.tolist(), 5.0 * team.tick_scale,
        )  # fmt: skip


class TeamRoutes:
    """What a team was told by its last plan, and the move rule (module docstring) that follows
    it: the readable rule, :class:`PlanFollower`'s; the batched follower
    (:class:`fcplan.env.vector_expert.BatchPlanFollower`) runs its fast kernel
    :class:`fcplan.env.vector_moves.BatchRoutes`, tested equal to it.

    Parameters
    ----------
    ids : list of str
        The agents, in row order.
    scenario : Scenario
        Their scenario (roles: each agent's action names).
    """

    def __init__(self, ids: list[str], scenario: Any) -> None:
        self._ids = ids
        self._row = {a: i for i, a in enumerate(ids)}
        #: action index by name, per agent
        self._act = [
            {name: k for k, name in enumerate(ACTION_NAMES[r])} for r in role_letters(scenario)
        ]
        self._can_act = [bool(a.role.can_act) for a in scenario.agents]
        n = len(ids)
        self._routes: list[list[tuple[float, float, bool]]] = [[] for _ in range(n)]
        self._alt: list[float | None] = [None] * n
        self._patrol = [False] * n

    def follow(self, plan: Plan, graph: TaskGraph) -> None:
        """Take the routes (goal positions, dump on fire tasks) and altitudes of a new plan."""
        tidx, pos, kind = graph.task_index, graph.task_pos, graph.task_kind
        can_act = self._can_act
        for agent, z in plan.altitudes.items():
            self._alt[self._row[agent]] = float(z)
        for agent in plan.home:
            self._routes[self._row[agent]] = []
        for agent, route in plan.routes.items():
            i = self._row[agent]
            self._patrol[i] = agent in plan.patrol
            self._routes[i] = [
                (
                    float(pos[tidx[t], 0]),
                    float(pos[tidx[t], 1]),
                    can_act[i] and int(kind[tidx[t]]) == _FIRE,
                )
                for t in route
            ]

    def choose(self, masks: dict[str, Any], pos: list, z_target: list, mode: list, speed: list,
               climb: float) -> dict[str, int]:  # fmt: skip
        """One legal action for each agent of ``masks`` (agent id -> its action mask), from the
        team's positions, commanded altitudes, modes and speeds (lists in row order) and the
        altitude step of a climb."""
        out = {}
        for i, a in enumerate(self._ids):
            if a not in masks:
                continue
            mask = masks[a].tolist()
            act = self._act[i]

            def legal(name: str, act: dict[str, int] = act, mask: list[int] = mask) -> bool:
                k = act.get(name)
                return k is not None and bool(mask[k])

            choice = "stay"
            route = self._routes[i]
            if mode[i] < _RETURNING:  # (a forced return flies home by itself)
                x, y = pos[i]
                half = 0.5 * speed[i]
                while route and abs(route[0][0] - x) <= half and abs(route[0][1] - y) <= half:
                    if route[0][2] and legal("dump"):
                        choice = "dump"
                        route[0] = (route[0][0], route[0][1], False)  # one dump per goal
                        break
                    done = route.pop(0)
                    if self._patrol[i]:  # a patrol loop goes round again
                        route.append(done)
                alt = self._alt[i]
                if choice == "stay" and alt is not None:  # altitude first
                    if z_target[i] < alt - 0.5 * climb and legal("climb"):
                        choice = "climb"
                    elif z_target[i] > alt + 0.5 * climb and legal("descend"):
                        choice = "descend"
                if choice == "stay" and route:
                    dx, dy = route[0][0] - x, route[0][1] - y
                    moves = [
                        ("east" if dx > 0 else "west", abs(dx)),
                        ("south" if dy > 0 else "north", abs(dy)),
                    ]
                    moves.sort(key=lambda m: -m[1])
                    for name, off in moves:
                        if off > half and legal(name):
                            choice = name
                            break
            out[a] = act[choice]
        return out
