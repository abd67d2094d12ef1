"""Actions of the task-level environment: to a :class:`fcplan.plan.Plan`, and back from one.

Agent ``i``'s action ``a`` in ``0..k`` means: ``a < k`` fly to the task in candidate slot ``a``;
``a == k`` is the **no-op**: the plan does not mention the agent, so it *holds its course*
(keeps flying its current route, keeps hovering, keeps going home; the 3-second rule and the
battery and tank rules still apply as in any episode).

Conflicts
    At most one agent **per role** (perception, action, hybrid) may take a task in a step, so a
    perception agent can watch the fire an action agent is sent to, but two action agents never
    waste two dumps on one tile. When several agents of one role pick the same task, the one that
    gets there first (smallest flight time from where its route starts; ties: lower agent row)
    keeps it and the others get the no-op. The losers are reported (``infos[agent]["conflict"]``).

Illegal actions
    A masked-out slot (padding) or an out-of-range action is the no-op when
    ``illegal_action="noop"`` (reported as ``infos[agent]["illegal"]``) and raises
    :class:`fcplan.env.EnvError` when ``illegal_action="raise"``.

Altitude
    A perception-only agent sent to a fire watches it at ``watch_altitude`` (low: high sensing
    confidence), sent to a search block it flies at ``search_altitude`` (a wide view). A hybrid
    with water sent to a fire dumps on it from ``dump_altitude``: in ``task_v1`` (the default)
    it is None, the rule of every built-in scheduler
    (:meth:`fcplan.taskgraph.TaskGraph.dump_altitude`: the top of its bounds, the widest dump);
    in ``task_v0`` it is ``"watch"``, ``watch_altitude``. A hybrid flies at ``search_altitude`` over blocks. All are clipped to the
    agent's bounds; action-only agents fly at their fixed altitude.

Plans to actions (:func:`plan_to_actions`, used by the demonstrations)
    The first task of each agent's route becomes the slot that holds it. A task outside the
    agent's ``k`` candidates becomes the legal candidate of the same kind (fire/search) nearest to
    it, or the no-op if the agent has none (counted as ``outside_top_k``). An agent the plan does
    not mention, with an empty route or sent home, gets the no-op (``home`` counted apart).

Examples
--------
>>> import numpy as np
>>> from fcplan.taskgraph import synthetic_task_graph
>>> from fcplan.env.task_candidates import rank_candidates
>>> g = synthetic_task_graph(3, 10, np.random.default_rng(0))
>>> c = rank_candidates(g, 4)
>>> noop = np.full(3, 4)
>>> rows, illegal, conflict = decode_actions(g, c, noop)
>>> rows.tolist(), int(illegal.sum()), int(conflict.sum())
([-1, -1, -1], 0, 0)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from fcplan.env.task_candidates import Candidates, _as_list
from fcplan.errors import EnvError
from fcplan.plan import Plan
from fcplan.settings import MAX_ALTITUDE_M, SettingError, altitude_setting
from fcplan.taskgraph import TaskGraph, TaskKind
from fcplan.team import Command

__all__ = [
    "decode_actions",
    "actions_plan",
    "actions_commands",
    "rows_commands",
    "plan_to_actions",
    "MappingCounts",
    "altitude_option",
    "resolve_dump_altitude",
]

_FIRE = int(TaskKind.FIRE)


def decode_actions(
    graph: TaskGraph, cand: Candidates, actions: np.ndarray, *, illegal: str = "noop"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Chosen task rows per agent after masking and conflict resolution.

    Parameters
    ----------
    graph, cand
        The step's graph and candidates.
    actions : ndarray, (A,) int
        One action per agent row (``k`` = no-op).
    illegal : {"noop", "raise"}

    Returns
    -------
    rows : ndarray, (A,) int64
        Task row per agent, ``-1`` for the no-op.
    illegal, conflict : ndarray, (A,) bool
        Agents whose action was illegal / lost a conflict.
    """
    n_a, k = cand.rows.shape
    if type(actions) is list and len(actions) == n_a and all(type(x) is int for x in actions):
        a = actions  # the environment's own list of Python ints
    else:
        a = np.asarray(actions, dtype=np.int64).reshape(n_a).tolist()
    # a handful of agents: plain Python over the (A,) actions beats a dozen numpy calls
    cand_rows, valid = cand.rows.tolist(), cand.valid.tolist()
    out: list[int] = []
    bad_l: list[bool] = []
    for i, x in enumerate(a):
        r = cand_rows[i][x] if 0 <= x < k and valid[i][x] else -1
        out.append(r)
        bad_l.append(r < 0 and x != k)
    bad = np.array(bad_l, dtype=bool)
    if illegal == "raise" and True in bad_l:
        from fcplan.errors import EnvError

        i = bad_l.index(True)
        legal = np.flatnonzero(np.r_[cand.valid[i], True]).tolist()
        raise EnvError(
            f"agent {graph.agent_ids[i]}: action {int(a[i])} is illegal (legal now: {legal}; "
            f"{k} is the no-op)"
        )
    rows = np.array(out, dtype=np.int64)
    conflict = np.zeros(n_a, dtype=bool)
    sent = [i for i, r in enumerate(out) if r >= 0]
    if len(sent) > 1:
        role = _as_list(graph, "agent_role")
        keys = [out[i] * 8 + role[i] for i in sent]
        if len(set(keys)) < len(keys):  # rare: resolve by arrival time
            chosen = np.array(sent)
            key = np.array(keys, dtype=np.int64)
            eta = cand.start_distance[chosen, rows[chosen]] / graph.agent_speed[chosen]
            order = np.lexsort((chosen, eta, key))
            ks = key[order]
            losers = chosen[order][np.r_[False, ks[1:] == ks[:-1]]]
            rows[losers] = -1
            conflict[losers] = True
    return rows, bad, conflict


