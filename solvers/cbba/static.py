"""CBBA on a static assignment instance: the textbook model, to check fcplan's auction against
other implementations of the algorithm.

The model
---------
``A`` agents and ``M`` tasks in the plane. Agent ``i`` starts at ``p_i`` at time 0 and flies at
``v_i``; task ``j`` at ``q_j`` is worth ``c_j``; agent ``i`` may do task ``j`` when their types
match (``agent_type[i] == task_type[j]``). A path of agent ``i`` is an ordered list of at most
``L`` (``bundle_length``) tasks, flown in straight lines with no service time, no way home and no
battery, so its ``n``-th task is reached at

``t_n = (|p_i - q_{j_1}| + |q_{j_1} - q_{j_2}| + ... + |q_{j_{n-1}} - q_{j_n}|) / v_i``

and the path scores ``S_i = sum_n c_{j_n} exp(-lambda t_n)`` (``lambda``: ``discount``, 1/s). The
team score is ``sum_i S_i`` with every task in at most one path. Agents talk over a fixed
undirected graph (``adjacency``; None: everyone to everyone).

:func:`solve_static` runs the auction of :mod:`solvers.cbba.auction` on it, the same code as the
scheduler's dump auction (scores ``c_j exp(-lambda t)`` instead of ``value * 2 ** (-t / h)``, an
unlimited budget), with one of two insertion rules:

``"anywhere"``
    The scheduler's rule: a task may be inserted at any position of the path, its marginal score
    being its discounted value minus what the detour costs the tasks after it; bids are warped
    (non-increasing within a bundle) because this score is not always DMG.
``"append"``
    The promised-time rule of implementations that fix the arrival time of every task in a path
    and insert a task only where it breaks no promise: with no time windows and no service time,
    only at the end of the path (the detour of an insertion in the middle delays the next task,
    by the triangle inequality). The score is then DMG and the auction is plain CBBA (no warp).

With ``"append"`` and full communication CBBA provably converges to the sequential greedy
assignment (Choi, Brunet and How 2009, with DMG scores).

The JSON form
-------------
:meth:`StaticInstance.from_dict` / :meth:`StaticInstance.to_dict` (the format of the test data in
``tests/solvers/data/cbba/``):

=================  ===========================================================================
field              meaning
=================  ===========================================================================
``name``           case name
``discount``       ``lambda`` (1/s), >= 0
``bundle_length``  ``L``, >= 1
``agents``         ``{"x": [A], "y": [A], "speed": [A] (> 0), "type": [A] (int)}``
``tasks``          ``{"x": [M], "y": [M], "value": [M] (>= 0), "type": [M] (int)}``
``adjacency``      ``null`` (all-to-all) or an ``A x A`` 0/1 matrix (made symmetric)
=================  ===========================================================================

Examples
--------
>>> import numpy as np
>>> inst = StaticInstance.random(np.random.default_rng(0), n_agents=3, n_tasks=8)
>>> res = solve_static(inst, insertion="append")
>>> res.stopped_by, sorted(j for p in res.paths for j in p) == sorted(set(j for p in res.paths for j in p))
('converged', True)
>>> bool(np.isclose(res.score, sum(inst.path_score(i, p) for i, p in enumerate(res.paths))))
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from solvers.cbba.assembly import assemble
from solvers.cbba.auction import Auction, run_auction
from solvers.cbba.comms import CommGraph, communication_graph, graph_from_adjacency

__all__ = [
    "INSERTIONS",
    "StaticInstance",
    "StaticResult",
    "solve_static",
    "static_auction",
    "static_comm",
]

#: Insertion rules of :func:`solve_static`.
INSERTIONS = ("anywhere", "append")


def _array(name: str, value: Any, dtype: Any, shape: tuple[int, ...] | None = None) -> np.ndarray:
    out = np.array(value, dtype=dtype)
    if shape is not None and out.shape != shape:
        raise ValueError(f"static instance: {name} must have shape {shape}, got {out.shape}")
    if out.dtype.kind == "f" and not np.isfinite(out).all():
        raise ValueError(f"static instance: {name} must be finite")
    return out


@dataclass(frozen=True, eq=False)
class StaticInstance:
    """A static assignment instance (see the module docstring); arrays are checked and copied."""

    agent_pos: np.ndarray  # (A, 2) float64
    agent_speed: np.ndarray  # (A,) float64 > 0
    agent_type: np.ndarray  # (A,) int64
    task_pos: np.ndarray  # (M, 2) float64
    task_value: np.ndarray  # (M,) float64 >= 0
    task_type: np.ndarray  # (M,) int64
    discount: float  # lambda, 1/s
    bundle_length: int  # L
    adjacency: np.ndarray | None = None  # (A, A) bool, None: all-to-all
    name: str = ""

    def __post_init__(self) -> None:
        pos = _array("agent_pos", self.agent_pos, np.float64).reshape(-1, 2)
        a = len(pos)
        speed = _array("agent_speed", self.agent_speed, np.float64, (a,))
        task_pos = _array("task_pos", self.task_pos, np.float64).reshape(-1, 2)
        m = len(task_pos)
        value = _array("task_value", self.task_value, np.float64, (m,))
        if not (speed > 0).all() or not (value >= 0).all():
            raise ValueError("static instance: speeds must be > 0 and values >= 0")
        if not (math.isfinite(self.discount) and self.discount >= 0):
            raise ValueError(f"static instance: discount must be >= 0, got {self.discount!r}")
        if int(self.bundle_length) < 1:
            raise ValueError(
                f"static instance: bundle_length must be >= 1, got {self.bundle_length!r}"
            )
        fields = {
            "agent_pos": pos,
            "agent_speed": speed,
            "agent_type": _array("agent_type", self.agent_type, np.int64, (a,)),
            "task_pos": task_pos,
            "task_value": value,
            "task_type": _array("task_type", self.task_type, np.int64, (m,)),
            "discount": float(self.discount),
            "bundle_length": int(self.bundle_length),
        }
        if self.adjacency is not None:
            fields["adjacency"] = _array("adjacency", self.adjacency, bool, (a, a))
        for key, val in fields.items():
            object.__setattr__(self, key, val)

    @property
    def n_agents(self) -> int:
        """``A``."""
        return len(self.agent_pos)

    @property
    def n_tasks(self) -> int:
        """``M``."""
        return len(self.task_pos)

    @property
    def compatible(self) -> np.ndarray:
        """(A, M) bool: agent ``i`` may do task ``j``."""
        return self.agent_type[:, None] == self.task_type[None, :]

    def path_score(self, agent: int, path: list[int]) -> float:
        """``S_i`` of ``path`` (task indices in flying order) flown by agent row ``agent``."""
        if not path:
            return 0.0
        pts = np.vstack([self.agent_pos[agent], self.task_pos[path]])
        t = np.cumsum(np.hypot(*np.diff(pts, axis=0).T)) / self.agent_speed[agent]
        return float(np.sum(self.task_value[path] * np.exp(-self.discount * t)))

    # ------------------------------------------------------------------ JSON form
    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> StaticInstance:
        """An instance from its JSON form (see the module docstring)."""
        ag, tk = data["agents"], data["tasks"]
        adj = data.get("adjacency")
        return cls(
            agent_pos=np.stack([ag["x"], ag["y"]], axis=1) if ag["x"] else np.zeros((0, 2)),
            agent_speed=ag["speed"],
            agent_type=ag["type"],
            task_pos=np.stack([tk["x"], tk["y"]], axis=1) if tk["x"] else np.zeros((0, 2)),
            task_value=tk["value"],
            task_type=tk["type"],
            discount=data["discount"],
            bundle_length=data["bundle_length"],
            adjacency=None if adj is None else np.array(adj, dtype=bool),
            name=data.get("name", ""),
        )

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (see the module docstring)."""
        return {
            "name": self.name,
            "discount": self.discount,
            "bundle_length": self.bundle_length,
            "agents": {
                "x": self.agent_pos[:, 0].tolist(),
                "y": self.agent_pos[:, 1].tolist(),
                "speed": self.agent_speed.tolist(),
                "type": self.agent_type.tolist(),
            },
            "tasks": {
                "x": self.task_pos[:, 0].tolist(),
                "y": self.task_pos[:, 1].tolist(),
                "value": self.task_value.tolist(),
                "type": self.task_type.tolist(),
            },
            "adjacency": None if self.adjacency is None else self.adjacency.astype(int).tolist(),
        }

    @classmethod
    def random(
        cls,
        rng: np.random.Generator,
        n_agents: int,
        n_tasks: int,
        *,
        size: float = 100.0,
        bundle_length: int = 3,
        discount: float = 0.05,
        n_types: int = 1,
    ) -> StaticInstance:
        """Uniform positions on a ``size`` square, speeds 1..5, values 10..100, random types."""
        return cls(
            agent_pos=rng.uniform(0, size, (n_agents, 2)),
            agent_speed=rng.uniform(1.0, 5.0, n_agents),
            agent_type=rng.integers(0, n_types, n_agents),
            task_pos=rng.uniform(0, size, (n_tasks, 2)),
            task_value=rng.uniform(10.0, 100.0, n_tasks),
            task_type=rng.integers(0, n_types, n_tasks),
            discount=discount,
            bundle_length=bundle_length,
        )


