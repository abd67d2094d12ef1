"""Copies of environments: ``copy.deepcopy`` and ``pickle`` of the single and batched envs of
both levels, taken mid-episode, step exactly as the original from then on (observations,
rewards, flags, through episode ends and resets), so do the envs of every registered Gymnasium
id (the preset envs included), every block of memory the original's arrays
share is shared in the copy, the batched belief's maps stay paged, and the multi-process env
refuses to be copied with a clear error and stays usable."""

from __future__ import annotations

import collections
import copy
import functools
import mmap
import pickle

import gymnasium
import numpy as np
import pytest

from fcplan.env import parallel_env, vector_env
from fcplan.errors import EnvError
from fcplan.scenario import load_scenario
from fcplan.shared_views import memory_owner
from tests._fast.bits import same_values

#: every env registered under fcplan/ (fcplan.env.registration)
_IDS = sorted(i for i in gymnasium.registry if i.startswith("fcplan/"))


def _clone(env, how):
    return copy.deepcopy(env) if how == "deepcopy" else pickle.loads(pickle.dumps(env))


#: (level, scenario, steps before the copy, steps compared after it)
_COPY_POINTS = pytest.mark.parametrize(
    "level, scenario, before, after",
    [
        ("motion", "practice", 7, 40),
        ("task", "practice", 2, 10),
        ("motion", "1", 5, 12),
        ("task", "1", 2, 4),
        ("motion", "24", 5, 10),
        ("task", "24", 2, 4),
    ],
)


def _copied_mid_episode(make, scenario, level, before, how, actions, seed):
    """``(env, its copy, the last observations, the action generator)`` after ``before`` steps
    of ``make(scenario, mode=level)`` (practice's episodes cut to 2 s, 3 s at the task level)."""
    sc = load_scenario(scenario)
    if scenario == "practice":
        sc = sc.replace(duration_s=2 if level == "motion" else 3)
    env = make(sc, level)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    for _ in range(before):
        obs, *_ = env.step(actions(rng, obs))
    return env, _clone(env, how), obs, rng


def _vector_actions(rng, obs):
    m = obs["action_mask"]
    return (rng.random(m.shape) * m).argmax(axis=2)


def _single_actions(rng, obs):
    return {
        a: int((rng.random(o["action_mask"].shape) * o["action_mask"]).argmax())
        for a, o in obs.items()
    }


@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
@_COPY_POINTS
def test_a_copied_vector_env_steps_as_the_original(level, scenario, before, after, how):
    """3 batched worlds copied after ``before`` steps: the next ``after`` steps of the copy
    and the original, on the same actions, are equal (practice's 2-3-s episodes end and
    autoreset in between)."""
    env, twin, obs, rng = _copied_mid_episode(
        lambda sc, lv: vector_env(sc, mode=lv, num_envs=3),
        scenario,
        level,
        before,
        how,
        _vector_actions,
        seed=5,
    )
    ends = 0
    for t in range(after):
        act = _vector_actions(rng, obs)
        out, want = twin.step(act), env.step(act)
        assert same_values(out[:4], want[:4]), t
        ends += int(np.count_nonzero(want[2] | want[3]))
        obs = want[0]
    if scenario == "practice":
        assert ends, "the episodes should end within the steps"


@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
@_COPY_POINTS
def test_a_copied_single_env_steps_as_the_original(level, scenario, before, after, how):
    """A single PettingZoo env copied mid-episode steps as the original from then on, through
    the end of its episode and a reset."""
    env, twin, obs, rng = _copied_mid_episode(
        lambda sc, lv: parallel_env(sc, mode=lv),
        scenario,
        level,
        before,
        how,
        _single_actions,
        seed=2,
    )
    for t in range(after):
        if not env.agents:
            obs, _ = env.reset(seed=3 + t)
            assert same_values(twin.reset(seed=3 + t), (obs, _)), t
        act = _single_actions(rng, obs)
        out, want = twin.step(act), env.step(act)
        assert same_values(out[:4], want[:4]), t
        obs = want[0]


