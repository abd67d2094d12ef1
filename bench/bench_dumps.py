"""Where the water goes: dumps per agent role, cells put out per dump, and hybrids' dump altitude.

A dump puts out the *sensed* burning cells in the dumping agent's field of view, which is
``2 z x 1.15 z`` px at altitude ``z`` (:mod:`fcplan.world`); tanks hold 2-4 dumps on the hard
tier, and an empty tank costs a flight home. So a scheduler's fire fighting is bounded by how many
cells each dump puts out. This script plays episodes through the :class:`fcplan.mission.Mission`
loop and, for every dump, records the dumping agent's role (action ``A`` or hybrid ``H``), what
its plan's first task was (a fire, a search block), the cells it put out and, for hybrids, the
altitude it dumped from. It prints per scheduler: the manual final score, dumps, mean and median
cells per dump, dumps of fewer than 10 cells, and the hybrids' median dump altitude.

It found that ``milp`` flew hybrids' dump routes at the 35-m watch altitude (a view an eighth of
the 100-m one), dumping twice as often as greedy for half the cells per dump
(``bench/README.md``, "MILP: hybrids dump from the top of their bounds").

Usage::

    python bench/bench_dumps.py fcplan-bench-v2/hard-03 --schedulers greedy milp --seeds 0
    python bench/bench_dumps.py fcplan-bench-v2/hard-03 --schedulers milp milp:dump_altitude=35
"""

from __future__ import annotations

import argparse
from collections import defaultdict

import numpy as np

import fcplan
from fcplan.mission import Mission
from fcplan.scheduling import parse_scheduler_spec, supports_deterministic


def _role(graph: fcplan.TaskGraph, i: int) -> str:
    if graph.agent_can_act[i] and graph.agent_can_sense[i]:
        return "H"
    return "A" if graph.agent_can_act[i] else "P"


def dumps_of(scenario: str, scheduler: str, seed: int) -> dict[str, object]:
    """Play one episode and return its score and every dump (role, first task, cells, z)."""
    sched = fcplan.make_scheduler(scheduler)
    mission = Mission(fcplan.load_scenario(scenario), seed=seed)
    first: dict[int, tuple[str, str]] = {}
    dumps: list[tuple[str, str, float, float]] = []
    while not mission.done:
        commands = None
        if mission.replan_due():
            graph, plan = mission.replan(sched)
            fires = {graph.task_ids[k] for k in graph.fire_tasks}
            for i, a in enumerate(graph.agent_ids):
                route = plan.routes.get(a, ())
                kind = "none" if not route else "fire" if route[0] in fires else "search"
                first[i] = (_role(graph, i), kind)
            commands = mission.commands_for(plan, graph)
        info = mission.step(commands)
        if info.dumped:  # cells of a tick shared alike among that tick's dumps
            share = len(info.pruned) / len(info.dumped)
            for i in info.dumped:
                role, kind = first.get(i, ("?", "?"))
                dumps.append((role, kind, share, float(mission.world.team.z[i])))
    manual = fcplan.compute_all(mission.world.trace())["manual"]
    return {"score": manual.final_score, "dumps": dumps}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("--schedulers", nargs="+", default=["greedy", "milp"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[0])
    args = ap.parse_args()
    print(f"# {args.scenario}, seeds {args.seeds}; schedulers in their deterministic modes")
    for spec in args.schedulers:
        base, settings = parse_scheduler_spec(spec)
        name = spec
        if "deterministic" not in settings and supports_deterministic(base):
            name = f"{spec}:deterministic=true"
        scores, rows = [], defaultdict(list)
        zs: list[float] = []
        for seed in args.seeds:
            out = dumps_of(args.scenario, name, seed)
            scores.append(float(out["score"]))  # type: ignore[arg-type]
            for role, kind, cells, z in out["dumps"]:  # type: ignore[attr-defined]
                rows[(role, kind)].append(cells)
                if role == "H":
                    zs.append(z)
        print(f"{spec}: mean final score {np.mean(scores):.1f}")
        for (role, kind), cells in sorted(rows.items()):
            c = np.asarray(cells)
            print(
                f"  {role} on {kind:<6} dumps {c.size:4d}  cells/dump mean {c.mean():6.1f}"
                f"  median {np.median(c):5.0f}  under 10: {int((c < 10).sum())}"
            )
        if zs:
            print(f"  hybrids' dump altitude: median {np.median(zs):.0f} m")


if __name__ == "__main__":
    main()
