"""The motion expert's move rule for every world and agent at once: the fast kernel of
:class:`fcplan.env.motion_expert.TeamRoutes`.

:class:`TeamRoutes` is the readable rule (its :meth:`~TeamRoutes.choose`: on arrival at a goal
dump once if it is a fire and dumping is legal, else drop the goal, a patrol putting it back at
the end; then the altitude first, then the larger of the two axis offsets, then the other, each
only if it is more than half a step and legal). :class:`BatchRoutes` keeps the routes of ``B``
worlds as padded arrays, a route as a ring of its goals (``start`` the head, ``count`` the goals
left, ``size`` the ring: a patrol pops its head and puts it back, i.e. moves ``start`` on), and
chooses every agent's action of every live world with numpy over the ``(world, agent)`` axes: the
arrival loop runs as many vector passes as the most goals any agent drops in a tick (usually
none or one). The comparisons are the rule's, on the same float64 values, so the actions are the
rule's (``tests/env/test_vector_moves.py``: random plans, positions, masks and modes against
:meth:`TeamRoutes.choose`, and the batched expert against the single one on whole episodes in
``tests/env/test_vector_expert.py``). One difference, where the rule has no answer: an agent
whose every patrol goal lies within half a step of it makes the rule loop forever; here it drops
at most one round of its goals per tick and then flies on.

Measured reason for writing it: with greedy planning all worlds in one call, the rule's Python
loop over worlds and agents was the largest part left of a batched expert step (``bench/README.md``,
"Greedy plans all the worlds in one call").
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.env.motion import ACTION_NAMES, role_letters
from fcplan.plan import Plan
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode

__all__ = ["BatchRoutes"]

#: the rule's action names, in the columns of the legality table
_NAMES = ("stay", "dump", "climb", "descend", "east", "west", "south", "north")
STAY, DUMP, CLIMB, DESCEND, EAST, WEST, SOUTH, NORTH = range(len(_NAMES))
_FIRE = int(TaskKind.FIRE)
_RETURNING = int(Mode.RETURNING)


class BatchRoutes:
    """What each world's team was told by its last plan, and the move rule of
    :class:`fcplan.env.motion_expert.TeamRoutes` for all of them (module docstring).

    Parameters
    ----------
    ids : list of str
        The agents, in row order.
    scenario : Scenario
        Their scenario (roles: each agent's action names).
    num : int
        Worlds.
    """

    def __init__(self, ids: list[str], scenario: Any, num: int) -> None:
        n = len(ids)
        self._row = {a: i for i, a in enumerate(ids)}
        names = [ACTION_NAMES[r] for r in role_letters(scenario)]
        #: (N, 8) the agent's action index of each name of _NAMES, -1 where its role has none
        self._act = np.array([[nm.index(x) if x in nm else -1 for x in _NAMES] for nm in names])
        self._can_act = [bool(a.role.can_act) for a in scenario.agents]
        self.gx = np.zeros((num, n, 4))
        self.gy = np.zeros((num, n, 4))
        self.dump = np.zeros((num, n, 4), dtype=bool)
        self.start = np.zeros((num, n), dtype=np.int64)
        self.count = np.zeros((num, n), dtype=np.int64)
        self.size = np.zeros((num, n), dtype=np.int64)
        self.alt = np.zeros((num, n))
        self.has_alt = np.zeros((num, n), dtype=bool)
        self.patrol = np.zeros((num, n), dtype=bool)

    def reset(self, rows: np.ndarray) -> None:
        """Forget the routes and altitudes of the worlds ``rows``."""
        for a in (self.start, self.count, self.size, self.has_alt, self.patrol):
            a[rows] = 0

    def follow(self, b: int, plan: Plan, graph: TaskGraph) -> None:
        """World ``b`` takes the routes and altitudes of a new plan (:meth:`TeamRoutes.follow`)."""
        tidx, pos, kind = graph.task_index, graph.task_pos, graph.task_kind
        for agent, z in plan.altitudes.items():
            i = self._row[agent]
            self.alt[b, i], self.has_alt[b, i] = float(z), True
        for agent in plan.home:
            i = self._row[agent]
            self.start[b, i] = self.count[b, i] = self.size[b, i] = 0
        for agent, route in plan.routes.items():
            i = self._row[agent]
            self.patrol[b, i] = agent in plan.patrol
            k = np.array([tidx[t] for t in route], dtype=np.int64)
            n = k.size
            if n > self.gx.shape[2]:
                self._grow(n)
            self.gx[b, i, :n], self.gy[b, i, :n] = pos[k, 0], pos[k, 1]
            self.dump[b, i, :n] = self._can_act[i] & (kind[k] == _FIRE)
            self.start[b, i], self.count[b, i], self.size[b, i] = 0, n, n

    def _grow(self, n: int) -> None:
        pad = ((0, 0), (0, 0), (0, max(n, 2 * self.gx.shape[2]) - self.gx.shape[2]))
        self.gx, self.gy = np.pad(self.gx, pad), np.pad(self.gy, pad)
        self.dump = np.pad(self.dump, pad)

    def choose(self, rows: np.ndarray, masks: np.ndarray, pos: np.ndarray, z_target: np.ndarray,
               mode: np.ndarray, speed: np.ndarray, climb: float) -> np.ndarray:  # fmt: skip
        """(len(rows), N) int64 actions of the worlds ``rows`` (:meth:`TeamRoutes.choose` of each
        world and agent) from the batch's (B, N, K) action masks, (B, N, 2) positions, (B, N)
        commanded altitudes and modes, the agents' (N,) speeds and the altitude step of a climb;
        the routes of those worlds move on as the rule's do."""
        n = self._act.shape[0]
        act = self._act
        m = masks[rows].astype(bool)
        legal = np.zeros((rows.size, n, len(_NAMES)), dtype=bool)
        has = act >= 0
        legal[:, has] = m[:, np.nonzero(has)[0], act[has]]
        x, y = pos[rows, :, 0], pos[rows, :, 1]
        half = 0.5 * speed[None, :]
        active = mode[rows] < _RETURNING  # (a forced return flies home by itself)
        choice = np.full((rows.size, n), STAY)
        start, count, size = self.start[rows], self.count[rows], self.size[rows]
        gx, gy, dump, patrol = self.gx[rows], self.gy[rows], self.dump[rows], self.patrol[rows]
        dumped = np.zeros((rows.size, n), dtype=bool)
        pops = np.zeros((rows.size, n), dtype=np.int64)
        while True:
            head = (start % np.maximum(size, 1))[:, :, None]
            hx = np.take_along_axis(gx, head, axis=2)[:, :, 0]
            hy = np.take_along_axis(gy, head, axis=2)[:, :, 0]
            near = active & ~dumped & (count > 0) & (pops < np.maximum(size, 1))
            near &= (np.abs(hx - x) <= half) & (np.abs(hy - y) <= half)
            if not near.any():
                break
            hd = np.take_along_axis(dump, head, axis=2)[:, :, 0]
            d = near & hd & legal[:, :, DUMP]
            choice[d] = DUMP
            w, a = np.nonzero(d)
            dump[w, a, head[w, a, 0]] = False  # one dump per goal
            dumped |= d
            p = near & ~d
            start[p] += 1
            pops[p] += 1
            count[p & ~patrol] -= 1  # a patrol loop goes round again
        alt, has_alt = self.alt[rows], self.has_alt[rows]
        z = z_target[rows]
        free = active & (choice == STAY) & has_alt  # altitude first
        up = free & (z < alt - 0.5 * climb) & legal[:, :, CLIMB]
        down = free & ~up & (z > alt + 0.5 * climb) & legal[:, :, DESCEND]
        choice[up], choice[down] = CLIMB, DESCEND
        go = active & (choice == STAY) & (count > 0)
        dx, dy = hx - x, hy - y
        ew, ns = np.where(dx > 0, EAST, WEST), np.where(dy > 0, SOUTH, NORTH)
        ax, ay = np.abs(dx), np.abs(dy)
        x_first = ax >= ay  # (the rule's stable sort by the larger offset)
        first, second = np.where(x_first, ew, ns), np.where(x_first, ns, ew)
        off1, off2 = np.where(x_first, ax, ay), np.where(x_first, ay, ax)

        def ok(name: np.ndarray) -> np.ndarray:
            return np.take_along_axis(legal, name[:, :, None], axis=2)[:, :, 0]

        one = go & (off1 > half) & ok(first)
        two = go & ~one & (off2 > half) & ok(second)
        choice[one], choice[two] = first[one], second[two]
        self.start[rows], self.count[rows], self.dump[rows] = start, count, dump
        return np.take_along_axis(np.broadcast_to(act, choice.shape + (len(_NAMES),)),
                                  choice[:, :, None], axis=2)[:, :, 0]  # fmt: skip