def _arrays(obj, path, seen, out):
    """Every ndarray reachable through fcplan objects' attributes, lists, tuples and dicts, by
    path."""
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        out[path] = obj
        return
    if isinstance(obj, dict):
        items = list(obj.items())
    elif isinstance(obj, list | tuple):
        items = list(enumerate(obj))
    elif type(obj).__module__.startswith("fcplan") and hasattr(obj, "__dict__"):
        items = list(vars(obj).items())
    else:
        return
    for k, v in items:
        _arrays(v, f"{path}.{k}", seen, out)


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # (fcplan/Task-v0 is kept, old)
@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
@pytest.mark.parametrize(
    "make",
    [
        lambda: parallel_env("1", mode="motion"),
        lambda: parallel_env("1", mode="task"),
        lambda: vector_env("1", mode="motion", num_envs=2),
        lambda: vector_env("1", mode="task", num_envs=2),
        *(functools.partial(gymnasium.make, i) for i in _IDS),
    ],
    ids=["single-motion", "single-task", "vector-motion", "vector-task", *_IDS],
)
def test_a_copy_shares_what_the_original_shares(make, how):
    """Every two writeable arrays of the original that share memory share it in the copy (a
    class that keeps views without :class:`fcplan.shared_views.KeepsViews` fails here; the
    registered ids are walked from their unwrapped env)."""
    env = make()
    env = getattr(env, "unwrapped", env)
    env.reset(seed=0)
    mine, theirs = {}, {}
    _arrays(env, "env", set(), mine)
    _arrays(_clone(env, how), "env", set(), theirs)
    groups = collections.defaultdict(list)
    for path, a in mine.items():
        groups[id(memory_owner(a))].append(path)
    checked = 0
    for paths in groups.values():
        paths = [p for p in paths if mine[p].flags.writeable and mine[p].size]
        for i, p in enumerate(paths):
            for q in paths[i + 1 :]:
                if np.shares_memory(mine[p], mine[q]):
                    assert np.shares_memory(theirs[p], theirs[q]), (p, q)
                    checked += 1
    assert checked >= 1  # (every env keeps views: the test walks them)


@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
def test_the_copied_belief_stays_paged(how):
    """The batched belief's maps of a copied task env live in paged memory again and read as
    the original's."""
    env = vector_env("1", mode="task", num_envs=3)
    obs, _ = env.reset(seed=1)
    rng = np.random.default_rng(2)
    for _ in range(3):
        obs, *_ = env.step(_vector_actions(rng, obs))
    twin = _clone(env, how)
    for b in range(3):
        assert np.array_equal(twin.belief.last_seen(b), env.belief.last_seen(b))
    assert np.array_equal(twin.belief._mask, env.belief._mask)
    for name in ("_seen", "_mask", "_seen_flat"):
        base = memory_owner(getattr(twin.belief, name)).base
        assert isinstance(getattr(base, "obj", base), mmap.mmap), name
    assert np.shares_memory(twin.belief._seen, twin.belief._seen_flat)


def test_the_sharded_env_refuses_copies():
    """``pickle``, ``copy.copy`` and ``copy.deepcopy`` of a multi-process env raise an
    ``EnvError`` naming the way out, and the env steps and closes normally afterwards."""
    env = vector_env(load_scenario("practice"), mode="motion", num_envs=4, processes=2)
    try:
        obs, _ = env.reset(seed=0)
        for clone in (copy.deepcopy, copy.copy, pickle.dumps):
            with pytest.raises(EnvError, match="processes=1"):
                clone(env)
        env.step(_vector_actions(np.random.default_rng(0), obs))
    finally:
        env.close()


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # (fcplan/Task-v0 is kept, old)
@pytest.mark.parametrize("how", ["deepcopy", "pickle"])
@pytest.mark.parametrize("env_id", _IDS)
def test_every_registered_env_copies(env_id, how):
    """``gymnasium.make(id)`` copied after 3 steps: the next 12 steps (or up to the episode's
    end) give the same observations and rewards as the original's on the same actions."""
    env = gymnasium.make(env_id)
    env.reset(seed=0)
    space = env.action_space
    space.seed(0)
    for _ in range(3):
        env.step(space.sample())
    twin = _clone(env, how)
    for t in range(12):
        act = space.sample()
        out, want = twin.step(act), env.step(act)
        assert same_values(out[:4], want[:4]), t
        if want[2] or want[3]:
            break


def test_one_graph_pickles_without_its_batch():
    """World 0's task graph and candidate table of a 16-world batch pickle to the size of the
    same world's in a batch of one: handed-out values carry their own rows only."""
    sizes = []
    for num in (1, 16):
        env = vector_env("1", mode="task", num_envs=num)
        env.reset(seed=0)
        sizes.append((len(pickle.dumps(env.graphs[0])), len(pickle.dumps(env.candidates[0]))))
    (g1, c1), (g16, c16) = sizes
    assert g16 <= 1.1 * g1 and c16 <= 1.1 * c1, sizes
