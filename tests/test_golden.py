"""Golden traces: the simulator's behaviour pinned tick by tick, so speed work cannot change it.

Every run below (scenario x seed x scheduler through :func:`fcplan.run_episode`, and hand-driven
:class:`fcplan.World` loops with random commands) is digested: the whole per-tick trace
(``trace().arrays()``), every :class:`fcplan.world.StepInfo` field of every tick, the belief
(known cells, their last-seen ticks, coverage) after every replan period, every field of every task
graph a scheduler received, the metrics, and the final fire, visit and sensed grids. Each array
goes into a SHA-256 per name and run, in two forms:

* ``exact``: the raw little-endian bytes (floats bit for bit). Compared only on the platform the
  golden file was written on (machine, numpy version, AVX-512 dispatch), because libm and SIMD
  builds may round transcendental functions differently in the last bit.
* ``portable``: floats quantised to 1e-6 (non-finite values as sentinels), integers in their own
  width (the machinery is in ``tests/golden.py``).
  Compared everywhere.

Regenerate the file only after an intended behaviour change (and say so in the commit)::

    python tests/test_golden.py --regenerate
"""

from __future__ import annotations

import dataclasses
import sys
from contextlib import contextmanager
from pathlib import Path
from unittest import mock

import numpy as np
import pytest

if __name__ == "__main__":  # (run as a script: make ``tests`` and ``fcplan`` importable)
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import fcplan.mission  # noqa: E402
from fcplan import World, load_scenario, run_episode  # noqa: E402
from fcplan.belief import Belief  # noqa: E402
from fcplan.scheduling import make_scheduler  # noqa: E402
from fcplan.taskgraph import build_task_graph  # noqa: E402
from fcplan.team import Command  # noqa: E402
from tests.golden import Digests, GoldenFile  # noqa: E402

GOLDEN = Path(__file__).parent / "data" / "golden_traces.json"

# (run id, kind, scenario, scheduler or None, seed, duration_s or None)
RUNS: list[tuple[str, str, str, str | None, int, float | None]] = []
for _sc in ("practice", "1", "12", "21", "24", "open_world_example"):
    for _seed in (0, 1):
        RUNS.append((f"episode-{_sc}-greedy-{_seed}", "episode", _sc, "greedy", _seed, None))
    RUNS.append((f"episode-{_sc}-idle-0", "episode", _sc, "idle", 0, None))
    RUNS.append((f"episode-{_sc}-random-2", "episode", _sc, "random", 2, None))
RUNS += [
    ("episode-scale_example-greedy-0", "episode", "scale_example", "greedy", 0, 120.0),
    ("episode-scale_example-random-1", "episode", "scale_example", "random", 1, 90.0),
    ("manual-1-3", "manual", "1", None, 3, None),
    ("manual-21-4", "manual", "21", None, 4, None),
    ("manual-24-5", "manual", "24", None, 5, None),
    ("manual-24ref-6", "manual-reference", "24", None, 6, None),
    ("manual-scale_example-7", "manual", "scale_example", None, 7, 90.0),
]


def digest_info(d: Digests, info) -> None:
    """Every field of one tick's StepInfo (the fields of view as the ``fov`` array, the name
    and form they had when the golden file was written)."""
    for f in dataclasses.fields(info):
        name = "fov" if f.name == "fov_rects" else f.name
        v = info.fov if name == "fov" else getattr(info, f.name)
        d.add(f"step.{name}", np.asarray(v, dtype=np.int64) if isinstance(v, tuple) else v)


def digest_belief(d: Digests, b: Belief) -> None:
    """What the belief holds (the last-seen grid only at the known cells: it is big)."""
    d.add("belief.known", b.known)
    d.add("belief.known_last_seen", b._last_seen_flat[b.known])
    d.add("belief.coverage", b.coverage)
    # (third: whether any fire was ever sensed, the flag the belief kept when the file was written)
    ever = bool((b.last_seen >= 0).any())
    d.add("belief.scalars", np.array([b.tick, b.n_pruned, ever], np.int64))


def digest_graph(d: Digests, g) -> None:
    """Every field of a task graph."""
    for f in dataclasses.fields(g):
        v = getattr(g, f.name)
        if isinstance(v, tuple) and v and isinstance(v[0], str):
            d.add(f"graph.{f.name}", v)
        else:
            d.add(f"graph.{f.name}", np.nan if v is None else v)


def digest_end(d: Digests, world: World, belief: Belief | None) -> None:
    """The trace and the final grids."""
    for k, v in world.trace().arrays().items():
        d.add(f"trace.{k}", v)
    d.add("end.fire_state", world.fire.state)
    d.add("end.fire_visits", world.fire.visits)
    d.add("end.fire_fronts", np.stack([world.fire.x, world.fire.y]))
    d.add("end.sensed", world.sensed)
    d.add("end.team", np.stack([world.team.battery, world.team.hover_s, world.team.distance]))
    if belief is not None:
        d.add("end.last_seen", belief.last_seen)


