"""Tests of demonstrations in Minari's format and of human games converted into the same
dataset: written, loaded back with ``minari.load_dataset`` offline, replayed to the same metrics."""

from __future__ import annotations

import numpy as np
import pytest

from fcplan.env.demo_minari import dataset_metadata, episode_options, replay_episode
from fcplan.env.demonstrations import demonstrations
from fcplan.errors import FcplanError
from fcplan.mission import Mission
from fcplan.recording import Recorder
from fcplan.scenario import load_scenario
from tests.batch.drive import random_commands

minari = pytest.importorskip("minari")

KW = {"k": 5, "max_steps": 12}


def human_game(name, seed, ticks=150):
    """A recorded game with ``source="human"``: random commands at random ticks."""
    sc = load_scenario(name).replace(duration_s=ticks / 10)
    rec = Recorder(sc, seed, source="human")
    mission = Mission(sc, seed, observers=[rec], belief=False)
    rng = np.random.default_rng(seed)
    while not mission.world.done:
        cmds = random_commands(rng, sc, mission.world.team.ids) if rng.random() < 0.2 else None
        mission.step(cmds or None)
    return rec.recording()


@pytest.fixture
def root(tmp_path, monkeypatch):
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path))
    return tmp_path


def test_write_load_replay(root):
    """A dataset of greedy rollouts and a human game loads with ``minari.load_dataset``; every
    scheduler episode replays offline to its stored observations, rewards and metrics; the human
    episode keeps its game's metrics and seed."""
    game = human_game(24, 5)
    demonstrations("greedy", ["practice", 24], [0, 1], root, format="minari",
                   dataset_id="fcplan/test/mixed-v0", env_kwargs=KW, recordings=[game])  # fmt: skip
    ds = minari.load_dataset("fcplan/test/mixed-v0")
    assert ds.total_episodes == 5 and ds.storage.metadata["algorithm_name"] == "greedy+human"
    meta = dataset_metadata(ds)
    assert meta["env_kwargs"] == {**KW, "dump_altitude": None}
    assert set(meta["scenarios"]) == {"practice", "#24", "#24'"}
    for i, ep in enumerate(ds.iterate_episodes()):
        opts = episode_options(ds, i)
        n = len(ep.actions)
        assert ep.observations["tasks"].shape == (n + 1, 4, 5, 17)
        assert ep.truncations.tolist() == [False] * (n - 1) + [True]
        if opts["source"] == "greedy":
            out = replay_episode(ds, i)
            assert out["metrics"] == opts["metrics"]
            assert out["observations_equal"] and out["rewards_equal"]
            assert float(np.sum(ep.rewards)) == pytest.approx(opts["return"])
        else:
            assert opts["seed"] == 5 and opts["scenario"] == "#24'"  # (a shorter #24)
            assert opts["metrics"] == {k: m.as_dict() for k, m in game.metrics().items()}
            assert n == 15 and (ep.actions <= 5).all()
            assert opts["mapping"] == {} and opts["fallbacks"] == 0  # (no plans to map)
    eps = [episode_options(ds, i) for i in range(ds.total_episodes)]
    for key in ("conflicts", "fallbacks"):
        assert sum(e[key] for e in eps) == meta[key]
    assert {k: sum(e["mapping"].get(k, 0) for e in eps) for k in meta["mapping"]} == meta["mapping"]


def test_human_game_observed_along_its_own_trajectory(root):
    """The human episode's observations are the env's features along the game's own
    re-simulated world (its first observation is the env's reset observation), and its rewards
    sum to minus the game's total negative reward."""
    from fcplan.env.gym_view import TaskGymEnv

    game = human_game("practice", 7, ticks=60)
    demo = demonstrations("greedy", [], [], env_kwargs={"k": 5}, recordings=[game])
    env = TaskGymEnv(game.scenario, k=5)
    obs, _ = env.reset(seed=7)
    rows = demo.step == 0
    assert np.array_equal(demo.task_obs[rows], obs["tasks"])
    total = game.metrics()["manual"].total_negative_reward
    assert demo.reward[demo.agent == 0].sum() == pytest.approx(-total)
    assert demo.episodes[0]["source"] == "human"


def test_errors(root):
    """One team size per Minari dataset; a taken id; an unknown format."""
    with pytest.raises(FcplanError, match="team size"):
        demonstrations("greedy", ["practice", "open_world_example"], [0], format="minari",
                       dataset_id="fcplan/test/bad-v0", env_kwargs={"k": 3, "max_steps": 2})  # fmt: skip
    kw = {
        "format": "minari",
        "dataset_id": "fcplan/test/once-v0",
        "env_kwargs": {"k": 3, "max_steps": 2},
    }
    demonstrations("greedy", ["practice"], [0], **kw)
    with pytest.raises(FcplanError, match="exists"):
        demonstrations("greedy", ["practice"], [1], **kw)
    with pytest.raises(FcplanError, match="format"):
        demonstrations("greedy", ["practice"], [0], format="hdf5")
