"""From one auction's final bundles to conflict-free routes, completed greedily when cut short.

Conflicts
---------
Agents in different connected components reach consensus separately, and an auction stopped by
its round cap or the clock may not have reached it at all, so an item can sit in several bundles.
:func:`assemble` keeps each item with the agent that bid the most for it (ties to the lower
index) and drops it from the other routes; dropping a task never breaks a route's battery
feasibility (triangle inequality). The number of such items is ``conflicts``.

Greedy completion
-----------------
An auction that did not converge may leave a bidder with nothing only because it was stopped (it
had not built a bundle yet, or lost everything it held to the conflict rule). Handing that back
would make the limit decide, not the algorithm, so after a cut every bidder with an empty route
is *completed*, in index order: it builds a bundle exactly as in the auction (same scores,
insertion and feasibility rules, at most its bundle limit) from the items nobody holds, each
item it takes leaving the pool. ``completed`` counts the agents that got a route this way. After
a converged auction nothing is completed: an empty route there is what CBBA decided. With a
clock, completion gives up as soon as what is left of it would end past the clock's hard deadline
and raises :class:`~solvers.cbba.clock.CBBATimeLimitError` (:mod:`solvers.cbba.clock`).

Examples
--------
>>> import numpy as np
>>> from solvers.cbba.static import StaticInstance, solve_static
>>> inst = StaticInstance.random(np.random.default_rng(0), n_agents=3, n_tasks=8)
>>> full = solve_static(inst)
>>> cut = solve_static(inst, max_rounds=1)  # one round: no consensus yet
>>> cut.stopped_by, cut.conflicts >= 0, sum(map(len, cut.paths)) > 0
('max_rounds', True, True)
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from solvers.cbba.auction import Auction, StageResult, insertion_scores
from solvers.cbba.clock import BUILD_OVERHEAD, CBBATimeLimitError, Clock

__all__ = ["Assembly", "assemble"]


@dataclass(frozen=True, eq=False)
class Assembly:
    """Conflict-free routes of one auction.

    Attributes
    ----------
    paths : list of list of int
        Per agent, the items it serves in flying order.
    bids : list of list of float
        The bid of each item of ``paths`` (its marginal score when completed greedily).
    conflicts : int
        Items held by more than one agent at the end of the auction.
    completed : int
        Agents given a route by the greedy completion.
    """

    paths: list[list[int]]
    bids: list[list[float]]
    conflicts: int
    completed: int

    @property
    def objective(self) -> float:
        """Sum of the bids of the items kept."""
        return float(sum(sum(b) for b in self.bids))

    def holders(self, n_items: int) -> np.ndarray:
        """(n_items,) the agent serving each item (-1: none)."""
        out = np.full(n_items, -1, dtype=np.int64)
        for i, path in enumerate(self.paths):
            out[path] = i
        return out


def assemble(stage: StageResult, auc: Auction, clock: Clock | None = None) -> Assembly:
    """Resolve conflicts by bid and, if the auction was cut short, complete empty bidders
    greedily (see the module docstring)."""
    best: dict[int, tuple[float, int]] = {}
    held: dict[int, int] = {}
    for i, (bundle, placed) in enumerate(zip(stage.bundles, stage.bundle_bids, strict=True)):
        for j, b in zip(bundle, placed, strict=True):
            held[j] = held.get(j, 0) + 1
            cur = best.get(j)
            if cur is None or b > cur[0]:
                best[j] = (b, i)
    keep = {j: i for j, (_, i) in best.items()}
    bid_of = {j: b for j, (b, _) in best.items()}
    paths = [[j for j in path if keep.get(j) == i] for i, path in enumerate(stage.paths)]
    bids = [[bid_of[j] for j in path] for path in paths]
    conflicts = sum(1 for c in held.values() if c > 1)
    completed = 0
    if not stage.converged:
        completed = _complete(auc, paths, bids, clock)
    return Assembly(paths=paths, bids=bids, conflicts=conflicts, completed=completed)


def _complete(
    auc: Auction, paths: list[list[int]], bids: list[list[float]], clock: Clock | None
) -> int:
    """Give each bidder with an empty path a greedy bundle of free items; returns how many got
    one. Changes ``paths`` and ``bids`` in place."""
    free = np.ones(auc.value.shape[1], dtype=bool)
    for path in paths:
        free[path] = False
    bidders = np.flatnonzero(auc.eligible.any(axis=1)).tolist()
    todo = [i for i in bidders if not paths[i]]
    work = {i: int(auc.eligible[i].sum()) + BUILD_OVERHEAD for i in todo}
    completed = 0
    for n, i in enumerate(todo):
        if clock is not None and clock.past_hard(sum(work[k] for k in todo[n:])):
            raise CBBATimeLimitError(
                f"cbba: time limit {clock.limit:g} s too short to give {len(todo) - n} "
                "agent(s) a route"
            )
        t = time.perf_counter() if clock is not None else 0.0
        path, got = paths[i], bids[i]
        while len(path) < auc.limit[i]:
            cand = np.flatnonzero(auc.eligible[i] & free)
            if cand.size == 0:
                break
            score, where = insertion_scores(auc, i, path, cand)
            k = int(np.argmax(score))
            if not score[k] > 0.0:
                break
            j = int(cand[k])
            path.insert(int(where[k]), j)
            got.insert(int(where[k]), float(score[k]))
            free[j] = False
        if clock is not None:
            clock.record(time.perf_counter() - t, work[i])
        completed += bool(path)
    return completed
