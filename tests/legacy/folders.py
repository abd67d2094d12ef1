"""Synthetic legacy folders: an fcplan episode written as the 2020 GUI's 13 ``.pkl`` files."""

from __future__ import annotations

import math
import os
import pickle

import numpy as np

from fcplan import World, load_scenario, make_scheduler
from fcplan.belief import Belief
from fcplan.legacy import LEGACY_FILES
from fcplan.plan import plan_commands
from fcplan.scheduling import solve
from fcplan.taskgraph import build_task_graph
from fcplan.team import Mode

_FLAG = {int(Mode.IDLE): 1, int(Mode.ACTIVE): 1, int(Mode.RETURNING): 0, int(Mode.HOMING): 2}


def dump_pickle(folder, name, obj):
    with open(os.path.join(folder, name), "wb") as f:
        pickle.dump(obj, f, protocol=2)


def write_legacy_folder(folder, scenario_name="practice", seed=0, duration_s=None):
    """Play ``scenario_name`` (for ``duration_s`` if given) with greedy in fcplan and write it as
    the 13 files of the 2020 GUI (FIRECOMMANDER.md section 7 layout; one frame per 100 ms).
    Returns the world."""
    sc = load_scenario(scenario_name)
    if duration_s is not None:
        sc = sc.replace(duration_s=duration_s)
    world, belief = World().reset(sc, seed), Belief(sc)
    sched = make_scheduler("greedy")
    w = sc.world_size
    n = len(sc.agents)
    roles = [int(a.role) for a in sc.agents]
    index_in_role = [int(a.id[1:]) for a in sc.agents]
    actors = [i for i in range(n) if sc.agents[i].role.can_act]
    sensors = [i for i in range(n) if sc.agents[i].role.can_sense]
    states = [[] for _ in range(n)]
    fire_rows = []
    sensed = [[] for _ in sensors]
    pruned = [[] for _ in actors]
    base = []
    user = [[] for _ in range(n)]
    on_fire = [[0] for _ in sc.scored_facilities]
    pruned_so_far = []
    while not world.done:
        cmds = None
        if world.tick % 10 == 0:
            g = build_task_graph(sc, world.team, belief)
            cmds = plan_commands(solve(sched, g, time_limit=None, rng=world.controller_rng), g)
            for aid, c in cmds.items():
                if c.route:
                    i = sc.agent_ids.index(aid)
                    user[i].append([c.route[0][0], c.route[0][1], world.tick, 0, 0])
        info = world.step(cmds)
        belief.update(info)
        ms = world.tick * 100
        team = world.team
        for i in range(n):
            dist = (team.battery_capacity[i] - team.battery[i]) / 0.1
            row = [
                *team.pos[i],
                team.z[i],
                0,
                0,
                0,
                0,
                ms,
                roles[i],
                index_in_role[i],
                dist,
                0,
                team.tank[i],
                _FLAG[int(team.mode[i])],
                0,
                0,
            ]
            states[i].extend(row)
            if world.tick == 77:  # the agent-switch bug: an extra 16-tuple for every agent
                states[i].extend(row)
        for c in info.ignited:
            fire_rows.append([c // w, c % w, 1.0, ms])
        for k in range(len(sensors)):
            cells = info.newly_sensed if k == 0 else np.zeros(0, np.int64)
            if k == 0 and world.tick % 50 == 0 and pruned_so_far:  # the GUI re-sensed old cells
                cells = np.concatenate([cells, pruned_so_far[:5]])
            sensed[k].append(
                np.stack([cells // w, cells % w, np.ones(cells.size), np.zeros(cells.size)], 1)
                if cells.size
                else []
            )
        if info.pruned.size:
            who = actors.index(info.dumped[0])
            pruned[who].append(
                [[[c // w, c % w, 1.0] for c in info.pruned], [*team.pos[info.dumped[0]], ms]]
            )
            pruned_so_far.extend(info.pruned.tolist())
        for k in range(len(actors)):
            if not (info.pruned.size and k == actors.index(info.dumped[0])):
                pruned[k].append([])
        base.append([*sc.depot.center, *sc.depot.size, 9, 1, world.tick])
        for f in range(len(on_fire)):
            on_fire[f].append(int(world.facility_burning[f]))
    regions = sc.regions
    fire_setting = [
        [r.fronts for r in regions],
        [r.delay_s for r in regions],
        [r.fuel for r in regions],
        [r.wind_speed for r in regions],
        [r.wind_dir_deg for r in regions],
        sc.scoring.temporal_exponent,
        sc.scoring.propagation_weight,
        90,
        80,
        1,
    ]
    kinds = {
        k: [list(f.center) for f in sc.facilities if f.kind == k]
        for k in ("house", "hospital", "power_station")
    }
    team_counts = sc.team_counts
    adv = [
        [list(sc.agents[0].altitude)],
        [[10, 100]],
        [[500]],
        [[500]],
        [[500]],
        [[20]],
        [[20]],
        [[20]],
        [[10]],
        [[10]],
    ]
    background = [
        [w, sc.duration_s, len(regions), *(len(v) for v in kinds.values()), len(sc.lakes)],
        [team_counts["perception"], team_counts["action"], team_counts.get("hybrid", 0), 0],
        [
            [list(r.center) for r in regions],
            fire_setting,
            [list(sc.depot.center), 1 if sc.depot.orientation == "vertical" else 0],
            kinds["house"],
            kinds["hospital"],
            kinds["power_station"],
            [list(lk.center) for lk in sc.lakes],
        ],
        adv,
        8,
        [math.pi / 4, math.pi / 6],
        16,
    ]
    os.makedirs(folder, exist_ok=True)
    files = {
        "Background_Info.pkl": background,
        "Battery_Info.pkl": [[a.battery, 0.1, 0.05] for a in sc.agents],
        "User_Data.pkl": user,
        "Target_Loci.pkl": [[[*f.center, *f.size, 0, 1, 0]] for f in sc.facilities],
        "Agent_Base_Loci.pkl": [base],
        "Lake_info.pkl": [[[*lk.center, 100, 0]] for lk in sc.lakes],
        "Fire_States.pkl": [fire_rows] + [[] for _ in regions[1:]],
        "Fire_Map.pkl": np.zeros((w, w)),
        "Sensing_Data_CoM.pkl": [[[] for _ in base] for _ in sensors],
        "Sensed_Fire_Map.pkl": sensed,
        "Pruned_Fire_Map.pkl": pruned,
        "target_onFire_List.pkl": on_fire,
        "Agent_States.pkl": states,
    }
    assert set(files) == set(LEGACY_FILES)
    for name, obj in files.items():
        dump_pickle(folder, name, obj)
    return world
