"""Test helper: a mission played up to a tick by a scheduler, with its replan rule, as
:meth:`fcplan.mission.Mission.run` plays it to the end."""

from __future__ import annotations

from typing import Any

from fcplan.mission import Mission


def play_until(mission: Mission, scheduler: Any, tick: int) -> Mission:
    """Step ``mission`` until its tick is ``tick``, replanning with ``scheduler`` whenever the
    replan rule says so and applying each plan at once; return ``mission``."""
    while mission.tick < tick:
        commands = None
        if mission.replan_due():
            graph, plan = mission.replan(scheduler)
            commands = mission.commands_for(plan, graph)
        mission.step(commands)
    return mission
