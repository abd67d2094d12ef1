"""Tests for fcplan.env.demonstrations: pickle-free round trip, exact replay, metadata, errors."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from fcplan.env.demonstrations import (
    DemonstrationError,
    demonstrations,
    load_demonstrations,
    replay_actions,
)

KW = {"k": 6, "max_steps": 25}


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """greedy on two scenarios (one with hybrids) x two seeds, saved and loaded back."""
    path = tmp_path_factory.mktemp("demo") / "greedy.npz"
    made = demonstrations("greedy", [24, "open_world_example"], [0, 1], path, env_kwargs=KW)
    return made, load_demonstrations(path)


def test_round_trip_without_pickle(demo):
    """Every array survives save/load with allow_pickle=False, dtypes and shapes as documented."""
    made, loaded = demo
    assert loaded.metadata == json.loads(json.dumps(made.metadata))
    for name, arr in made.arrays.items():
        assert loaded.arrays[name].dtype == arr.dtype
        assert np.array_equal(loaded.arrays[name], arr)
    n = len(loaded)
    assert loaded.task_obs.shape == (n, 6, len(loaded.metadata["task_features"]))
    assert loaded.mask.shape == (n, 7) and loaded.mask.dtype == np.int8
    assert (loaded.mask[np.arange(n), loaded.action] == 1).all()  # actions are legal


def test_metadata(demo):
    """Metadata names the scheduler, its settings, the env arguments (the hybrids' dump rule
    too, though the caller gave none), versions and episodes."""
    _, d = demo
    m = d.metadata
    assert m["scheduler"] == "greedy" and m["env_kwargs"] == {**KW, "dump_altitude": None}
    assert {"fcplan", "numpy", "pettingzoo", "gymnasium", "python"} <= set(m["versions"])
    assert [e["seed"] for e in d.episodes] == [0, 1, 0, 1]
    assert len({e["scenario"] for e in d.episodes}) == 2 == len(m["scenarios"])
    assert sum(m["mapping"].values()) == len(d)


@pytest.mark.parametrize("episode", [0, 3])
def test_replay_reproduces_metrics_exactly(demo, episode):
    """Replaying the recorded actions through a fresh env with the same seed gives the
    rollout's final metrics exactly (both definitions, every field)."""
    _, d = demo
    assert replay_actions(d, episode) == d.episodes[episode]["metrics"]


def test_rewards_and_done(demo):
    """Each episode's rewards (one per step) sum to its recorded return; done marks its last step."""
    _, d = demo
    for ep, info in enumerate(d.episodes):
        rows = (d.episode == ep) & (d.agent == 0)
        assert d.reward[rows].sum() == pytest.approx(info["return"])
        assert d.done[rows].tolist() == [False] * (info["steps"] - 1) + [True]


def test_scheduler_object_and_settings(tmp_path):
    """A scheduler object works too; its public settings go into the metadata."""
    from fcplan import make_scheduler

    d = demonstrations(
        make_scheduler("greedy", route_length=2),
        ["practice"],
        [0],
        env_kwargs={"k": 3, "max_steps": 3},
    )
    assert d.metadata["scheduler_settings"]["route_length"] == 2
    spec = demonstrations(
        "greedy:route_length=2", ["practice"], [0], env_kwargs={"k": 3, "max_steps": 3}
    )
    assert spec.metadata["scheduler_settings"] == {"route_length": 2}
    assert np.array_equal(spec.action, d.action)


@pytest.mark.parametrize("num_envs", [1, 2])
def test_specs_run_in_their_deterministic_mode(num_envs):
    """A spec of a scheduler with a deterministic mode runs in it by default (so the dataset
    does not depend on the machine's load), recorded in the settings, in the single and the
    batched rollouts alike; a spec that sets the mode keeps it; ``deterministic=False`` leaves
    it to the spec; greedy, which has no such setting, is unchanged; a non-bool is refused."""
    kw = {"k": 3, "max_steps": 3}
    cbba = demonstrations("cbba", ["practice"], [0, 1], env_kwargs=kw, num_envs=num_envs,
                          progress=False)  # fmt: skip
    assert cbba.metadata["scheduler_settings"] == {"deterministic": True}
    same = demonstrations("cbba:deterministic=true", ["practice"], [0, 1], env_kwargs=kw,
                          progress=False)  # fmt: skip
    assert np.array_equal(cbba.action, same.action)
    assert cbba.episodes == same.episodes
    off = demonstrations("cbba:deterministic=false", ["practice"], [0], env_kwargs=kw,
                         progress=False)  # fmt: skip
    assert off.metadata["scheduler_settings"] == {"deterministic": False}
    free = demonstrations("cbba", ["practice"], [0], env_kwargs=kw, deterministic=False,
                          progress=False)  # fmt: skip
    assert free.metadata["scheduler_settings"] == {}
    greedy = demonstrations("greedy", ["practice"], [0], env_kwargs=kw, progress=False)
    assert greedy.metadata["scheduler_settings"] == {}
    with pytest.raises(DemonstrationError, match="deterministic: must be True or False"):
        demonstrations("cbba", ["practice"], [0], env_kwargs=kw, deterministic="yes")


