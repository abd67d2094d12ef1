"""Golden episodes of the task-level environment: its API outputs pinned step by step, so speed
work on the observation side cannot change them.

Every run below (scenario x policy x seed x env options) plays one whole episode of
:class:`fcplan.env.task.TaskEnv` and digests, at the reset and after every step: every observation
array of every agent (``agent``, ``tasks``, ``action_mask``), :meth:`~fcplan.env.task.TaskEnv.state`,
the rewards, terminations and truncations, and the infos (tick, illegal, conflict, task id, and
on the last step the metrics and the return). Policies:

* ``random``: uniformly random legal actions drawn from the masks by a seeded Generator;
* ``greedy``: the greedy scheduler's plans mapped to actions by
  :func:`fcplan.env.task_actions.plan_to_actions` (as ``bench/bench_env.py`` does);
* ``any``: uniformly random actions in ``0..k`` ignoring the masks (illegal actions become
  no-ops), which exercises the illegal and conflict paths.

Each stream goes into a SHA-256 in two forms, as in ``tests/test_golden.py``:

* ``exact``: the raw little-endian bytes (floats bit for bit), compared only on the platform the
  golden file was written on (machine, numpy version, AVX-512 dispatch);
* ``portable``: floats quantised to 1e-6 (non-finite values as sentinels), integers as int64,
  compared everywhere.

Regenerate the file only after an intended behaviour change (and say so in the commit)::

    python tests/env/test_task_env_golden.py --regenerate
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

if __name__ == "__main__":  # (run as a script: make ``tests`` and ``fcplan`` importable)
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from fcplan import load_scenario, make_scheduler  # noqa: E402
from fcplan.env.task import TaskEnv  # noqa: E402
from fcplan.env.task_actions import plan_to_actions  # noqa: E402
from tests.golden import Digests, GoldenFile  # noqa: E402

GOLDEN = Path(__file__).parent.parent / "data" / "golden_task_env.json"

# (run id, scenario, policy, seed, env keyword arguments). The open-world scenario has hybrids,
# whose dumps the env's default rule (None: the top of their bounds) and task_v0's ("watch")
# fly differently: its runs pin v0's rule (recorded before the default changed) and its "-v1"
# runs the default; the manual's scenarios have no hybrids, so the rule changes nothing there.
RUNS: list[tuple[str, str, str, int, dict]] = []
for _sc in ("practice", "1", "12", "24", "open_world_example"):
    _kw = {"dump_altitude": "watch"} if _sc == "open_world_example" else {}
    for _seed in (0, 1):
        RUNS.append((f"{_sc}-random-{_seed}", _sc, "random", _seed, _kw))
    RUNS.append((f"{_sc}-greedy-0", _sc, "greedy", 0, _kw))
RUNS += [
    ("open_world_example-random-0-v1", "open_world_example", "random", 0, {}),
    ("open_world_example-greedy-0-v1", "open_world_example", "greedy", 0, {}),
    ("1-any-2", "1", "any", 2, {}),
    ("24-any-3", "24", "any", 3, {"k": 4, "replan_period": 0.5, "max_steps": 150}),
    ("12-random-4-k3-bonus", "12", "random", 4, {"k": 3, "prune_bonus": 0.5, "validate": False}),
]


def _leaves(prefix: str, value, out: list) -> None:
    """Flatten nested dicts into ``(dotted name, leaf)`` pairs, keys sorted."""
    if isinstance(value, dict):
        for key in sorted(value):
            _leaves(f"{prefix}.{key}", value[key], out)
    else:
        out.append((prefix, value))


def digest_obs(d: Digests, env: TaskEnv, obs: dict) -> None:
    """Every observation array of every agent, and the global state."""
    d.add("obs.agents", tuple(obs))
    for a in env.possible_agents:
        for key in ("agent", "tasks", "action_mask"):
            d.add(f"obs.{key}", obs[a][key])
    d.add("state", env.state())


def digest_step(d: Digests, env: TaskEnv, out: tuple) -> None:
    """Observations, rewards, terminations, truncations and infos of one step."""
    obs, rewards, terms, truncs, infos = out
    digest_obs(d, env, obs)
    d.add("rewards.agents", tuple(rewards))
    d.add("rewards", np.array(list(rewards.values()), dtype=np.float64))
    d.add("terminations", np.array(list(terms.values()), dtype=bool))
    d.add("truncations", np.array(list(truncs.values()), dtype=bool))
    d.add("infos.agents", tuple(infos))
    d.add("env.agents", tuple(env.agents) or ("",))
    for a, info in infos.items():
        d.add("infos.keys", tuple(sorted(info)))
        d.add("infos.flags", np.array([info["tick"], info["illegal"], info["conflict"]], np.int64))
        d.add("infos.task", ("-" if info["task"] is None else info["task"],))
        rest = {k: v for k, v in info.items() if k not in ("tick", "illegal", "conflict", "task")}
        leaves: list = []
        _leaves(a, rest, leaves)
        for name, v in leaves:
            if isinstance(v, str):
                d.add("infos.text", (name, v))
            else:
                d.add("infos.names", (name,))
                d.add("infos.values", np.array([v], dtype=np.float64))


def run_digest(run) -> dict[str, dict[str, str]]:
    """Play one episode and digest everything the environment returned."""
    _, name, policy, seed, kwargs = run
    env = TaskEnv(load_scenario(name), **kwargs)
    d = Digests(ints_as_int64=True)
    obs, infos = env.reset(seed=seed)
    digest_obs(d, env, obs)
    d.add("reset.infos", np.array([info["tick"] for info in infos.values()], np.int64))
    rng = np.random.default_rng(seed + 100)
    sched = make_scheduler("greedy")
    ids = env.possible_agents
    while env.agents:
        if policy == "random":
            act = np.argmax(rng.random(env._mask.shape) * env._mask, axis=1)
        elif policy == "any":
            act = rng.integers(0, env.k + 1, size=len(ids))
        else:
            plan = sched.plan(env.graph, time_limit=None, rng=env.world.controller_rng)
            act = plan_to_actions(plan, env.graph, env.candidates)
        d.add("actions", act.astype(np.int64))
        digest_step(d, env, env.step(dict(zip(ids, act.tolist(), strict=True))))
    return d.result()


GOLDEN_FILE = GoldenFile(GOLDEN, RUNS, run_digest)


@pytest.mark.parametrize("run", RUNS, ids=[r[0] for r in RUNS])
def test_golden_task_env(run):
    """An episode reproduces the recorded digests of every observation, state, reward, flag and
    info the task environment returned."""
    GOLDEN_FILE.check(run)


def test_golden_task_env_file_covers_every_run():
    """The golden file holds exactly the runs this module plays."""
    GOLDEN_FILE.check_covers_runs()


if __name__ == "__main__":
    GOLDEN_FILE.main(sys.argv[1:], "tests/env/test_task_env_golden.py")
