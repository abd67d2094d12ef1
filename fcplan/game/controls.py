"""The manual's game controls, turned into :class:`fcplan.team.Command` objects.

A human steers the team with the FireCommander GUI's controls (manual "GUI Reference Manual",
FIRECOMMANDER.md section 4.3):

* keys **1-9** select an agent (team order: perception, action, hybrid);
* a **click** on the map adds a goal at the end of the selected agent's route;
* a click within ``5 x speed`` px (100 px at the default speed) of the route's **first goal**
  closes a **patrol loop** over the goals clicked so far, provided there are at least two; the
  agent then cycles through them (a later click replaces the loop with a new route);
* **Up/Down** raise or lower a perception or hybrid agent's target altitude by 5 m within its
  altitude bounds (action agents fly at a fixed 30 m);
* a click inside the **depot** sends the selected agent home, where it stays idle.

Inputs are plain JSON-able dicts (the same dicts the game records with
:meth:`fcplan.recording.Recorder.on_input`): ``{"type": "key", "key": "3"}``, ``{"type": "key",
"key": "up"}``, ``{"type": "click", "map": [x, y]}`` (map px). :class:`Controller` is pure Python
on top of a :class:`fcplan.world.World`: no pygame, so the same inputs replayed at the same ticks
give the same commands, and therefore the same game.

Examples
--------
>>> from fcplan import World, load_scenario
>>> world = World().reset(load_scenario("practice"), seed=0)
>>> ctl = Controller(world)
>>> ctl.handle({"type": "key", "key": "3"})  # select A1
>>> ctl.handle({"type": "click", "map": [400, 400]})
>>> ctl.handle({"type": "click", "map": [600, 400]})
>>> ctl.pending["A1"].route
((400.0, 400.0), (600.0, 400.0))
>>> cmds = ctl.take_commands()
>>> _ = world.step(cmds)
>>> ctl.planned_route(2).tolist()
[[400.0, 400.0], [600.0, 400.0]]
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.team import DRAIN_PER_PX, Command, Mode

__all__ = ["Controller", "InputError", "ALTITUDE_STEP", "PATROL_RADIUS_STEPS"]

ALTITUDE_STEP = 5.0
"""Metres per Up/Down key press (the GUI's step)."""

PATROL_RADIUS_STEPS = 5.0
"""A click within this many agent steps (``speed`` px) of the first goal closes a patrol loop."""


class InputError(FcplanError):
    """An input event dict that the controls do not understand."""


class Controller:
    """Turns human inputs into per-agent commands for the next :meth:`World.step`.

    Parameters
    ----------
    world : fcplan.world.World
        The live world. The controller reads its team state (routes, goal index, altitude target)
        and never changes it: commands only reach the world through ``World.step``.

    Attributes
    ----------
    selected : int
        Row of the selected agent (0, i.e. the first agent, at the start).
    pending : dict of str to Command
        Commands collected since the last :meth:`take_commands`.
    message : str
        A short human message about the last input (shown by the game).
    """

    def __init__(self, world: Any) -> None:
        self.world = world
        self.team = world.team
        sc = world.scenario
        self.selected = 0
        self.pending: dict[str, Command] = {}
        self.message = ""
        #: goals clicked since each agent's route was last empty (what a patrol loop closes over)
        self.clicked: list[list[tuple[float, float]]] = [[] for _ in range(self.team.n)]
        self._speed = np.array([a.speed for a in sc.agents], dtype=np.float64)
        self._depot = sc.depot.footprint
        self._w = sc.world_size

    # ------------------------------------------------------------------ inputs
    def handle(self, event: Mapping[str, Any]) -> None:
        """Apply one input event (see the module docstring for the dict format)."""
        kind = event.get("type")
        if kind == "key":
            key = str(event.get("key", ""))
            if key.isdigit() and len(key) == 1 and key != "0":
                self.select(int(key) - 1)
            elif key in ("up", "down"):
                self.change_altitude(+1 if key == "up" else -1)
            return
        if kind == "click":
            pos = event.get("map")
            if pos is None:  # a click outside the map
                return
            x, y = (float(v) for v in pos)
            self.click(x, y)
            return
        raise InputError(f"unknown input event type {kind!r}; expected 'key' or 'click'")

    def select(self, row: int) -> None:
        """Select agent ``row`` (ignored with a message if the team is smaller)."""
        if 0 <= row < self.team.n:
            self.selected = row
            self.message = f"{self.team.ids[row]} selected"
        else:
            self.message = f"no agent {row + 1}: this team has {self.team.n}"

    def in_depot(self, x: float, y: float) -> bool:
        """Whether map point (x, y) lies inside the depot footprint."""
        x0, x1, y0, y1 = self._depot
        return x0 < x < x1 and y0 < y < y1

    def click(self, x: float, y: float) -> None:
        """A click at map point (x, y) for the selected agent: home, patrol loop or a new goal."""
        i = self.selected
        aid = self.team.ids[i]
        x = min(max(x, 0.0), self._w - 1.0)
        y = min(max(y, 0.0), self._w - 1.0)
        if self.in_depot(x, y):
            self.clicked[i] = []
            self._put(aid, route=None, patrol=False, home=True)
            self.message = f"{aid} sent home"
            return
        route, patrol = self._current_route(i)
        goals = self.clicked[i]
        if not route:
            goals = []
        first = goals[0] if goals else None
        near = first is not None and np.hypot(x - first[0], y - first[1]) <= (
            PATROL_RADIUS_STEPS * self._speed[i]
        )
        if not patrol and near and len(goals) >= 2:
            # close the loop; the agent carries on to the goal it is heading for
            k = len(goals) - len(route)
            loop = goals[k:] + goals[:k]
            self._put(aid, route=tuple(loop), patrol=True, home=False)
            self.message = f"{aid} patrols {len(loop)} goals"
            return
        if patrol:
            goals, route = [], []
        goals = [*goals, (x, y)]
        self.clicked[i] = goals
        self._put(aid, route=(*route, (x, y)), patrol=False, home=False)
        self.message = f"{aid} goal {len(goals)} at ({x:.0f}, {y:.0f})"

    def change_altitude(self, direction: int) -> None:
        """Raise (+1) or lower (-1) the selected agent's target altitude by :data:`ALTITUDE_STEP`."""
        i = self.selected
        aid = self.team.ids[i]
        if not self.team.can_sense[i]:
            self.message = f"{aid} flies at a fixed {self.team.z[i]:g} m"
            return
        cmd = self.pending.get(aid)
        z = cmd.altitude if cmd is not None and cmd.altitude is not None else self.team.z_target[i]
        z = float(np.clip(z + direction * ALTITUDE_STEP, self.team.alt_lo[i], self.team.alt_hi[i]))
        self._put(aid, altitude=z)
        self.message = f"{aid} altitude -> {z:g} m"

    # ------------------------------------------------------------------ commands
    def _put(self, aid: str, **fields: Any) -> None:
        old = self.pending.get(aid, Command())
        new: dict[str, Any] = {
            "route": old.route,
            "patrol": old.patrol,
            "altitude": old.altitude,
            "home": old.home,
        }
        new.update(fields)
        self.pending[aid] = Command(**new)

    def _current_route(self, i: int) -> tuple[list[tuple[float, float]], bool]:
        """Goals agent ``i`` still has to visit (pending command first), and its patrol flag."""
        cmd = self.pending.get(self.team.ids[i])
        if cmd is not None and cmd.home:
            return [], False
        if cmd is not None and cmd.route is not None:
            return [(p[0], p[1]) for p in cmd.route], cmd.patrol
        team = self.team
        if team.mode[i] in (Mode.IDLE, Mode.HOMING):
            return [], False
        r = team.routes[i]
        k = int(team.goal_index[i])
        rest = np.concatenate([r[k:], r[:k]]) if team.patrol[i] else r[k:]
        return [(float(a), float(b)) for a, b in rest], bool(team.patrol[i])

    def take_commands(self) -> dict[str, Command]:
        """The commands collected since the last call (for ``World.step``); clears them."""
        out, self.pending = self.pending, {}
        return out

    # ------------------------------------------------------------------ display
    def planned_route(self, i: int) -> np.ndarray:
        """(k, 2) goals agent ``i`` will visit from now on, in order (a patrol lists one loop)."""
        route, _ = self._current_route(i)
        return np.asarray(route, dtype=np.float64).reshape(-1, 2)

    def battery_at_goal(self, i: int) -> float:
        """Battery agent ``i`` would have left at its last planned goal (now, if it has none)."""
        team = self.team
        pts = np.vstack([team.pos[i : i + 1], self.planned_route(i)])
        d = float(np.hypot(*np.diff(pts, axis=0).T).sum()) if len(pts) > 1 else 0.0
        return float(team.battery[i] - DRAIN_PER_PX * d)
