"""Who can talk to whom: the communication graph of a CBBA auction.

Agents ``i`` and ``k`` are neighbours when their positions at the replan are at most
``comm_range`` px apart (None: everyone talks to everyone); the graph stays fixed during the
auctions. Each round every agent broadcasts to all its neighbours, so a round sends
:attr:`CommGraph.messages_per_round` messages (the sum of the degrees, relays included), and
news crosses a connected component in at most ``diameter`` rounds (its largest hop distance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, shortest_path

__all__ = ["CommGraph", "communication_graph", "graph_from_adjacency"]


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
        if n == 0:
            return CommGraph(adj, np.zeros(0, dtype=np.int64), 0, 0)
        return CommGraph(adj, np.zeros(n, dtype=np.int64), 1, 1 if n > 1 else 0)
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    return graph_from_adjacency((d <= float(comm_range)) & ~np.eye(n, dtype=bool))


def graph_from_adjacency(adjacency: np.ndarray) -> CommGraph:
    """The communication graph with the given (A, A) adjacency (made symmetric, no self-loops).

    Examples
    --------
    >>> import numpy as np
    >>> line = np.eye(4, k=1, dtype=bool)  # 0 - 1 - 2 - 3
    >>> cg = graph_from_adjacency(line)
    >>> cg.n_components, cg.diameter, cg.messages_per_round
    (1, 3, 6)
    """
    adj = np.asarray(adjacency, dtype=bool)
    adj = (adj | adj.T) & ~np.eye(len(adj), dtype=bool)
    n = len(adj)
    if n == 0:
        return CommGraph(adj, np.zeros(0, dtype=np.int64), 0, 0)
    n_comp, labels = connected_components(csr_matrix(adj), directed=False)
    hops = shortest_path(csr_matrix(adj), directed=False, unweighted=True)
    diameter = int(hops[np.isfinite(hops)].max(initial=0))
    return CommGraph(adj, labels.astype(np.int64), int(n_comp), diameter)
