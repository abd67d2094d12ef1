"""One CBBA auction: bundle construction and consensus, alternated until the agents agree.

The agents of an :class:`Auction` bid on its items with scores fixed for the whole auction;
:func:`run_auction` simulates them in synchronous rounds (Choi, Brunet and How 2009).

Phase 1: bundle construction
----------------------------
Each agent scores a path (its tasks in flying order, from its start to its depot slot) with the
time-discounted reward ``S(path) = sum_j value_j * 2 ** (-t_j / half_life_s)``, where ``t_j`` is
the arrival time at task ``j`` along the path (dump value: the task value weighted by freshness,
as in greedy). The marginal score of task ``j`` is the best gain over insertion positions,
``c_j = max_n S(path (+)_n j) - S(path)``: the discounted value of ``j`` minus what the detour
costs the tasks after it. Feasible insertions keep ``start -> tasks -> home`` within the agent's
budget (:attr:`fcplan.taskgraph.TaskGraph.agent_budget_px`: its battery, or a full battery from
the depot slot for an agent on a forced return) and every task within a full-battery round trip
of home (:attr:`fcplan.taskgraph.TaskGraph.in_round_trip`). Bundles hold at most ``bundle_length`` tasks,
and an action agent's no more than its tank. The agent repeatedly adds the task with the largest
marginal score among those where its bid beats the winning bid it knows (higher bid, ties to the
lower agent index), until the bundle is full or no bid can win.

*Diminishing marginal gain (DMG).* CBBA's convergence proof needs an agent's bid for a task not
to grow as its bundle grows. The time-discounted reward mostly has this property (a longer path
reaches every task later, and a detour delays more tasks), but not always: a task added to the
bundle can offer a cheaper place to insert another one. So the bid is *warped* (Johnson, Choi,
Ponda and How, "Allowing non-submodular score functions in distributed task allocation", CDC
2012): the bid placed is ``min(c_j, last bid in the bundle)``, and every bundle's bids are
non-increasing. The task is chosen by its true marginal score. (The watch rule only makes bids
drop: a watch cannot join a non-empty bundle.) Even with a DMG score the warp can bind: a task
the agent could not win when it built its bundle, freed later, may score more than the tasks
added before it. Plain CBBA bids ``c_j`` there; ``Auction.warp=False`` does that.

*Append-only insertion.* With ``Auction.append_only`` a task may only join the end of a path,
so ``c_j`` is just its discounted value at the path's end: the rule of implementations that
promise every task in a path its arrival time and insert only where no promise is broken
(:mod:`solvers.cbba.static`). That score is DMG (by the triangle inequality a task appended
later is reached no earlier), and it runs as plain CBBA (no warp).

Phase 2: consensus
------------------
Over the communication graph (:mod:`solvers.cbba.comms`), each round every agent broadcasts its
winning bids ``y``, winners ``z`` and timestamps ``s`` to all its neighbours (``messages`` counts
these sender-to-receiver transmissions: the sum of the degrees, every round, relays included). A receiver processes its neighbours' messages in
index order with the update / reset / leave rules of Table I of the paper (vectorised over the
tasks; a sender sends what it held at the start of the round), then updates its timestamps
(``s_ik`` = this round for a neighbour ``k``, else the newest copy a neighbour had). An agent that
has lost a task of its bundle releases that task and every task it added after it (those it still
believed it held are reset to "no winner", as in the authors' reference implementation).

Convergence
-----------
Rounds alternate phase 1 and phase 2 until a round after the first ``diameter`` (the largest
hop diameter of a connected component) changes no agent's ``y``, ``z`` or bundle; that round is
a fixed point. Proof: a timestamp ``s_in`` is 0 until news from ``n`` first reaches ``i``, and
from round ``hop(i, n)`` on it is ``t - hop(i, n) + 1`` at the end of round ``t`` (by induction
over the hops), so from round ``diameter + 1`` on every comparison of Table I (``s_kn`` against
``s_in``, within a round too) has the same outcome in every round. A round that then changes
nothing is followed by one that starts from the same ``y``, ``z`` and bundles, compares the same
way and so changes nothing either. ``last_change`` is the last round in which something changed
(0: none). The simulator sees every agent, so it can stop there; agents on their own would need
a detection protocol (e.g. ``diameter`` quiet rounds) on top. An auction also stops after
``max_rounds``, or when the wall clock says so (:mod:`solvers.cbba.clock`; asked before each
bundle construction and each neighbour slot; a consensus round cut short is discarded).

One row of Table I differs from the paper. Synchronous rounds make equal timestamps common, and
in the row where sender and receiver name two different third agents ``m`` (sender) and ``n``
(receiver) the paper's rule then leaves some stale beliefs in place for ever (seen on a 23-agent
team: agents disagreeing about a winner, with nothing left to change their minds). That row
follows the authors' reference implementation: update if ``s_kn > s_in`` and ``s_km >= s_im``,
reset if ``s_kn > s_in`` and ``s_km < s_im``, else update if ``s_km > s_im`` and the sender's
bid is higher.

Cost
----
A round costs one bundle construction per agent whose view changed (``O(L)`` numpy passes over
the tasks it may bid on) plus, per neighbour slot (at most ``A - 1``), one numpy pass over the
tasks somebody holds; only the entries where a message differs from the receiver's belief go
through the table.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from solvers.cbba.clock import BUILD_OVERHEAD, Clock
from solvers.cbba.comms import CommGraph

__all__ = ["NO_WINNER", "STOPS", "Auction", "StageResult", "insertion_scores", "run_auction"]

NO_WINNER = -1  # "no winner" in a winner vector

#: Why an auction stopped: it converged, it hit ``max_rounds``, or the wall clock ran out.
STOPS = ("converged", "max_rounds", "time_limit")


@dataclass(frozen=True, eq=False)
class Auction:
    """One CBBA auction: ``A`` agents (all of them, bidders or relays), ``M`` items."""

    value: np.ndarray  # (A, M) item value to each agent (time zero)
    eligible: np.ndarray  # (A, M) bool: the agent may bid on the item
    exclusive: np.ndarray  # (M,) bool: an item that is a whole path on its own
    limit: np.ndarray  # (A,) int: most items in a bundle
    item_pos: np.ndarray  # (M, 2)
    d_start: np.ndarray  # (A, M) px from the agent's start to each item
    d_home: np.ndarray  # (A, M) px from each item to the agent's depot slot
    start: np.ndarray  # (A, 2)
    home: np.ndarray  # (A, 2)
    budget: np.ndarray  # (A,) px of flight
    speed: np.ndarray  # (A,) px/s
    rate: float  # discount rate per second: score = value * exp(-rate * t)
    append_only: bool = False  # a task only joins the end of a path
    warp: bool = True  # bid min(c_j, last bid in the bundle)


@dataclass(frozen=True, eq=False)
class StageResult:
    """Outcome of one auction.

    Attributes
    ----------
    name : str
        ``"dump"`` or ``"sense"``.
    items : ndarray, (M,) int
        Task row of each item.
    winners, bids : ndarray, (A, M)
        Every agent's final winner vector ``z`` (-1: none) and winning-bid vector ``y``.
    paths, bundles : list of list of int
        Each agent's final path (flying order) and bundle (order added), as item indices.
    bundle_bids : list of list of float
        The bid placed for each bundle entry.
    rounds, messages : int
        Rounds started (a round cut short by the clock counts) and messages sent.
    last_change : int
        Last round in which an agent's ``y``, ``z`` or bundle changed (0: none did).
    stopped_by : str
        One of :data:`STOPS`.
    """

    name: str
    items: np.ndarray
    winners: np.ndarray
    bids: np.ndarray
    paths: list[list[int]]
    bundles: list[list[int]]
    bundle_bids: list[list[float]]
    rounds: int
    messages: int
    last_change: int
    stopped_by: str

    @property
    def converged(self) -> bool:
        """The auction reached its fixed point (see the module docstring)."""
        return self.stopped_by == "converged"

    @property
    def timed_out(self) -> bool:
        """The wall clock stopped the auction."""
        return self.stopped_by == "time_limit"


def insertion_scores(
    auc: Auction, i: int, path: list[int], cand: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Best marginal score of inserting each candidate item into agent ``i``'s path, and where.

    Returns ``(score, position)`` over ``cand``; ``-inf`` where no insertion is feasible.
    """
    n = len(path)
    rate, speed = auc.rate, auc.speed[i]
    pos = auc.item_pos[cand]
    d_start = auc.d_start[i, cand]
    d_home = auc.d_home[i, cand]
    if n:
        pts = np.vstack([auc.start[i], auc.item_pos[path], auc.home[i]])
        legs = np.hypot(*np.diff(pts, axis=0).T)  # (n + 1,) start -> p0 ... p_{n-1} -> home
        reach = np.cumsum(legs)[:n]  # px to reach each path item
        disc = auc.value[i, path] * np.exp(-rate * reach / speed)
        tail = np.r_[np.cumsum(disc[::-1])[::-1], 0.0]  # (n + 1,) value of items at/after slot
        d_path = np.hypot(*(pos[None, :, :] - auc.item_pos[path][:, None, :]).transpose(2, 0, 1))
        d_prev = np.vstack([d_start[None, :], d_path])  # (n + 1, m): from the node before slot q
        d_next = np.vstack([d_path, d_home[None, :]])  # (n + 1, m): to the node after slot q
        before = np.r_[0.0, reach]  # px flown when leaving the node before slot q
        total = float(legs.sum())
    else:
        legs = np.array([float(np.hypot(*(auc.home[i] - auc.start[i])))])
        tail = np.zeros(1)
        d_prev, d_next = d_start[None, :], d_home[None, :]
        before = np.zeros(1)
        total = float(legs[0])
    detour = d_prev + d_next - legs[:, None]
    arrive = (before[:, None] + d_prev) / speed
    gain = auc.value[i, cand][None, :] * np.exp(-rate * arrive)
    loss = tail[:, None] * -np.expm1(-rate * detour / speed)
    score = gain - loss
    feasible = total + detour <= auc.budget[i] + 1e-9
    if auc.append_only:
        feasible[:n] = False  # only the last slot
    if n:
        feasible[:, auc.exclusive[cand]] = False  # an exclusive item only on an empty path
        if auc.exclusive[path[0]]:
            feasible[:] = False  # nothing joins an exclusive item
    score = np.where(feasible, score, -np.inf)
    where = np.argmax(score, axis=0)
    return score[where, np.arange(cand.size)], where