@dataclass(frozen=True, eq=False)
class StaticResult:
    """What :func:`solve_static` found.

    Attributes
    ----------
    paths, bundles : list of list of int
        Per agent, its tasks in flying order / in the order it added them (conflict-free).
    winners : ndarray, (A, M) int
        Every agent's final winner vector (-1: none).
    agent_scores : list of float
        ``S_i`` of each path.
    rounds, last_change, messages : int
        Rounds run, the last round in which anything changed, messages sent.
    stopped_by : str
        ``converged``, ``max_rounds``.
    conflicts, completed : int
        Tasks held by several agents at the end, and agents completed greedily
        (:mod:`solvers.cbba.assembly`).
    """

    paths: list[list[int]]
    bundles: list[list[int]]
    winners: np.ndarray
    agent_scores: list[float]
    rounds: int
    last_change: int
    messages: int
    stopped_by: str
    conflicts: int
    completed: int

    @property
    def score(self) -> float:
        """Team score ``sum_i S_i``."""
        return float(sum(self.agent_scores))


def static_auction(inst: StaticInstance, insertion: str = "anywhere") -> Auction:
    """The :class:`~solvers.cbba.auction.Auction` that :func:`solve_static` runs on ``inst``."""
    if insertion not in INSERTIONS:
        raise ValueError(f"insertion must be one of {', '.join(INSERTIONS)}, got {insertion!r}")
    a, m = inst.n_agents, inst.n_tasks
    d = np.hypot(*(inst.agent_pos[:, None, :] - inst.task_pos[None, :, :]).transpose(2, 0, 1))
    value = np.broadcast_to(inst.task_value, (a, m)).copy()
    append = insertion == "append"
    return Auction(
        value=value,
        eligible=inst.compatible & (value > 0),
        exclusive=np.zeros(m, dtype=bool),
        limit=np.full(a, inst.bundle_length),
        item_pos=inst.task_pos,
        d_start=d,
        d_home=d,
        start=inst.agent_pos,
        home=inst.agent_pos,
        budget=np.full(a, np.inf),
        speed=inst.agent_speed,
        rate=inst.discount,
        append_only=append,
        warp=not append,
    )