def _scenario(name: str, duration_s: float | None, gate: str | None = None):
    sc = load_scenario(name)
    if duration_s is not None:
        sc = sc.replace(duration_s=duration_s)
    if gate is not None:
        sc = sc.replace(action_gate=gate)
    return sc


@contextmanager
def _recording_episode(d: Digests):
    """Patch the World and Belief of run_episode's mission with recording subclasses."""
    holder: dict = {}

    class RecWorld(World):
        def reset(self, scenario=None, seed=None):
            holder["world"] = self
            return super().reset(scenario, seed)

        def step(self, commands=None):
            info = super().step(commands)
            digest_info(d, info)
            return info

    class RecBelief(Belief):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            holder["belief"] = self

        def update(self, info) -> None:
            super().update(info)
            if info.tick % 10 == 0:
                digest_belief(d, self)

    with (
        mock.patch.object(fcplan.mission, "World", RecWorld),
        mock.patch.object(fcplan.mission, "Belief", RecBelief),
    ):
        yield holder


class _RecScheduler:
    """Wraps a scheduler and digests every task graph it is given."""

    def __init__(self, inner, d: Digests) -> None:
        self.inner, self.d = inner, d
        self.name = inner.name

    def plan(self, graph, *, time_limit=None, rng=None):
        digest_graph(self.d, graph)
        return self.inner.plan(graph, time_limit=time_limit, rng=rng)


def run_digest(run) -> dict[str, dict[str, str]]:
    """Play one run and digest everything it produced."""
    _, kind, name, scheduler, seed, duration = run
    d = Digests()
    if kind == "episode":
        sc = _scenario(name, duration)
        with _recording_episode(d) as holder:
            res = run_episode(sc, _RecScheduler(make_scheduler(scheduler), d), seed=seed)
        digest_end(d, holder["world"], holder["belief"])
        d.add("episode.replan_ticks", res.replan_ticks)
        d.add("episode.statuses", tuple(s.status for s in res.solves))
        for mname, m in sorted(res.metrics.items()):
            vals = {k: v for k, v in m.as_dict().items() if isinstance(v, (int, float))}
            d.add(f"metrics.{mname}.names", tuple(sorted(vals)))
            d.add(f"metrics.{mname}", np.array([vals[k] for k in sorted(vals)], np.float64))
        return d.result()
    gate = "reference" if kind == "manual-reference" else None
    sc = _scenario(name, duration, gate)
    world = World().reset(sc, seed)
    belief = Belief(sc)
    rng = np.random.default_rng(seed + 1000)
    w = sc.world_size
    ids = sc.agent_ids
    while not world.done:
        commands = None
        if world.tick % 7 == 0:
            commands = {}
            for agent in rng.choice(ids, size=rng.integers(1, len(ids) + 1), replace=False):
                r = rng.random()
                alt = float(rng.uniform(0, 120)) if rng.random() < 0.5 else None
                if r < 0.1:
                    commands[str(agent)] = Command(home=True, altitude=alt)
                elif r < 0.2:
                    commands[str(agent)] = Command(route=(), altitude=alt)
                elif r < 0.3:
                    commands[str(agent)] = Command(altitude=alt)
                else:
                    pts = rng.uniform(-20, w + 20, size=(int(rng.integers(1, 4)), 2))
                    commands[str(agent)] = Command(
                        route=tuple(map(tuple, pts)), patrol=bool(rng.random() < 0.3), altitude=alt
                    )
        if world.tick in (55, 400):
            d.add("manual.ignited", world.ignite(rng.integers(0, w, size=(5, 2))))
        info = world.step(commands)
        digest_info(d, info)
        belief.update(info)
        if world.tick % 10 == 0:
            digest_belief(d, belief)
            digest_graph(d, build_task_graph(sc, world.team, belief))
    digest_end(d, world, belief)
    return d.result()


GOLDEN_FILE = GoldenFile(GOLDEN, RUNS, run_digest)


@pytest.mark.parametrize("run", RUNS, ids=[r[0] for r in RUNS])
def test_golden_trace(run):
    """A run reproduces the recorded digests of every trace, step, belief and graph array."""
    GOLDEN_FILE.check(run)


def test_golden_file_covers_every_run():
    """The golden file holds exactly the runs this module plays."""
    GOLDEN_FILE.check_covers_runs()


if __name__ == "__main__":
    GOLDEN_FILE.main(sys.argv[1:], "tests/test_golden.py")