def actions_plan(
    graph: TaskGraph,
    rows: np.ndarray,
    *,
    watch_altitude: float = 35.0,
    search_altitude: float = 70.0,
    dump_altitude: float | None | str = None,
) -> Plan:
    """A one-task-per-agent :class:`Plan` from chosen task rows (``-1``: not mentioned); a
    hybrid with water sent to a fire at ``dump_altitude`` (``"watch"``: ``watch_altitude``;
    None: the top of its bounds)."""
    routes: dict[str, tuple[str, ...]] = {}
    alts: dict[str, float] = {}
    ids, tids = graph.agent_ids, graph.task_ids
    rows_l = rows.tolist()
    for i in np.flatnonzero(rows >= 0).tolist():
        routes[ids[i]] = (tids[rows_l[i]],)
    dump = resolve_dump_altitude(dump_altitude, watch_altitude)
    for i, z in _altitudes(graph, rows_l, watch_altitude, search_altitude, dump).items():
        alts[ids[i]] = z
    return Plan(routes=routes, altitudes=alts)


def altitude_option(name: str, value: Any, *, named: str = "") -> float:
    """An altitude option of the task env as a float in the schedulers' range,
    (0, MAX_ALTITUDE_M] m (:func:`fcplan.settings.altitude_setting`); anything else is an
    :class:`~fcplan.errors.EnvError` naming the option (``named``: the other values it takes).

    Examples
    --------
    >>> altitude_option("watch_altitude", 35)
    35.0
    """
    try:
        return altitude_setting(name, value)
    except SettingError:
        raise EnvError(
            f"{name}: must be {named}a number of metres in (0, {MAX_ALTITUDE_M:g}] (got {value!r})"
        ) from None


def resolve_dump_altitude(value: Any, watch_altitude: float) -> float | None:
    """The ``dump_altitude`` option resolved (the one rule of the env and these functions):
    None (the top of each hybrid's bounds) stays None, ``"watch"`` is ``watch_altitude``
    (``task_v0``'s rule), a number is an altitude (:func:`altitude_option`).

    Examples
    --------
    >>> resolve_dump_altitude("watch", 35.0), resolve_dump_altitude(None, 35.0)
    (35.0, None)
    """
    if value is None:
        return None
    if isinstance(value, str) and value == "watch":
        return float(watch_altitude)
    return altitude_option("dump_altitude", value, named="'watch', None or ")


def _altitudes(
    graph: TaskGraph,
    rows: list[int],
    watch_altitude: float,
    search_altitude: float,
    dump_altitude: float | None,
) -> dict[int, float]:
    """Agent row -> commanded altitude of every camera agent sent to a task (the module's rule)."""
    sense = _as_list(graph, "agent_can_sense")
    act, tank = _as_list(graph, "agent_can_act"), graph.agent_tank.tolist()
    kind = graph.task_kind
    out: dict[int, float] = {}
    for i, t in enumerate(rows):
        if t < 0 or not sense[i]:
            continue
        if kind[t] != _FIRE:
            out[i] = graph.clip_altitude(i, search_altitude)
        elif act[i] and tank[i] > 0:
            out[i] = graph.dump_altitude(i, dump_altitude)
        else:
            out[i] = graph.clip_altitude(i, watch_altitude)
    return out


