"""fcplan's CBBA against an independent implementation (zehuilu/CBBA-Python), sequential greedy
and exact optima, on the static instances of ``tests/solvers/data/cbba/`` (see its README)."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers.cbba.comms import graph_from_adjacency
from solvers.cbba.static import StaticInstance, StaticResult, solve_static

DATA = Path(__file__).parent / "data" / "cbba" / "reference_cases.json"
CASES = json.loads(DATA.read_text())["cases"]
NAMES = [c["name"] for c in CASES]
BY_NAME = {c["name"]: c for c in CASES}
#: Small enough for brute force.
SMALL = [c["name"] for c in CASES if len(c["tasks"]["x"]) <= 7 and len(c["agents"]["x"]) <= 4]
#: Cases where inserting anywhere ends below the reference's append-only assignment (see the
#: README): sequential greedy with insertion lands on the same lower score, so the greedy rule
#: decides it, not the consensus.
ANYWHERE_BELOW_REFERENCE = {"full-1type-8x30-L3": 0.9996}


def instance(name: str) -> StaticInstance:
    return StaticInstance.from_dict(BY_NAME[name])


def model_score(inst: StaticInstance, agent: int, path: list[int]) -> float:
    """``S_i`` the slow obvious way: leg by leg, in plain floats."""
    t, here, total = 0.0, inst.agent_pos[agent], 0.0
    for j in path:
        t += math.dist(here, inst.task_pos[j]) / inst.agent_speed[agent]
        here = inst.task_pos[j]
        total += inst.task_value[j] * math.exp(-inst.discount * t)
    return total


def sequential_greedy(inst: StaticInstance, append: bool) -> list[list[int]]:
    """Central sequential greedy (SGA): repeatedly give the (agent, task, position) with the
    largest marginal score to that agent, until nothing gains or every bundle is full."""
    paths: list[list[int]] = [[] for _ in range(inst.n_agents)]
    free = set(range(inst.n_tasks))
    while True:
        best: tuple[float, tuple[int, list[int], int] | None] = (0.0, None)
        for i in range(inst.n_agents):
            if len(paths[i]) >= inst.bundle_length:
                continue
            base = model_score(inst, i, paths[i])
            for j in sorted(free):
                if not inst.compatible[i, j]:
                    continue
                slots = [len(paths[i])] if append else range(len(paths[i]) + 1)
                for q in slots:
                    new = paths[i][:q] + [j] + paths[i][q:]
                    gain = model_score(inst, i, new) - base
                    if gain > best[0]:
                        best = (gain, (i, new, j))
        if best[1] is None:
            return paths
        i, new, j = best[1]
        paths[i] = new
        free.discard(j)


def optimum(inst: StaticInstance) -> float:
    """Exact best team score: every agent's best ordered path over every task subset of at
    most ``L``, combined over agents by dynamic programming on the tasks used."""
    per_agent = []
    for i in range(inst.n_agents):
        ok = [j for j in range(inst.n_tasks) if inst.compatible[i, j]]
        best = {0: 0.0}
        for r in range(1, min(inst.bundle_length, len(ok)) + 1):
            for combo in itertools.combinations(ok, r):
                mask = sum(1 << j for j in combo)
                best[mask] = max(
                    model_score(inst, i, list(p)) for p in itertools.permutations(combo)
                )
        per_agent.append(best)

    @cache
    def f(i: int, used: int) -> float:
        if i == inst.n_agents:
            return 0.0
        return max(v + f(i + 1, used | m) for m, v in per_agent[i].items() if not m & used)

    return f(0, 0)


def check_assignment(inst: StaticInstance, res: StaticResult) -> None:
    """Converged, conflict-free, bundles within ``L``, compatible, scores as the model's."""
    assert res.stopped_by == "converged" and res.conflicts == 0 and res.completed == 0
    flat = [j for p in res.paths for j in p]
    assert len(flat) == len(set(flat))
    for i, path in enumerate(res.paths):
        assert len(path) <= inst.bundle_length
        assert all(inst.compatible[i, j] for j in path)
        assert res.agent_scores[i] == pytest.approx(model_score(inst, i, path), rel=1e-12)


# ---------------------------------------------------------------------- the data
def test_reference_scores_are_this_model():
    """The reference's reported scores are the model's path scores of its paths (so both codes
    score the same thing), its paths are conflict-free, and every case is well formed."""
    assert len(CASES) >= 60
    for case in CASES:
        inst = StaticInstance.from_dict(case)
        ref = case["reference"]
        assert len(ref["paths"]) == inst.n_agents
        for i, path in enumerate(ref["paths"]):
            assert ref["agent_scores"][i] == pytest.approx(model_score(inst, i, path), rel=1e-9)
        flat = [j for p in ref["paths"] for j in p]
        assert len(flat) == len(set(flat))
        if inst.adjacency is not None:
            assert graph_from_adjacency(inst.adjacency).n_components == 1
        assert StaticInstance.from_dict(inst.to_dict()).to_dict() == inst.to_dict()


