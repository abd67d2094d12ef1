"""Helpers of the batch tests: drive a :class:`fcplan.batch.BatchWorld` and single worlds with the
same commands and compare them bit for bit."""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.batch import BatchWorld
from fcplan.mission import Mission
from fcplan.scenario import Scenario
from fcplan.team import Command
from tests._fast.bits import bits


def random_commands(rng: np.random.Generator, scenario: Scenario, ids: tuple) -> dict:
    """A few random commands: flights to a fire region (arming dumps on arrival), patrols over
    the map, calls home, altitude changes."""
    w = scenario.world_size
    cmds: dict[str, Command] = {}
    for a in ids:
        u = rng.random()
        if u < 0.05:
            r = scenario.regions[int(rng.integers(len(scenario.regions)))]
            c = np.clip(np.array(r.center, float) + rng.normal(0, 60, 2), 0, w - 1)
            cmds[a] = Command(route=[tuple(c)], altitude=float(rng.uniform(10, 100)))
        elif u < 0.06:
            cmds[a] = Command(home=True)
        elif u < 0.08:
            pts = rng.uniform(0, w - 1, (3, 2))
            cmds[a] = Command(route=[tuple(p) for p in pts], patrol=bool(rng.random() < 0.5))
        elif u < 0.085:
            cmds[a] = Command(route=[])
    return cmds


def mismatches(batch: BatchWorld, b: int, mission: Mission) -> list[str]:
    """Names of the arrays of world ``b`` that differ from ``mission``'s world (empty: equal)."""
    w = mission.world
    fire, team = batch.fire, batch.team
    state, sensed = batch.cells(b)
    pairs: dict[str, tuple[Any, Any]] = {
        "tick": (batch.tick[b], w.tick),
        "state": (state, w.fire.state),
        "sensed": (sensed, w.sensed),
        "x": (fire.x[b], w.fire.x),
        "y": (fire.y[b], w.fire.y),
        "alive": (fire.alive[b], w.fire.alive),
        "frozen": (fire.frozen[b], w.fire.frozen),
        "region_active": (fire.region_active[b], w.fire.region_active),
        "n_burning": (fire.n_burning[b], w.fire.n_burning),
        "facility_burning": (batch.facility_burning[b], w.facility_burning),
        "facility_pruned": (batch.facility_pruned[b], w.facility_pruned),
    }
    for name in ("pos", "z", "z_target", "battery", "tank", "mode", "goal", "has_goal", "armed",
                 "hover_s", "distance", "dumps", "sorties", "patrol"):  # fmt: skip
        pairs[name] = (getattr(team, name)[b], getattr(w.team, name))
    bad = [
        k
        for k, (u, v) in pairs.items()
        if bits(np.asarray(u)) != bits(np.asarray(v).astype(np.asarray(u).dtype))
    ]
    rows, ref = batch.trace_rows(b), w.trace()
    for key in (
        "active",
        "pruned",
        "sensed_active",
        "sensed_ever",
        "facility_burning",
        "facility_pruned",
    ):
        if bits(rows[key]) != bits(getattr(ref, key)):
            bad.append(f"trace.{key}")
    if batch.record_agents:
        for key in ("xyz", "battery", "tank", "mode", "dumps"):
            if bits(rows[key]) != bits(getattr(ref.agents, key)):
                bad.append(f"trace.agents.{key}")
    return bad


def run_pair(
    scenario: Scenario,
    seeds: list[int],
    ticks: int,
    *,
    resets: dict[int, list[tuple[int, int]]] | None = None,
    command_seed: int = 0,
    record_agents: bool = True,
) -> BatchWorld:
    """Step a batch and one :class:`~fcplan.mission.Mission` per world ``ticks`` times with the
    same random commands, resetting world ``b`` with seed ``s`` before tick ``t`` for each
    ``(b, s)`` of ``resets[t]``; assert every world equal to its single world before each reset
    and at the end. Return the batch."""
    batch = BatchWorld(scenario, len(seeds), record_agents=record_agents)
    batch.reset(seeds=seeds)
    singles = [Mission(scenario, s, event_replans=False, belief=False) for s in seeds]
    rngs = [np.random.default_rng([command_seed, b]) for b in range(len(seeds))]
    for t in range(ticks):
        for b, s in (resets or {}).get(t, []):
            assert mismatches(batch, b, singles[b]) == [], f"world {b} before its reset at {t}"
            mask = np.zeros(len(seeds), dtype=bool)
            mask[b] = True
            batch.reset(seeds=[s], mask=mask)
            singles[b] = Mission(scenario, s, event_replans=False, belief=False)
        for b, m in enumerate(singles):
            if not m.world.done:
                c = random_commands(rngs[b], scenario, m.world.team.ids)
                batch.team.apply(b, c)
                m.world.team.apply(c)
        batch.step()
        for m in singles:
            if not m.world.done:
                m.step()
    for b, m in enumerate(singles):
        assert mismatches(batch, b, m) == [], f"world {b} at the end"
    return batch