def actions_commands(
    graph: TaskGraph,
    rows: np.ndarray,
    *,
    watch_altitude: float = 35.0,
    search_altitude: float = 70.0,
    dump_altitude: float | None | str = None,
) -> dict[str, Command]:
    """``plan_commands(actions_plan(graph, rows, ...), graph)`` built directly from the rows
    (the environment's per-step path: no task-id lookups).

    Examples
    --------
    >>> import numpy as np
    >>> from fcplan.plan import plan_commands
    >>> from fcplan.taskgraph import synthetic_task_graph
    >>> g = synthetic_task_graph(3, 10, np.random.default_rng(0))
    >>> rows = np.array([4, -1, 2])
    >>> actions_commands(g, rows) == plan_commands(actions_plan(g, rows), g)
    True
    """
    dump = resolve_dump_altitude(dump_altitude, watch_altitude)
    return rows_commands(graph, rows.tolist(), watch_altitude, search_altitude, dump)[0]


def rows_commands(
    graph: TaskGraph,
    rows: list[int],
    watch_altitude: float,
    search_altitude: float,
    dump_altitude: float | None,
) -> tuple[dict[str, Command], list[list[float]]]:
    """:func:`actions_commands` from the rows as a list of ints (``dump_altitude`` resolved:
    a number or None); also returns the ``[x, y]`` task position of each agent sent somewhere
    (agent row order)."""
    sel = [i for i, t in enumerate(rows) if t >= 0]
    if not sel:
        return {}, []
    t = [rows[i] for i in sel]
    pos = graph.task_pos[t].tolist()
    alts = _altitudes(graph, rows, watch_altitude, search_altitude, dump_altitude)
    ids = graph.agent_ids
    out: dict[str, Command] = {}
    for j, i in enumerate(sel):
        x, y = pos[j]
        out[ids[i]] = Command(route=((x, y),), patrol=False, altitude=alts.get(i))
    return out, pos


class MappingCounts(dict):
    """Counts of how a scheduler's plans mapped onto actions: ``exact`` (first task is a
    candidate), ``outside_top_k`` (replaced by the nearest candidate of its kind or the no-op),
    ``noop`` (agent not mentioned or empty route), ``home`` (sent home: no-op)."""

    def __init__(self) -> None:
        super().__init__(exact=0, outside_top_k=0, noop=0, home=0)

    def add(self, other: Mapping[str, int]) -> None:
        """Add ``other``'s counts to these (an episode's into a dataset's, a shard's into the
        caller's).

        >>> c = MappingCounts()
        >>> c.add({"exact": 2, "noop": 1})
        >>> c["exact"], c["noop"], c["home"]
        (2, 1, 0)
        """
        for name, n in other.items():
            self[name] += n


def plan_to_actions(
    plan: Plan, graph: TaskGraph, cand: Candidates, counts: MappingCounts | None = None
) -> np.ndarray:
    """(A,) int64 env actions for a scheduler's ``plan`` (module docstring: "Plans to actions")."""
    n_a, k = cand.rows.shape
    out = np.full(n_a, k, dtype=np.int64)
    counts = MappingCounts() if counts is None else counts
    tidx = graph.task_index
    routes: Mapping[str, tuple[str, ...]] = plan.routes
    for i, agent in enumerate(graph.agent_ids):
        route = routes.get(agent)
        if agent in plan.home:
            counts["home"] += 1
            continue
        if not route:
            counts["noop"] += 1
            continue
        t = tidx[route[0]]
        hit = np.flatnonzero(cand.rows[i] == t)
        if hit.size:
            out[i] = int(hit[0])
            counts["exact"] += 1
            continue
        counts["outside_top_k"] += 1
        same = cand.valid[i] & (graph.task_kind[np.maximum(cand.rows[i], 0)] == graph.task_kind[t])
        if same.any():
            p = graph.task_pos[np.maximum(cand.rows[i], 0)]
            d = np.hypot(*(p - graph.task_pos[t]).T)
            out[i] = int(np.argmin(np.where(same, d, np.inf)))
    return out
