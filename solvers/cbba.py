"""CBBA: the consensus-based bundle algorithm, run as decentralised agents with a radio range.

Choi, Brunet and How, "Consensus-Based Decentralized Auctions for Robust Task Allocation", IEEE
Transactions on Robotics 25(4), 2009. Every agent keeps its own copy of the auction state and
only talks to the agents within ``graph.comm_range`` px of it; the scheduler simulates those
agents in synchronous rounds and assembles their final bundles into a :class:`fcplan.plan.Plan`.

Auction items and services
--------------------------
A fire task can be served in two ways, so conflict-freeness is per **(task, service)**:

* ``dump``: one action (or hybrid) agent dumps water on the fire task;
* ``sense``: one camera agent (perception or hybrid) serves the task with its camera: it covers
  a search block, or it *watches* a fire task (hovers over it, low) so the cells the fire adds
  before the dump are sensed and can be pruned (only sensed cells can be pruned).

A fire task may thus appear in one dumper's route and one watcher's route, never in two dumpers'
or two watchers' routes; a search task appears in at most one route. Two auctions run one after
the other over the same communication graph, each a complete CBBA run with fixed scores:

1. the **dump auction**: items are the fire tasks; bidders are the action and hybrid agents with
   water (an agent on a forced return counts its full tank: it refills at the depot first);
2. the **sense auction**: items are all tasks (watch a fire, cover a search block); bidders are
   the camera agents that won no dump. Each agent values the items with what it learnt in the
   dump auction (its own winner vector, so only what reached its component). A fire an
   action-only agent will dump on is *fought*; the fought tile of each connected fire closest to
   its dumper's start *leads* the fight (most likely the first dump; every agent knows where its
   teammates are from the task graph, but not their paths: CBBA only shares ``y, z, s``). Watching a lead is worth
   ``watch_weight * (top search value + value_k)``, so one camera per fought fire supports the
   fight before any searching (greedy's watchers, one per connected fire); watching another
   fought tile is worth ``watch_weight * value_k``, and an unfought fire
   ``watch_weight * value_k * (1 - freshness_k)`` (re-sensing a stale fire makes it worth dumping
   at the next replan; a fresh, unfought fire is worth nothing to watch). Search blocks are
   worth their task value. A watch is a whole route on its own (the agent flies there and
   hovers): it is only bid on with an empty bundle and nothing joins it.

Both auctions are plain CBBA with scores fixed for the whole auction (the sense scores depend on
the dump auction's outcome, settled by then), so each converges on its own; the rounds and
messages reported are the sums over the two.

Phase 1: bundle construction
----------------------------
Each agent scores a path (its tasks in flying order, from its start to its depot slot) with the
time-discounted reward ``S(path) = sum_j value_j * 2 ** (-t_j / half_life_s)``, where ``t_j`` is
the arrival time at task ``j`` along the path (dump value: the task value weighted by freshness,
as in greedy). The marginal score of task ``j`` is the best gain over insertion positions,
``c_j = max_n S(path (+)_n j) - S(path)``: the discounted value of ``j`` minus what the detour
costs the tasks after it. Feasible insertions keep ``start -> tasks -> home`` within the battery
(``battery / 0.1`` px; a full battery from the depot slot for an agent on a forced return) and
every task within a full-battery round trip of home. Bundles hold at most ``bundle_length`` tasks,
and an action agent's no more than its tank. The agent repeatedly adds the task with the largest
marginal score among those where its bid beats the winning bid it knows (higher bid, ties to the
lower agent index), until the bundle is full or no bid can win.

*Diminishing marginal gain (DMG).* CBBA's convergence proof needs an agent's bid for a task not
to grow as its bundle grows. The time-discounted reward mostly has this property (a longer path
reaches every task later, and a detour delays more tasks), but not always: a task added to the
bundle can offer a cheaper place to insert another one. So the bid is *warped* (Johnson, Choi,
Ponda and How, "Allowing non-submodular score functions in distributed task allocation", CDC
2012): the bid placed is ``min(c_j, last bid in the bundle)``. Every bundle's bids are then
non-increasing, which is what the proof uses; with a DMG score the warp never binds, so this is
plain CBBA. The task is chosen by its true marginal score. (The watch rule only makes bids
drop: a watch cannot join a non-empty bundle.)

Phase 2: consensus
------------------
Agents ``i`` and ``k`` are neighbours when their positions at the replan are at most
``comm_range`` px apart (None: everyone talks to everyone); the graph stays fixed during the
auctions. Each round every agent broadcasts its winning bids ``y``, winners ``z`` and timestamps
``s`` to all its neighbours (``messages`` counts these sender-to-receiver transmissions: the sum
of the degrees, every round, relays included). A receiver processes its neighbours' messages in
index order with the update / reset / leave rules of Table I of the paper (vectorised over the
tasks; a sender sends what it held at the start of the round), then updates its timestamps
(``s_ik`` = this round for a neighbour ``k``, else the newest copy a neighbour had). An agent that
has lost a task of its bundle releases that task and every task it added after it (those it still
believed it held are reset to "no winner", as in the authors' reference implementation). Rounds
alternate phase 1 and phase 2 until no agent's ``y``, ``z`` or bundle has changed for
``2 * diameter`` rounds (at least one), ``diameter`` being the largest hop diameter of a
connected component, or until ``max_rounds``.

One row of Table I differs from the paper. Synchronous rounds make equal timestamps common, and
in the row where sender and receiver name two different third agents ``m`` (sender) and ``n``
(receiver) the paper's rule then leaves some stale beliefs in place for ever (seen on a 23-agent
team: agents disagreeing about a winner, with nothing left to change their minds). That row
follows the authors' reference implementation: update if ``s_kn > s_in`` and ``s_km >= s_im``,
reset if ``s_kn > s_in`` and ``s_km < s_im``, else update if ``s_km > s_im`` and the sender's
bid is higher.

Disconnected teams
------------------
Each connected component reaches consensus on its own, and agents in different components may
both win the same (task, service). Sending both would be what a truly decentralised team does, but
the testbed executes one plan, so the plan assembly keeps the higher bid (ties to the lower agent
index) and drops the task from the other route; dropping a task from a route never breaks its
battery feasibility (triangle inequality). These are counted as ``conflicts_resolved`` in the
stats, so the price of the partition is visible; with a connected team it is 0 at convergence.

Time limit
----------
The rounds stop when the time limit passes (each auction runs at least one round, so perception
agents still get routes); the bundles the agents hold then are assembled as above (conflicts
resolved by bid) and the status is ``time_limit``.

Stats
-----
``status`` is ``heuristic`` (``time_limit`` when stopped by the limit); ``objective`` is the sum of
the winning bids of the tasks in the final plan; ``size`` holds ``agents``, ``tasks``, ``rounds``,
``messages``, ``converged``, ``components``, ``diameter`` and ``conflicts_resolved``, and
``message`` says the same in words. Agents on their way home for good (``HOMING``) do not bid but
relay messages. Camera agents fly at ``watch_altitude`` when they watch and at ``search_altitude``
when they search. The algorithm uses no randomness (ties go to lower indices), so plans
are deterministic.

Cost
----
A round costs one bundle construction per agent whose view changed (``O(L)`` numpy passes over
the tasks it may bid on) plus, per neighbour slot (at most ``A - 1``), one numpy pass over the
tasks somebody holds; only the entries where a message differs from the receiver's belief go
through the table. About 0.5 s for 100 agents x 2,000 tasks with full communication
(``bench/bench_cbba.py``).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from solvers.cbba import CBBAScheduler
>>> g = synthetic_task_graph(4, 20, np.random.default_rng(0), comm_range=400.0)
>>> plan = CBBAScheduler().plan(g, time_limit=None, rng=np.random.default_rng(0))
>>> plan.stats.size["converged"], plan.stats.size["rounds"] > 0
(True, True)
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, shortest_path

from fcplan.plan import Plan
from fcplan.scheduling import SolveStats
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Mode

__all__ = ["CBBAScheduler", "CBBAResult", "CommGraph", "StageResult", "communication_graph"]

_NONE = -1  # "no winner" in a winner vector


# ---------------------------------------------------------------------- communication graph
@dataclass(frozen=True, eq=False)
class CommGraph:
    """Who can talk to whom.

    Attributes
    ----------
    adjacency : ndarray, (A, A) bool
        Symmetric, False on the diagonal.
    labels : ndarray, (A,) int
        Connected-component label of each agent.
    n_components : int
    diameter : int
        Largest hop diameter over the components (0 when nobody can talk).
    """

    adjacency: np.ndarray
    labels: np.ndarray
    n_components: int
    diameter: int

    @property
    def messages_per_round(self) -> int:
        """Messages sent in one round: each agent broadcasts to each of its neighbours."""
        return int(self.adjacency.sum())

    def slots(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """``(receivers, senders)`` per neighbour slot: in slot ``n`` every agent with more than
        ``n`` neighbours hears its ``n``-th neighbour (index order)."""
        deg = self.adjacency.sum(axis=1)
        # row i: its neighbours in index order first (stable sort of "not a neighbour")
        order = np.argsort(~self.adjacency, axis=1, kind="stable")
        out = []
        for n in range(int(deg.max(initial=0))):
            rec = np.flatnonzero(deg > n)
            out.append((rec, order[rec, n]))
        return out


def communication_graph(positions: np.ndarray, comm_range: float | None) -> CommGraph:
    """The communication graph of agents at ``positions`` with radio range ``comm_range`` px.

    Examples
    --------
    >>> import numpy as np
    >>> cg = communication_graph(np.array([[0.0, 0], [100, 0], [500, 0]]), 150.0)
    >>> cg.n_components, cg.diameter, cg.messages_per_round
    (2, 1, 2)
    """
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    n = len(pos)
    if comm_range is None:
        adj = ~np.eye(n, dtype=bool)
    else:
        d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
        adj = (d <= float(comm_range)) & ~np.eye(n, dtype=bool)
    if n == 0:
        return CommGraph(adj, np.zeros(0, dtype=np.int64), 0, 0)
    n_comp, labels = connected_components(csr_matrix(adj), directed=False)
    if comm_range is None:
        diameter = 1 if n > 1 else 0
    else:
        hops = shortest_path(csr_matrix(adj), directed=False, unweighted=True)
        finite = hops[np.isfinite(hops)]
        diameter = int(finite.max(initial=0))
    return CommGraph(adj, labels.astype(np.int64), int(n_comp), diameter)


# ---------------------------------------------------------------------- one auction
@dataclass(frozen=True, eq=False)
class _Auction:
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
    converged, timed_out : bool
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
    converged: bool
    timed_out: bool


@dataclass(frozen=True, eq=False)
class CBBAResult:
    """What :meth:`CBBAScheduler.run` found.

    Attributes
    ----------
    routes : dict of int -> list of int
        Agent row -> task rows in flying order, after cross-component conflicts were resolved.
    service : dict of int -> str
        Agent row -> ``"dump"`` or ``"sense"`` for every routed agent.
    stages : tuple of StageResult
        The dump auction, then the sense auction.
    comm : CommGraph
    objective : float
        Sum of the winning bids of the tasks kept in the plan.
    conflicts_resolved : int
        (task, service) pairs held by more than one agent at the end, given to the highest bid.
    """

    routes: dict[int, list[int]]
    service: dict[int, str]
    stages: tuple[StageResult, ...]
    comm: CommGraph
    objective: float
    conflicts_resolved: int

    @property
    def rounds(self) -> int:
        """Consensus rounds over both auctions."""
        return sum(s.rounds for s in self.stages)

    @property
    def messages(self) -> int:
        """Messages sent over both auctions."""
        return sum(s.messages for s in self.stages)

    @property
    def converged(self) -> bool:
        """Both auctions converged."""
        return all(s.converged for s in self.stages)

    @property
    def timed_out(self) -> bool:
        """The time limit stopped an auction."""
        return any(s.timed_out for s in self.stages)


def _insertion_scores(
    auc: _Auction, i: int, path: list[int], cand: np.ndarray
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
    if n:
        feasible[:, auc.exclusive[cand]] = False  # an exclusive item only on an empty path
        if auc.exclusive[path[0]]:
            feasible[:] = False  # nothing joins an exclusive item
    score = np.where(feasible, score, -np.inf)
    where = np.argmax(score, axis=0)
    return score[where, np.arange(cand.size)], where


class _Agents:
    """The state of every simulated agent in one auction."""

    def __init__(self, auc: _Auction) -> None:
        a, m = auc.value.shape
        self.auc = auc
        self.y = np.zeros((a, m))
        self.z = np.full((a, m), _NONE, dtype=np.int64)
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
            score, where = _insertion_scores(auc, i, path, cand)
            bid = np.minimum(score, bids[-1]) if bids else score
            y, z = self.y[i, cand], self.z[i, cand]
            zz = np.where(z == _NONE, self.n_agents, z)
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
    def consensus(self, slots: list[tuple[np.ndarray, np.ndarray]], t: int) -> np.ndarray:
        """One synchronous round of message passing (Table I of the paper); returns the (A,) rows
        whose ``y`` or ``z`` changed."""
        a = self.n_agents
        s0 = self.s.copy()
        cols = np.flatnonzero((self.z != _NONE).any(axis=0))
        if cols.size == 0:
            for rec, snd in slots:
                self.s[rec] = np.maximum(self.s[rec], s0[snd])
                self.s[rec, snd] = t
            return np.zeros(a, dtype=bool)
        y0, z0 = self.y[:, cols], self.z[:, cols]  # snapshot: what each agent sends
        y, z = y0.copy(), z0.copy()
        s = self.s
        for rec, snd in slots:
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
                k_none, i_none = zk == _NONE, zi == _NONE
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
                z[i, cc] = np.where(update, zk, np.where(reset, _NONE, zi))
            s[rec] = np.maximum(s[rec], s0[snd])
            s[rec, snd] = t
        changed = (y != y0).any(axis=1) | (z != z0).any(axis=1)
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
            self.z[i, later] = _NONE
            gone = set(bundle[first:])
            self.paths[i] = [j for j in self.paths[i] if j not in gone]
            del bundle[first:]
            del self.bids[i][first:]
            changed[i] = True
        return changed


def _run_auction(
    name: str,
    auc: _Auction,
    items: np.ndarray,
    comm: CommGraph,
    *,
    max_rounds: int,
    deadline: float | None,
) -> StageResult:
    """Alternate bundle construction and consensus until nothing changes for 2 * diameter
    rounds, ``max_rounds`` or the deadline."""
    agents = _Agents(auc)
    bidders = auc.eligible.any(axis=1)
    slots = comm.slots()
    per_round = comm.messages_per_round
    need = max(2 * comm.diameter, 1)
    dirty = bidders.copy()
    stable = rounds = messages = 0
    converged = timed_out = False
    while rounds < max_rounds:
        rounds += 1
        changed = False
        for i in np.flatnonzero(dirty & bidders):
            changed |= agents.build(int(i))
        dirty[:] = False
        if per_round:
            messages += per_round
            moved = agents.consensus(slots, rounds)
            released = agents.release()
            changed |= bool(moved.any() or released.any())
            dirty |= moved | released
        stable = 0 if changed else stable + 1
        if stable >= need:
            converged = True
            break
        if deadline is not None and time.perf_counter() > deadline:
            timed_out = True
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
        converged=converged,
        timed_out=timed_out,
    )


# ---------------------------------------------------------------------- the scheduler
class CBBAScheduler:
    """Decentralised consensus-based bundle auction (see the module docstring).

    Parameters
    ----------
    bundle_length : int
        Most tasks an agent bids on per replan (``L`` in the paper); an action agent also no
        more than its tank.
    half_life_s : float
        Time discount: a task reached ``t`` seconds from now is worth ``2 ** (-t / half_life_s)``
        of its value.
    fresh_s : float
        A fire sensed within this many seconds counts as fresh; staler fires are worth less to
        dump on (``exp(-(staleness - fresh_s) / fresh_s)``, as greedy) and more to watch.
    watch_weight : float
        Value of watching a fire, relative to its task value (plus the top search-block value for
        the lead tile of a fought fire; see the module docstring).
    watch_altitude, search_altitude : float
        Altitude (m) of camera agents whose route ends with a watch / only covers search blocks
        (clipped to their bounds).
    max_rounds : int
        Cap on the rounds of each auction.

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(3, 12, np.random.default_rng(1))
    >>> res = CBBAScheduler().run(g)
    >>> res.converged, res.conflicts_resolved
    (True, 0)
    """

    name = "cbba"

    def __init__(
        self,
        bundle_length: int = 3,
        half_life_s: float = 2.0,
        fresh_s: float = 5.0,
        watch_weight: float = 2.0,
        watch_altitude: float = 35.0,
        search_altitude: float = 70.0,
        max_rounds: int = 500,
    ) -> None:
        if int(bundle_length) < 1:
            raise ValueError(f"bundle_length must be >= 1, got {bundle_length!r}")
        if not float(half_life_s) > 0:
            raise ValueError(f"half_life_s must be > 0, got {half_life_s!r}")
        if int(max_rounds) < 1:
            raise ValueError(f"max_rounds must be >= 1, got {max_rounds!r}")
        self.bundle_length = int(bundle_length)
        self.half_life_s = float(half_life_s)
        self.fresh_s = float(fresh_s)
        self.watch_weight = float(watch_weight)
        self.watch_altitude = float(watch_altitude)
        self.search_altitude = float(search_altitude)
        self.max_rounds = int(max_rounds)

    # ------------------------------------------------------------------ main
    def plan(self, graph: TaskGraph, *, time_limit=None, rng=None) -> Plan:
        """Run both auctions on ``graph`` and return the assembled plan (``rng`` is unused:
        CBBA breaks ties by agent index)."""
        res = self.run(graph, time_limit=time_limit)
        routes: dict[str, tuple[str, ...]] = {}
        alts: dict[str, float] = {}
        for i, tasks in res.routes.items():
            if not tasks:
                continue
            agent = graph.agent_ids[i]
            routes[agent] = tuple(graph.task_ids[k] for k in tasks)
            if res.service[i] == "sense":
                watch = graph.task_kind[tasks[-1]] == TaskKind.FIRE
                z = self.watch_altitude if watch else self.search_altitude
                alts[agent] = graph.clip_altitude(i, z)
        comm = res.comm
        size = {
            "agents": graph.n_agents,
            "tasks": graph.n_tasks,
            "rounds": res.rounds,
            "messages": res.messages,
            "converged": res.converged,
            "components": comm.n_components,
            "diameter": comm.diameter,
            "conflicts_resolved": res.conflicts_resolved,
        }
        message = (
            f"{res.rounds} rounds, {res.messages} messages, {comm.n_components} component(s), "
            + ("converged" if res.converged else "not converged")
            + (f", {res.conflicts_resolved} conflicts resolved" if res.conflicts_resolved else "")
        )
        stats = SolveStats(
            status="time_limit" if res.timed_out else "heuristic",
            objective=res.objective,
            size=size,
            message=message,
        )
        return Plan(routes=routes, altitudes=alts, stats=stats)

    def run(self, graph: TaskGraph, *, time_limit: float | None = None) -> CBBAResult:
        """Run the dump auction, then the sense auction, and assemble conflict-free routes.

        Parameters
        ----------
        graph : TaskGraph
        time_limit : float, optional
            Seconds for both auctions together.
        """
        deadline = None if time_limit is None else time.perf_counter() + float(time_limit)
        comm = communication_graph(graph.agent_pos, graph.comm_range)
        a = graph.n_agents
        forced = graph.agent_mode == Mode.RETURNING
        free = graph.agent_mode != Mode.HOMING
        start = graph.agent_start_pos
        budget = graph.agent_budget_px
        d_start = graph.start_task_distance
        trip = graph.in_round_trip
        rate = math.log(2.0) / self.half_life_s
        fires = graph.fire_tasks
        stale = graph.task_staleness
        fresh = np.where(
            stale <= self.fresh_s, 1.0, np.exp(-(stale - self.fresh_s) / max(self.fresh_s, 1e-9))
        )

        # 1. dump auction: action / hybrid agents with water -> fire tasks
        tank = np.where(forced, graph.agent_tank_capacity, graph.agent_tank)
        dumpers = free & graph.agent_can_act & (tank > 0)
        dump_value = np.broadcast_to(graph.task_value[fires] * fresh[fires], (a, fires.size))
        dump = _Auction(
            value=np.ascontiguousarray(dump_value),
            eligible=dumpers[:, None] & trip[:, fires] & (dump_value > 0),
            exclusive=np.zeros(fires.size, dtype=bool),
            limit=np.minimum(tank, self.bundle_length),
            item_pos=graph.task_pos[fires],
            d_start=d_start[:, fires],
            d_home=graph.task_home_distance[:, fires],
            start=start,
            home=graph.agent_home,
            budget=budget,
            speed=graph.agent_speed,
            rate=rate,
        )
        s1 = _run_auction("dump", dump, fires, comm, max_rounds=self.max_rounds, deadline=deadline)

        # 2. sense auction: camera agents without a dump -> watch a fire / cover a search block
        has_dump = np.array([bool(p) for p in s1.paths], dtype=bool)
        sensors = free & graph.agent_can_sense & ~has_dump
        is_fire = graph.task_kind == TaskKind.FIRE
        value = np.broadcast_to(np.where(is_fire, 0.0, graph.task_value), (a, graph.n_tasks)).copy()
        if fires.size and a:
            near = d_start[:, fires]  # px from each dumper's start to each fire
            value[:, fires] = self._watch_values(graph, s1.winners, near, fresh[fires])
        sense = _Auction(
            value=value,
            eligible=sensors[:, None] & trip & (value > 0),
            exclusive=is_fire,
            limit=np.full(a, self.bundle_length),
            item_pos=graph.task_pos,
            d_start=d_start,
            d_home=graph.task_home_distance,
            start=start,
            home=graph.agent_home,
            budget=budget,
            speed=graph.agent_speed,
            rate=rate,
        )
        s2 = _run_auction(
            "sense",
            sense,
            np.arange(graph.n_tasks),
            comm,
            max_rounds=self.max_rounds,
            deadline=None if deadline is None else max(deadline, time.perf_counter()),
        )

        # 3. assembly: one holder per (task, service), the highest bid
        routes: dict[int, list[int]] = {}
        service: dict[int, str] = {}
        objective = 0.0
        conflicts = 0
        for stage in (s1, s2):
            keep, n_conf, gained = _resolve(stage)
            conflicts += n_conf
            objective += gained
            for i, path in enumerate(stage.paths):
                kept = [stage.items[j] for j in path if keep.get(j) == i]
                if kept:
                    routes[i] = [int(k) for k in kept]
                    service[i] = stage.name
        return CBBAResult(
            routes=routes,
            service=service,
            stages=(s1, s2),
            comm=comm,
            objective=float(objective),
            conflicts_resolved=conflicts,
        )

    def _watch_values(
        self, graph: TaskGraph, winner: np.ndarray, reach: np.ndarray, fresh: np.ndarray
    ) -> np.ndarray:
        """(A, F) value of watching each fire task to each agent, from its dump-auction winners.

        A fire that an action-only agent will dump on is *fought*; the fought tile of each
        connected fire closest to the start of its dumper (``reach``: (A, F) px from each agent's
        start; ties: lowest index) *leads* it: where the first dump of the fight will most likely
        be. Watching a lead is worth
        ``watch_weight * (top search value + fire value)``, so one camera per fought fire
        supports the fight before it goes searching (greedy's rule); another fought tile is worth
        ``watch_weight * value``, an unfought one ``watch_weight * value * (1 - freshness)``.
        """
        fires = graph.fire_tasks
        val = graph.task_value[fires]
        fought = (winner != _NONE) & ~graph.agent_can_sense[np.maximum(winner, 0)]
        # order fires by (cluster, -value, index); a lead is the first fought fire of its cluster
        # per agent row: fires by (cluster, dumper distance, index); a lead is the first fought
        cluster = np.broadcast_to(graph.task_cluster[fires], winner.shape)
        index = np.broadcast_to(np.arange(fires.size), winner.shape)
        dist = reach[np.maximum(winner, 0), np.arange(fires.size)]
        order = np.lexsort((index, np.where(fought, dist, np.inf), cluster), axis=-1)
        rows = np.arange(winner.shape[0])[:, None]
        cl = cluster[rows, order]
        first = np.r_[True, cl[0, 1:] != cl[0, :-1]]
        f = fought[rows, order].astype(np.int64)
        csum = np.cumsum(f, axis=1)
        seg_start = np.flatnonzero(first)
        before = (csum - f)[:, seg_start]  # fought count before each cluster's segment
        seg = np.cumsum(first) - 1
        lead_sorted = (f == 1) & (csum - before[:, seg] == 1)
        lead = np.empty_like(lead_sorted)
        lead[rows, order] = lead_sorted
        search = graph.search_tasks
        top = float(graph.task_value[search].max()) if search.size else 0.0
        w = self.watch_weight
        return np.where(lead, w * (top + val), np.where(fought, w * val, w * val * (1.0 - fresh)))


def _resolve(stage: StageResult) -> tuple[dict[int, int], int, float]:
    """Item -> the agent that keeps it (highest own bid, ties to the lower index), the number of
    items held by more than one agent, and the sum of the kept bids."""
    best: dict[int, tuple[float, int]] = {}
    held: dict[int, int] = {}
    for i, (bundle, bids) in enumerate(zip(stage.bundles, stage.bundle_bids, strict=True)):
        for j, b in zip(bundle, bids, strict=True):
            held[j] = held.get(j, 0) + 1
            cur = best.get(j)
            if cur is None or b > cur[0]:
                best[j] = (b, i)
    conflicts = sum(1 for c in held.values() if c > 1)
    return {j: i for j, (_, i) in best.items()}, conflicts, sum(b for b, _ in best.values())
