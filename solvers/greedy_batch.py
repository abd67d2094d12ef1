"""Greedy's pick loop for many independent graphs at once: the fast kernel of
:meth:`solvers.greedy.GreedyScheduler._assign`.

A batched env replans hundreds of worlds at the same tick, and greedy's pick loop
(:meth:`~solvers.greedy.GreedyScheduler._assign`) makes a few dozen small numpy calls per pick
on a few agents and a hundred-odd tasks: per-call overhead, once per world. Here the worlds'
(agent, task) score matrices are stacked into one ``(W, A, K)`` array, padded with rows and
columns that can never be picked (``-inf``), and every pick step advances all worlds that still
have a finite pick: one pick per world per step, the loop running as many steps as the longest
world needs. The arithmetic is the readable rule's, element for element (the same expressions
in the same order; a multiplication by ``1.0`` where the rule leaves a value alone, which is
exact), so the picks, their order and the gained values are bit for bit those of the rule
(``tests/solvers/test_greedy_batch.py`` compares them on recorded episodes and on random
graphs). One difference in bookkeeping, not in result: the rule recomputes the best task only
of the agents a pick touched, this kernel of every agent; an untouched agent's best task kept
its score while the others only fell, so its ``argmax`` (the first maximum) is the same.

Measured reason for writing it (``bench/bench_vector_expert.py``): with one greedy call per
world, the solves were most of a batched expert rollout's time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from fcplan.taskgraph import TaskGraph

if TYPE_CHECKING:
    from solvers.greedy import _Job, _Picks

__all__ = ["assign_batch"]


def assign_batch(
    graphs: Sequence[TaskGraph],
    jobs: Sequence[_Job | None],
    *,
    spread_px: float | None,
) -> list[_Picks | None]:
    """The picks of :meth:`solvers.greedy.GreedyScheduler._assign` for every graph's job.

    Parameters
    ----------
    graphs : sequence of TaskGraph
    jobs : sequence of (agents, tasks, value, limit) or None
        Each graph's assignment problem (None: nothing to assign; its answer is None).
    spread_px : float or None
        The search step's discount radius (``spread=True`` in the rule); None for the fire step.

    Returns
    -------
    list of (routes, gained) or None
        Per graph, task rows per agent row in pick order and the value gained.
    """
    out: list[_Picks | None] = [None] * len(jobs)
    live = [i for i, j in enumerate(jobs) if j is not None and j[0].size and j[1].size]
    for i, job in enumerate(jobs):
        if job is not None and i not in live:
            out[i] = ({int(a): [] for a in job[0]}, 0.0)
    if not live:
        return out
    p = _Padded([graphs[i] for i in live], [jobs[i] for i in live])  # type: ignore[misc]
    picks = _run(p, spread_px)
    for n, i in enumerate(live):
        agents, tasks = p.agents[n], p.tasks[n]
        routes: dict[int, list[int]] = {int(a): [] for a in agents}
        for a, k in picks[n]:
            routes[int(agents[a])].append(int(tasks[k]))
        out[i] = (routes, float(p.gained[n]))
    return out


class _Padded:
    """The rule's per-world arrays stacked along a leading world axis, padded to the largest
    world: padded agents have no route left (limit 0), padded tasks are infeasible."""

    def __init__(self, graphs: list[TaskGraph], jobs: list[_Job]) -> None:
        w = len(jobs)
        self.agents = [j[0] for j in jobs]
        self.tasks = [j[1] for j in jobs]
        na = max(a.size for a in self.agents)
        nk = max(t.size for t in self.tasks)
        self.speed = np.ones((w, na))
        self.pos = np.zeros((w, na, 2))
        self.home = np.zeros((w, na, nk))
        self.ok = np.zeros((w, na, nk), dtype=bool)
        self.left = np.zeros((w, na))
        self.limit = np.zeros((w, na), dtype=np.int64)
        self.value = np.zeros((w, nk))
        self.tpos = np.zeros((w, nk, 2))
        for n, (g, (agents, tasks, value, limit)) in enumerate(zip(graphs, jobs, strict=True)):
            a, k = agents.size, tasks.size
            v = value.astype(np.float64)
            self.value[n, :k] = v
            self.speed[n, :a] = g.agent_speed[agents]
            self.pos[n, :a] = g.agent_start_pos[agents]
            self.home[n, :a, :k] = g.task_home_distance[np.ix_(agents, tasks)]
            self.ok[n, :a, :k] = g.in_round_trip[np.ix_(agents, tasks)] & (v > 0)[None, :]
            self.left[n, :a] = g.agent_budget_px[agents]
            self.limit[n, :a] = limit
            self.tpos[n, :k] = g.task_pos[tasks]
        self.used = np.zeros((w, na))
        self.elapsed = np.zeros((w, na))
        self.count = np.zeros((w, na), dtype=np.int64)
        self.taken = np.zeros((w, nk), dtype=bool)
        self.gained = np.zeros(w)

    def rows(self, ws: np.ndarray, ag: np.ndarray | None) -> tuple[np.ndarray, ...]:
        """(score, distance, eta) of worlds ``ws``: every agent's row (``ag`` None, shape
        (w, A, K)) or agent ``ag[n]``'s row of world ``ws[n]`` (shape (w, K)); the rule's
        ``rows``."""
        if ag is None:
            pos, el, sp, used, left = (x[ws] for x in (self.pos, self.elapsed, self.speed,
                                                       self.used, self.left))  # fmt: skip
            ok, home, value, tpos = self.ok[ws], self.home[ws], self.value[ws], self.tpos[ws]
            diff = pos[:, :, None, :] - tpos[:, None, :, :]
            d = np.sqrt(np.einsum("wakc,wakc->wak", diff, diff))
            eta = el[:, :, None] + d / sp[:, :, None]
            feasible = ok & (used[:, :, None] + d + home <= left[:, :, None])
            score = np.where(feasible, value[:, None, :] / (1.0 + eta), -np.inf)
            return score, d, eta
        pos, el, sp = self.pos[ws, ag], self.elapsed[ws, ag], self.speed[ws, ag]
        used, left = self.used[ws, ag], self.left[ws, ag]
        ok, home, value = self.ok[ws, ag], self.home[ws, ag], self.value[ws]
        diff = pos[:, None, :] - self.tpos[ws]
        d = np.sqrt(np.einsum("wkc,wkc->wk", diff, diff))
        eta = el[:, None] + d / sp[:, None]
        feasible = ok & (used[:, None] + d + home <= left[:, None])
        score = np.where(feasible, value / (1.0 + eta), -np.inf)
        return score, d, eta


def _run(p: _Padded, spread_px: float | None) -> list[list[tuple[int, int]]]:
    """The pick loop over all worlds; returns each world's (agent, task) picks in order and
    leaves the gained values in ``p.gained``."""
    w = p.value.shape[0]
    every = np.arange(w)
    score, dist, eta = p.rows(every, None)
    score[p.count >= p.limit] = -np.inf
    best = np.argmax(score, axis=2)
    best_s = np.take_along_axis(score, best[:, :, None], axis=2)[:, :, 0]
    picks: list[list[tuple[int, int]]] = [[] for _ in range(w)]
    ws = every
    while ws.size:
        a = np.argmax(best_s[ws], axis=1)
        k = best[ws, a]
        fin = np.isfinite(best_s[ws, a])
        ws, a, k = ws[fin], a[fin], k[fin]
        if not ws.size:
            break
        for n, ai, ki in zip(ws.tolist(), a.tolist(), k.tolist(), strict=True):
            picks[n].append((ai, ki))
        p.gained[ws] += p.value[ws, k]
        p.count[ws, a] += 1
        p.used[ws, a] += dist[ws, a, k]
        p.elapsed[ws, a] = eta[ws, a, k]
        p.pos[ws, a] = p.tpos[ws, k]
        p.taken[ws, k] = True
        score[ws, :, k] = -np.inf  # one agent per task
        if spread_px is not None:
            rel = p.tpos[ws] - p.tpos[ws, k][:, None, :]
            near = np.hypot(rel[..., 0], rel[..., 1]) < spread_px
            near[np.arange(ws.size), k] = False
            scale = np.where(near, 0.3, 1.0)
            p.value[ws] *= scale
            score[ws] *= scale[:, None, :]  # scores are proportional to value (finite ones > 0)
        more = p.count[ws, a] < p.limit[ws, a]
        wm, am = ws[more], a[more]
        if wm.size:
            row, d_a, eta_a = p.rows(wm, am)
            row[p.taken[wm]] = -np.inf
            score[wm, am], dist[wm, am], eta[wm, am] = row, d_a, eta_a
        score[ws[~more], a[~more]] = -np.inf
        sub = score[ws]
        best[ws] = np.argmax(sub, axis=2)
        best_s[ws] = np.take_along_axis(sub, best[ws][:, :, None], axis=2)[:, :, 0]
    return picks