# ---------------------------------------------------------------------- the reference
@pytest.mark.parametrize("name", NAMES)
def test_append_rule_reproduces_the_reference(name):
    """With the reference's promised-time (append-only) rule, fcplan's CBBA gives every agent
    the same path and bundle as the reference, the same scores, and all agents end with the
    reference's winner vector; it stops changing no later than the reference (rounds aligned:
    fcplan's round ``r`` builds bundles then exchanges them, the reference's iteration ``r``
    exchanges, then builds), and it stops in no more rounds than the reference iterates."""
    inst, ref = instance(name), BY_NAME[name]["reference"]
    res = solve_static(inst, insertion="append")
    check_assignment(inst, res)
    assert res.paths == ref["paths"]
    assert res.bundles == ref["bundles"]
    assert res.agent_scores == pytest.approx(ref["agent_scores"], rel=1e-9)
    assert res.score == pytest.approx(ref["score"], rel=1e-9)
    assert (res.winners == np.array(ref["winners"])).all()
    assert res.last_change <= ref["last_change"]
    assert res.rounds <= ref["iterations"]


@pytest.mark.parametrize("name", NAMES)
def test_anywhere_rule_is_at_least_the_reference(name):
    """With fcplan's own rule (insert anywhere, warped bids) the assignment is conflict-free and
    converged, stops changing no later than the reference, and scores at least the reference's
    append-only assignment, except in the listed cases (within 0.1 %)."""
    inst, ref = instance(name), BY_NAME[name]["reference"]
    res = solve_static(inst, insertion="anywhere")
    check_assignment(inst, res)
    assert res.last_change <= ref["last_change"]
    assert res.rounds <= ref["iterations"]
    ratio = res.score / ref["score"]
    if name in ANYWHERE_BELOW_REFERENCE:  # still below (else drop it from the list), by < 0.1 %
        assert ratio == pytest.approx(ANYWHERE_BELOW_REFERENCE[name], abs=1e-4) and ratio < 1.0
    else:
        assert ratio >= 1.0 - 1e-12


# ---------------------------------------------------------------------- greedy and optimum
@pytest.mark.parametrize("name", NAMES)
def test_cbba_equals_sequential_greedy(name):
    """On every case, over every communication graph here, both rules end with the central
    sequential greedy assignment of the same rule (for the append rule, whose score is DMG,
    this is Choi, Brunet and How's theorem)."""
    inst = instance(name)
    for insertion in ("append", "anywhere"):
        res = solve_static(inst, insertion=insertion)
        assert res.paths == sequential_greedy(inst, append=insertion == "append"), insertion


@pytest.mark.parametrize("name", SMALL)
def test_small_cases_against_the_exact_optimum(name):
    """Brute force over every assignment and order: no rule scores above the optimum (the
    scores are achievable), and each reaches at least 89 % of it (measured minimum over these
    cases: append 89.3 %, anywhere 97.2 %; see the README)."""
    inst = instance(name)
    best = optimum(inst)
    assert BY_NAME[name]["reference"]["score"] <= best + 1e-9
    for insertion in ("append", "anywhere"):
        score = solve_static(inst, insertion=insertion).score
        assert 0.89 * best <= score <= best + 1e-9, insertion


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_agents=st.integers(1, 5),
    n_tasks=st.integers(0, 12),
    length=st.integers(1, 4),
    topology=st.sampled_from(["full", "line", "ring"]),
)
def test_append_rule_equals_greedy_on_random_instances(seed, n_agents, n_tasks, length, topology):
    """On random instances (up to 5 agents x 12 tasks, two types, full / line / ring graphs) the
    append rule converges to the sequential greedy assignment, conflict-free."""
    rng = np.random.default_rng(seed)
    inst = StaticInstance.random(rng, n_agents, n_tasks, bundle_length=length, n_types=2)
    if topology != "full":
        adj = np.eye(n_agents, k=1, dtype=bool)
        if topology == "ring" and n_agents > 2:
            adj[-1, 0] = True
        inst = dataclasses.replace(inst, adjacency=adj)
    res = solve_static(inst, insertion="append")
    check_assignment(inst, res)
    assert res.paths == sequential_greedy(inst, append=True)


def test_bad_instances_are_rejected():
    """A static instance with a non-positive speed, a negative value, a NaN position, a bad
    shape or an unknown insertion rule is refused with one line naming what is wrong."""
    good = BY_NAME[NAMES[0]]
    for path, bad in (
        (("agents", "speed"), [0.0] * len(good["agents"]["x"])),
        (("tasks", "value"), [-1.0] * len(good["tasks"]["x"])),
        (("tasks", "x"), [float("nan")] * len(good["tasks"]["x"])),
        (("agents", "type"), [0]),
    ):
        data = json.loads(json.dumps(good))
        data[path[0]][path[1]] = bad
        with pytest.raises(ValueError, match="static instance"):
            StaticInstance.from_dict(data)
    with pytest.raises(ValueError, match="insertion"):
        solve_static(instance(NAMES[0]), insertion="middle")
