"""Tests of fcplan.batch.team.BatchTeam's batched shortcuts: go_to is apply of one-point routes,
range_px is Team.range_px of every world."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.batch.team import BatchTeam
from fcplan.errors import PlanError
from fcplan.scenario import load_scenario
from fcplan.team import Command, Mode, Team

_ARRAYS = ("z_target", "routes", "route_len", "goal_index", "patrol", "hover_s", "mode",
           "has_goal", "goal", "pos", "z", "battery", "armed")  # fmt: skip


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), name=st.sampled_from(["1", "practice"]))
def test_go_to_equals_apply(seed, name):
    """Property: from random team states (every mode, patrols, longer routes, pending goals),
    go_to of random one-point routes with or without an altitude (NaN: none; out of bounds
    too) to distinct (world, agent) pairs writes exactly what apply of the same Commands
    writes, array for array, bit for bit."""
    rng = np.random.default_rng(seed)
    sc = load_scenario(name)
    n = 5
    fast, slow = BatchTeam(sc, n), BatchTeam(sc, n)
    for team in (fast, slow):
        team.reset_worlds(np.arange(n))
    r = np.random.default_rng(seed + 1)
    modes = r.choice([int(m) for m in Mode], size=(n, fast.n)).astype(np.int8)
    z_t = r.uniform(0, 150, (n, fast.n))
    patrol = r.random((n, fast.n)) < 0.3
    for team in (fast, slow):
        team.mode[...] = modes
        team.z_target[...] = z_t
        team.patrol[...] = patrol
        team.apply(0, {team.ids[0]: Command(route=((1.0, 2.0), (3.0, 4.0), (5.0, 6.0)))})
    pairs = [(b, i) for b in range(n) for i in range(fast.n) if rng.random() < 0.5]
    goals = rng.uniform(0, sc.world_size - 1, (len(pairs), 2))
    alts = np.where(rng.random(len(pairs)) < 0.3, np.nan, rng.uniform(-20, 200, len(pairs)))
    for (b, i), g, z in zip(pairs, goals, alts, strict=True):
        alt = None if np.isnan(z) else float(z)
        slow.apply(b, {slow.ids[i]: Command(route=((float(g[0]), float(g[1])),), altitude=alt)})
    w = np.array([b for b, _ in pairs], dtype=np.int64)
    a = np.array([i for _, i in pairs], dtype=np.int64)
    fast.go_to(w, a, goals, alts)
    for name_ in _ARRAYS:
        u, v = getattr(fast, name_), getattr(slow, name_)
        assert (u.dtype, u.shape, u.tobytes()) == (v.dtype, v.shape, v.tobytes()), name_


def test_go_to_refuses_non_finite_goals():
    """A non-finite goal is refused as apply refuses it (PlanError)."""
    team = BatchTeam(load_scenario("practice"), 2)
    team.reset_worlds(np.arange(2))
    with pytest.raises(PlanError):
        team.go_to(np.array([1]), np.array([0]), np.array([[np.nan, 3.0]]), np.array([np.nan]))


def test_range_px_equals_team_range_px():
    """Property: BatchTeam.range_px of random positions and batteries (agents at home, far
    away, empty batteries) is, world for world, Team.range_px of a team in that state."""
    sc = load_scenario(1)
    rng = np.random.default_rng(5)
    batch = BatchTeam(sc, 4)
    batch.reset_worlds(np.arange(4))
    batch.pos[1:] = rng.uniform(0, sc.world_size, batch.pos[1:].shape)
    batch.battery[...] = rng.uniform(0, 1, batch.battery.shape) * batch.battery_capacity
    batch.battery[3, 0] = 0.0
    got = batch.range_px()
    team = Team(sc)
    for b in range(4):
        team.pos[...], team.battery[...] = batch.pos[b], batch.battery[b]
        want = team.range_px()
        assert (got[b].dtype, got[b].tobytes()) == (want.dtype, want.tobytes())