class _Agents:
    """The state of every simulated agent in one auction."""

    def __init__(self, auc: Auction) -> None:
        a, m = auc.value.shape
        self.auc = auc
        self.y = np.zeros((a, m))
        self.z = np.full((a, m), NO_WINNER, dtype=np.int64)
        self.s = np.zeros((a, a))
        self.paths: list[list[int]] = [[] for _ in range(a)]
        self.bundles: list[list[int]] = [[] for _ in range(a)]
        self.bids: list[list[float]] = [[] for _ in range(a)]
        self.cand = [np.flatnonzero(auc.eligible[i]) for i in range(a)]
        self.n_agents = a

    # ---------------------------------------------------------------- phase 1
    def build(self, i: int) -> bool:
        """Add tasks to agent ``i``'s bundle; True if it bid on something."""
        auc = self.auc
        cand = self.cand[i]
        bundle, path, bids = self.bundles[i], self.paths[i], self.bids[i]
        if cand.size == 0 or len(bundle) >= auc.limit[i]:
            return False
        free = np.ones(cand.size, dtype=bool)
        if bundle:
            free[np.isin(cand, bundle)] = False
        added = False
        while len(bundle) < auc.limit[i]:
            score, where = insertion_scores(auc, i, path, cand)
            bid = np.minimum(score, bids[-1]) if bids and auc.warp else score
            y, z = self.y[i, cand], self.z[i, cand]
            zz = np.where(z == NO_WINNER, self.n_agents, z)
            beats = (bid > y) | ((bid == y) & (i < zz))
            ok = free & beats & (bid > 0.0)
            if not ok.any():
                break
            k = int(np.argmax(np.where(ok, score, -np.inf)))
            j = int(cand[k])
            path.insert(int(where[k]), j)
            bundle.append(j)
            bids.append(float(bid[k]))
            self.y[i, j] = bid[k]
            self.z[i, j] = i
            free[k] = False
            added = True
        return added

    # ---------------------------------------------------------------- phase 2
    def consensus(
        self,
        slots: list[tuple[np.ndarray, np.ndarray]],
        t: int,
        stop: Callable[[], bool] | None = None,
    ) -> np.ndarray | None:
        """One synchronous round of message passing (Table I of the paper); returns the (A,) rows
        whose ``y`` or ``z`` changed, or None (and changes nothing) if ``stop()`` said so before
        a neighbour slot."""
        a = self.n_agents
        s0 = self.s.copy()
        cols = np.flatnonzero((self.z != NO_WINNER).any(axis=0))
        if cols.size == 0:
            for rec, snd in slots:
                self.s[rec] = np.maximum(self.s[rec], s0[snd])
                self.s[rec, snd] = t
            return np.zeros(a, dtype=bool)
        y0, z0 = self.y[:, cols], self.z[:, cols]  # snapshot: what each agent sends
        y, z = y0.copy(), z0.copy()
        s = s0.copy()
        for rec, snd in slots:
            if stop is not None and stop():
                return None
            # only entries where the message differs from the receiver's belief can change it
            zk_all = z0[snd]
            yk_all = y0[snd]
            rr, cc = np.nonzero((z[rec] != zk_all) | (y[rec] != yk_all))
            if rr.size:
                i, k = rec[rr], snd[rr]
                zi, yi = z[i, cc], y[i, cc]
                zk, yk = zk_all[rr, cc], yk_all[rr, cc]
                m = np.maximum(zk, 0)  # sender's winner (where it has one)
                n = np.maximum(zi, 0)  # receiver's winner
                sk_m, si_m = s0[k, m], s[i, m]
                newer_m, older_m = sk_m > si_m, sk_m < si_m
                newer_n = s0[k, n] > s[i, n]
                outbid = (yk > yi) | ((yk == yi) & (zk < zi))
                k_none, i_none = zk == NO_WINNER, zi == NO_WINNER
                k_self, k_rec = zk == k, zk == i
                k_other = ~k_none & ~k_self & ~k_rec
                i_rec, i_snd = zi == i, zi == k
                i_other = ~i_none & ~i_rec & ~i_snd
                same = zi == zk
                update = (
                    (k_self & ((i_rec & outbid) | i_snd | (i_other & (newer_n | outbid)) | i_none))
                    | (
                        k_other
                        & (
                            (i_rec & newer_m & outbid)
                            | (i_snd & newer_m)
                            | (same & newer_m)
                            | (i_other & ~same & ((newer_n & ~older_m) | (newer_m & outbid)))
                            | (i_none & newer_m)
                        )
                    )
                    | (k_none & (i_snd | (i_other & newer_n)))
                )
                reset = (k_rec & (i_snd | (i_other & newer_n))) | (
                    k_other & ((i_snd & ~newer_m) | (i_other & ~same & newer_n & older_m))
                )
                y[i, cc] = np.where(update, yk, np.where(reset, 0.0, yi))
                z[i, cc] = np.where(update, zk, np.where(reset, NO_WINNER, zi))
            s[rec] = np.maximum(s[rec], s0[snd])
            s[rec, snd] = t
        changed = (y != y0).any(axis=1) | (z != z0).any(axis=1)
        self.s = s
        self.y[:, cols] = y
        self.z[:, cols] = z
        return changed

    def release(self) -> np.ndarray:
        """Drop every bundle's first lost task and all tasks added after it; (A,) rows changed."""
        changed = np.zeros(self.n_agents, dtype=bool)
        for i, bundle in enumerate(self.bundles):
            if not bundle:
                continue
            b = np.asarray(bundle)
            own = self.z[i, b] == i
            if own.all():
                continue
            first = int(np.argmin(own))
            later = b[first + 1 :][own[first + 1 :]]
            self.y[i, later] = 0.0
            self.z[i, later] = NO_WINNER
            gone = set(bundle[first:])
            self.paths[i] = [j for j in self.paths[i] if j not in gone]
            del bundle[first:]
            del self.bids[i][first:]
            changed[i] = True
        return changed


