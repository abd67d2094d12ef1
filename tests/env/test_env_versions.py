"""Versioned PettingZoo modules (task_v0, task_v1, motion_v0, base_v0, cmplx1_v0, cmplx2_v0)
and the layout options (obs_layout="flat", pad_actions=True)."""

from __future__ import annotations

import importlib
import warnings

import numpy as np
import pytest
from pettingzoo.test import api_test, parallel_api_test, parallel_seed_test

from fcplan.env import EnvError, parallel_env
from fcplan.env.motion import MotionEnv
from fcplan.env.task import TaskEnv
from tests.conftest import scenario_with

MODULES = ["task_v0", "task_v1", "motion_v0", "base_v0", "cmplx1_v0", "cmplx2_v0"]


def _kwargs(name: str) -> dict:
    """Short episodes for every module."""
    if name == "task_v0":
        return {"scenario": 24, "k": 4, "max_steps": 8}
    if name == "task_v1":
        return {"scenario": "open_world_example", "k": 4, "max_steps": 8}
    if name == "motion_v0":
        return {"scenario": scenario_with("practice", duration_s=4.0)}
    return {"max_steps": 60}


@pytest.mark.parametrize("name", MODULES)
def test_module_convention(name):
    """Each module exports env, parallel_env and raw_env; metadata["name"] is the module's name;
    parallel_env() without options is a raw_env."""
    mod = importlib.import_module(f"fcplan.env.{name}")
    assert sorted(mod.__all__) == ["env", "parallel_env", "raw_env"]
    par = mod.parallel_env(**_kwargs(name))
    assert type(par) is mod.raw_env and par.metadata["name"] == name
    assert mod.env(**_kwargs(name)).metadata["name"] == name


@pytest.mark.parametrize("name", MODULES)
@pytest.mark.parametrize("options", [{}, {"obs_layout": "flat", "pad_actions": True}])
def test_pettingzoo_checkers(name, options):
    """parallel_api_test, api_test on env() and parallel_seed_test pass, with and without the
    layout options."""
    mod = importlib.import_module(f"fcplan.env.{name}")
    kw = {**_kwargs(name), **options}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        parallel_api_test(mod.parallel_env(**kw), num_cycles=30)
        api_test(mod.env(**kw), num_cycles=30)
        parallel_seed_test(lambda: mod.parallel_env(**kw))


def test_default_is_unchanged():
    """Without options fcplan.env.parallel_env returns the env classes themselves."""
    assert type(parallel_env(24, k=4)) is TaskEnv
    assert type(parallel_env("practice", mode="motion")) is MotionEnv


@pytest.mark.parametrize(
    "mode, scenario, fields",
    [("task", 24, ["agent", "tasks"]), ("motion", "practice", ["agent", "fov"]),
     ("motion", "base", ["agent", "fov"])],
)  # fmt: skip
def test_flat_layout_is_the_dict_layout_flattened(mode, scenario, fields):
    """obs_layout="flat" gives {"observation", "action_mask"}: observation is the dict
    layout's fields (sorted keys) flattened and concatenated, inside its Box; the mask is the
    same; rewards agree step by step."""
    d = parallel_env(scenario, mode=mode)
    f = parallel_env(scenario, mode=mode, obs_layout="flat")
    od, _ = d.reset(seed=2)
    of, _ = f.reset(seed=2)
    rng = np.random.default_rng(0)
    for _ in range(5):
        for a in d.possible_agents:
            want = np.concatenate([od[a][k].ravel() for k in fields]).astype(np.float32)
            assert np.array_equal(of[a]["observation"], want)
            assert np.array_equal(of[a]["action_mask"], od[a]["action_mask"])
            assert f.observation_space(a).contains(of[a])
        act = {a: int(rng.choice(np.flatnonzero(od[a]["action_mask"]))) for a in d.agents}
        od, rd, *_ = d.step(act)
        of, rf, *_ = f.step(act)
        assert rd == rf