def test_bad_files(tmp_path):
    """Missing, foreign, pickled or incomplete files raise DemonstrationError naming the file."""
    with pytest.raises(DemonstrationError, match="nope.npz"):
        load_demonstrations(tmp_path / "nope.npz")
    foreign = tmp_path / "foreign.npz"
    np.savez(foreign, x=np.arange(3))
    with pytest.raises(DemonstrationError, match="missing arrays"):
        load_demonstrations(foreign)
    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, metadata=np.array([{"a": 1}], dtype=object))
    with pytest.raises(DemonstrationError, match="pickled.npz"):
        load_demonstrations(pickled)
    text = tmp_path / "text.npz"
    text.write_text("hello")
    with pytest.raises(DemonstrationError):
        load_demonstrations(text)
    assert zipfile.is_zipfile(foreign)


def test_graph_params_survive_the_file(tmp_path):
    """Task-graph parameters are stored in the metadata and used again by the replay."""
    from fcplan.taskgraph import TaskGraphParams

    kw = {"k": 4, "max_steps": 8, "graph_params": TaskGraphParams(search_block_px=200)}
    path = tmp_path / "gp.npz"
    demonstrations("greedy", [1], [0], path, env_kwargs=kw)
    d = load_demonstrations(path)
    assert d.metadata["env_kwargs"]["graph_params"]["search_block_px"] == 200
    assert replay_actions(d, 0) == d.episodes[0]["metrics"]


def test_episodes_carry_their_own_mapping_counts(demo):
    """Each episode's entry names how its plans became actions (mapping counts, one per row,
    conflicts, fallbacks) and the dataset's totals are their sums, so episodes can be filtered
    on them."""
    _, d = demo
    m = d.metadata
    for key in ("conflicts", "fallbacks"):
        assert sum(e[key] for e in d.episodes) == m[key]
    assert sum(sum(e["mapping"].values()) for e in d.episodes) == sum(m["mapping"].values())
    for name, total in m["mapping"].items():
        assert sum(e["mapping"].get(name, 0) for e in d.episodes) == total
    for i, e in enumerate(d.episodes):  # one mapped action per (step, agent): the episode's rows
        assert sum(e["mapping"].values()) == int((d.episode == i).sum())


def test_hybrids_dump_rule_is_stored_and_replayed(demo, tmp_path):
    """A dataset names its hybrids' dump rule: the env's default (None: the top of the bounds,
    the schedulers' rule) when the caller gave none, ``"watch"`` when asked, and a dataset
    written before the rule was stored (no ``dump_altitude`` key) replays by ``"watch"``, the
    env's default then; on the scenario with hybrids the two rules give different episodes."""
    from fcplan.env.demo_episodes import env_kwargs_from_metadata

    _, d = demo
    assert env_kwargs_from_metadata(d.metadata)["dump_altitude"] is None
    old = {**d.metadata, "env_kwargs": dict(KW)}
    assert env_kwargs_from_metadata(old)["dump_altitude"] == "watch"
    path = tmp_path / "watch.npz"
    demonstrations("greedy", ["open_world_example"], [0], path,
                   env_kwargs={**KW, "dump_altitude": "watch"})  # fmt: skip
    w = load_demonstrations(path)
    assert w.metadata["env_kwargs"]["dump_altitude"] == "watch"
    assert replay_actions(w, 0) == w.episodes[0]["metrics"]
    new = next(e for e in d.episodes if e["scenario"] != "#24" and e["seed"] == 0)
    assert new["metrics"] != w.episodes[0]["metrics"]


def test_batched_rollouts_equal_sequential_ones():
    """Seeds rolled out several at a time in a batched task env (``num_envs``) give exactly the
    dataset of one at a time: every array, every episode record, the mapping counts."""
    kw = {"k": 4, "max_steps": 6}
    one = demonstrations("greedy", ["practice", 24], [3, 4, 5], env_kwargs=kw)
    many = demonstrations("greedy", ["practice", 24], [3, 4, 5], env_kwargs=kw, num_envs=2)
    for name, arr in one.arrays.items():
        assert many.arrays[name].dtype == arr.dtype and np.array_equal(many.arrays[name], arr)
    for key in ("episodes", "mapping", "conflicts", "fallbacks"):
        assert many.metadata[key] == one.metadata[key]


def test_demonstrations_report_progress_per_episode():
    """demonstrations() counts its episodes through the progress callback of compare and sweep
    (scheduler episodes, then recorded games), ending at the total; progress=False is silent."""
    calls = []
    demo = demonstrations(
        "greedy", ["practice"], [0, 1], env_kwargs={"max_steps": 3},
        progress=lambda done, total, row: calls.append((done, total)),
    )  # fmt: skip
    assert calls == [(1, 2), (2, 2)]
    assert demo.n_episodes == 2
    demonstrations("greedy", ["practice"], [0], env_kwargs={"max_steps": 3}, progress=False)


def test_episode_gap_compares_like_for_like():
    """episode_gap plays the scheduler through the env and in run_episode with the same spec
    (deterministic mode when it has one): the run_episode score is run_episode's own, and the
    env score is the demonstration's."""
    from fcplan import run_episode
    from fcplan.env.demonstrations import episode_gap

    (row,) = episode_gap("cbba", [24], [0], env_kwargs={"k": 4})
    ref = run_episode(24, "cbba:deterministic=true", seed=0)
    assert row["episode"] == ref.metrics["manual"].final_score
    demo = demonstrations("cbba", [24], [0], env_kwargs={"k": 4}, progress=False)
    assert row["env"] == demo.episodes[0]["metrics"]["manual"]["final_score"]