def run_auction(
    name: str,
    auc: Auction,
    items: np.ndarray,
    comm: CommGraph,
    *,
    max_rounds: int,
    clock: Clock | None = None,
) -> StageResult:
    """Alternate bundle construction and consensus until a round after the first ``diameter``
    changes nothing, ``max_rounds``, or the ``clock`` (None: never read) says stop."""
    agents = _Agents(auc)
    bidders = cast(np.ndarray, auc.eligible.any(axis=1))
    slots = comm.slots()
    per_round = comm.messages_per_round
    dirty = bidders.copy()
    rounds = messages = last_change = 0
    stopped_by = "max_rounds"
    work = np.array([c.size + BUILD_OVERHEAD for c in agents.cand], dtype=np.float64)
    pending = float(work[bidders].sum())  # work of completing the bidders holding nothing

    def stop() -> bool:
        return clock is not None and clock.past(pending)

    while rounds < max_rounds:
        if stop():
            stopped_by = "time_limit"
            break
        rounds += 1
        changed = cut = False
        for i in np.flatnonzero(dirty & bidders).tolist():
            if stop():
                cut = True
                break
            was_empty = not agents.bundles[i]
            t = time.perf_counter() if clock is not None else 0.0
            changed |= agents.build(i)
            if clock is not None:
                clock.record(time.perf_counter() - t, work[i])
            if was_empty and agents.bundles[i]:
                pending -= work[i]
            dirty[i] = False
        if not cut and per_round:
            moved = agents.consensus(slots, rounds, stop if clock is not None else None)
            if moved is None:
                cut = True
            else:
                messages += per_round
                released = agents.release()
                changed |= bool(moved.any() or released.any())
                dirty |= moved | released
                empty = np.array([not b for b in agents.bundles], dtype=bool)
                pending = float(work[bidders & empty].sum())
        if changed:
            last_change = rounds
        if cut:
            stopped_by = "time_limit"
            break
        if not changed and rounds > comm.diameter:
            stopped_by = "converged"
            break
    return StageResult(
        name=name,
        items=items,
        winners=agents.z,
        bids=agents.y,
        paths=agents.paths,
        bundles=agents.bundles,
        bundle_bids=agents.bids,
        rounds=rounds,
        messages=messages,
        last_change=last_change,
        stopped_by=stopped_by,
    )