def static_comm(inst: StaticInstance) -> CommGraph:
    """The communication graph of ``inst``."""
    if inst.adjacency is None:
        return communication_graph(inst.agent_pos, None)
    return graph_from_adjacency(inst.adjacency)


def solve_static(
    inst: StaticInstance, *, insertion: str = "anywhere", max_rounds: int = 1000
) -> StaticResult:
    """Run CBBA on ``inst`` with the ``insertion`` rule (see the module docstring)."""
    auc = static_auction(inst, insertion)
    stage = run_auction(
        "static", auc, np.arange(inst.n_tasks), static_comm(inst), max_rounds=max_rounds
    )
    asm = assemble(stage, auc)
    bundles = []
    for path, bundle in zip(asm.paths, stage.bundles, strict=True):
        held = [j for j in bundle if j in path]
        bundles.append(held + [j for j in path if j not in held])  # + completed greedily
    return StaticResult(
        paths=asm.paths,
        bundles=bundles,
        winners=stage.winners,
        agent_scores=[inst.path_score(i, p) for i, p in enumerate(asm.paths)],
        rounds=stage.rounds,
        last_change=stage.last_change,
        messages=stage.messages,
        stopped_by=stage.stopped_by,
        conflicts=asm.conflicts,
        completed=asm.completed,
    )
