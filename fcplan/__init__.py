"""fcplan: combinatorial multi-robot task assignment on the FireCommander wildfire game.

A discrete-time simulator runs a scenario (FARSITE fires, facilities, a composite team of
perception-only and action-only UAVs). Every replan tick it exposes a task graph of what the team
knows; a pluggable scheduler turns it into a plan; episodes are scored with the FireCommander
manual's metrics.

Examples
--------
>>> import fcplan
>>> result = fcplan.run_episode("practice", "greedy", seed=0)
>>> result.metrics["manual"].grade in fcplan.metrics.GRADES
True
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

#: public name -> module that defines it (imported on first use, so ``import fcplan`` is cheap)
_EXPORTS = {
    "Command": "fcplan.team",
    "EpisodeResult": "fcplan.episode",
    "FcplanError": "fcplan.errors",
    "Metrics": "fcplan.metrics",
    "Plan": "fcplan.plan",
    "PlanError": "fcplan.errors",
    "Scenario": "fcplan.scenario",
    "ScenarioError": "fcplan.errors",
    "Scheduler": "fcplan.scheduling",
    "SolveStats": "fcplan.scheduling",
    "StepInfo": "fcplan.world",
    "TaskGraph": "fcplan.taskgraph",
    "Trace": "fcplan.trace",
    "UnknownNameError": "fcplan.errors",
    "World": "fcplan.world",
    "available_schedulers": "fcplan.scheduling",
    "build_task_graph": "fcplan.taskgraph",
    "compute_all": "fcplan.metrics",
    "compute_metrics": "fcplan.metrics",
    "list_scenarios": "fcplan.scenario",
    "load_scenario": "fcplan.scenario",
    "make_scheduler": "fcplan.scheduling",
    "plan_commands": "fcplan.plan",
    "register_scheduler": "fcplan.scheduling",
    "run_episode": "fcplan.episode",
    "validate_plan": "fcplan.plan",
}


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    if name in ("metrics", "scenario", "env", "experiments"):
        return import_module(f"fcplan.{name}")
    raise AttributeError(f"module 'fcplan' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from fcplan.episode import EpisodeResult, run_episode
    from fcplan.errors import FcplanError, PlanError, ScenarioError, UnknownNameError
    from fcplan.metrics import Metrics, compute_all, compute_metrics
    from fcplan.plan import Plan, plan_commands, validate_plan
    from fcplan.scenario import Scenario, list_scenarios, load_scenario
    from fcplan.scheduling import (
        Scheduler,
        SolveStats,
        available_schedulers,
        make_scheduler,
        register_scheduler,
    )
    from fcplan.taskgraph import TaskGraph, build_task_graph
    from fcplan.team import Command
    from fcplan.trace import Trace
    from fcplan.world import StepInfo, World

__version__ = "0.1.0"

__all__ = [
    "Command",
    "EpisodeResult",
    "FcplanError",
    "Metrics",
    "Plan",
    "PlanError",
    "Scenario",
    "ScenarioError",
    "Scheduler",
    "SolveStats",
    "StepInfo",
    "TaskGraph",
    "Trace",
    "UnknownNameError",
    "World",
    "available_schedulers",
    "build_task_graph",
    "compute_all",
    "compute_metrics",
    "list_scenarios",
    "load_scenario",
    "make_scheduler",
    "plan_commands",
    "register_scheduler",
    "run_episode",
    "validate_plan",
    "__version__",
]