@pytest.mark.parametrize("scenario", ["practice", "open_world_example", "cmplx2"])
def test_padded_actions_are_masked_noops(scenario):
    """pad_actions=True: one Discrete(n_max) for all agents, extra mask entries 0, and an
    extra action does what leaving the agent out does (its no-op)."""
    p = parallel_env(scenario, mode="motion", pad_actions=True)
    q = parallel_env(scenario, mode="motion")
    n = {a: int(q.action_space(a).n) for a in q.possible_agents}
    n_max = max(n.values())
    first = p.action_space(p.possible_agents[0])
    assert all(p.action_space(a) is first for a in p.possible_agents)
    assert int(p.action_space("P1" if "P1" in n else "perception_0").n) == n_max
    op, _ = p.reset(seed=1)
    oq, _ = q.reset(seed=1)
    for a in p.possible_agents:
        assert op[a]["action_mask"][n[a] :].sum() == 0
    extra = {a: n_max - 1 for a in p.agents if n[a] < n_max}
    assert extra
    op, rp, *_ = p.step(extra)
    oq, rq, *_ = q.step({})
    assert rp == rq
    for a in p.possible_agents:
        assert np.array_equal(op[a]["fov"], oq[a]["fov"])
        assert np.array_equal(op[a]["agent"], oq[a]["agent"])


def test_unknown_layout_is_one_line_error():
    """An unknown obs_layout is refused with a one-line error naming the allowed values."""
    with pytest.raises(EnvError, match=r"obs_layout: must be one of dict, flat"):
        parallel_env(24, obs_layout="nested")


def test_task_versions_agree_without_hybrids():
    """task_v0 and task_v1 differ only in a hybrid's dump altitude: on #24 (no hybrids) the
    same seed and actions give the same observations and rewards step for step."""
    from fcplan.env import task_v0, task_v1

    envs = [m.parallel_env(scenario=24, k=4, max_steps=12) for m in (task_v0, task_v1)]
    obs = [e.reset(seed=3)[0] for e in envs]
    rng = np.random.default_rng(3)
    while envs[0].agents:
        act = {a: int(rng.choice(np.flatnonzero(obs[0][a]["action_mask"]))) for a in obs[0]}
        out = [e.step(act) for e in envs]
        for a in obs[0]:
            for key in out[0][0][a]:
                assert np.array_equal(out[0][0][a][key], out[1][0][a][key])
        assert out[0][1] == out[1][1]
        obs = [o[0] for o in out]


def test_every_entry_point_names_its_dump_rule():
    """The env's default is v1's rule (None: the top of the bounds, the schedulers' rule) in
    every entry point that names no version (``TaskEnv``, ``parallel_env``, ``vector_env``) and
    in ``task_v1`` / ``fcplan/Task-v1`` (single and ``make_vec``); ``task_v0`` and
    ``fcplan/Task-v0`` (single and ``make_vec``) fly such a hybrid at ``watch_altitude``, and
    an explicit ``dump_altitude`` overrides either."""
    import gymnasium

    from fcplan.env import task_v0, task_v1, vector_env

    kw = {"k": 3, "max_steps": 2}
    v1 = [TaskEnv("practice", **kw), parallel_env("practice", **kw), task_v1.raw_env(**kw),
          vector_env("practice", "task", 2, **kw).one,
          gymnasium.make("fcplan/Task-v1", **kw).unwrapped.env,
          gymnasium.make_vec("fcplan/Task-v1", num_envs=2, **kw).one]  # fmt: skip
    assert all(e.dump_altitude is None for e in v1)
    assert TaskEnv.metadata["name"] == "fcplan_task_v1"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # (Gymnasium: v0 is out of date)
        v0 = [task_v0.raw_env(**kw), gymnasium.make("fcplan/Task-v0", **kw).unwrapped.env,
              gymnasium.make_vec("fcplan/Task-v0", num_envs=2, **kw).one]  # fmt: skip
    assert all(e.dump_altitude == e.watch_altitude == 35.0 for e in v0)
    assert task_v0.raw_env(dump_altitude=None, **kw).dump_altitude is None
    assert task_v1.raw_env(dump_altitude="watch", watch_altitude=40.0, **kw).dump_altitude == 40.0
