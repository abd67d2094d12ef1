"""Tests for fcplan.env.demo_checkpoint: an interrupted demonstrations run resumes from its
checkpoint folder to the dataset of an uninterrupted one; other runs' folders are refused;
damaged episode files are reported and played again."""

from __future__ import annotations

import json
import zipfile

import numpy as np
import pytest

from fcplan.env.demo_checkpoint import DemoCheckpoint
from fcplan.env.demonstrations import demonstrations
from fcplan.errors import FcplanError

KW = {"k": 4, "max_steps": 5}
SEEDS = [0, 1, 2]


def _same(a, b):
    for name, arr in a.arrays.items():
        assert b.arrays[name].dtype == arr.dtype and np.array_equal(b.arrays[name], arr), name
    for key in ("episodes", "mapping", "conflicts", "fallbacks", "scenarios"):
        assert b.metadata[key] == a.metadata[key], key


@pytest.fixture(scope="module")
def whole():
    """The uninterrupted dataset."""
    return demonstrations("greedy", ["practice", 24], SEEDS, env_kwargs=KW, progress=False)


class _StopError(Exception):
    """Raised by a progress callback to stop a run."""


def test_an_interrupted_run_resumes_to_the_whole_dataset(tmp_path, whole):
    """A run stopped after two episodes (an exception from its progress callback, as Ctrl-C
    would stop it) left them in the folder; the re-run plays only the four others and gives the
    uninterrupted dataset; a third run plays nothing."""

    def stop_after_two(done, total, row):
        if done == 2:
            raise _StopError

    with pytest.raises(_StopError):
        demonstrations("greedy", ["practice", 24], SEEDS, env_kwargs=KW, checkpoint=tmp_path,
                       progress=stop_after_two)  # fmt: skip
    assert len(list((tmp_path / "episodes").glob("*.npz"))) == 2
    calls = []
    again = demonstrations("greedy", ["practice", 24], SEEDS, env_kwargs=KW, checkpoint=tmp_path,
                           progress=lambda d, t, row: calls.append(d))  # fmt: skip
    _same(whole, again)
    assert calls == [2, 3, 4, 5, 6]
    calls.clear()
    _same(
        whole,
        demonstrations(
            "greedy",
            ["practice", 24],
            SEEDS,
            env_kwargs=KW,
            checkpoint=tmp_path,
            progress=lambda d, t, row: calls.append(d),
        ),
    )
    assert calls == [6]


@pytest.mark.parametrize(("num_envs", "jobs"), [(2, 1), (1, 2)])
def test_batched_and_pooled_runs_share_a_checkpoint(tmp_path, whole, num_envs, jobs):
    """Episodes stored by a one-env run are reused by a batched or pooled run of more seeds and
    scenarios, which gives the uninterrupted dataset."""
    demonstrations("greedy", ["practice"], [1], env_kwargs=KW, checkpoint=tmp_path, progress=False)
    got = demonstrations("greedy", ["practice", 24], SEEDS, env_kwargs=KW, checkpoint=tmp_path,
                         num_envs=num_envs, jobs=jobs, progress=False)  # fmt: skip
    _same(whole, got)
    assert len(list((tmp_path / "episodes").glob("*.npz"))) == 6


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"scheduler": "greedy:route_length=1"}, "scheduler_settings"),
        ({"env_kwargs": {"k": 5, "max_steps": 5}}, "env_kwargs"),
        ({"time_limit": 3.0}, "time_limit"),
        ({"scheduler": "idle"}, "scheduler"),
    ],
)
def test_another_runs_folder_is_refused(tmp_path, change, named):
    """A folder made by a run with other settings is refused in one line naming what differs,
    before any episode."""
    demonstrations("greedy", ["practice"], [0], env_kwargs=KW, checkpoint=tmp_path, progress=False)
    args = {"scheduler": "greedy", "env_kwargs": KW, "time_limit": None, **change}
    with pytest.raises(FcplanError, match=f"made by a run with {named} .*use another folder"):
        demonstrations(args.pop("scheduler"), ["practice"], [0], checkpoint=tmp_path,
                       progress=False, **args)  # fmt: skip


def test_a_scenario_of_other_content_is_refused(tmp_path):
    """A scenario of the same name but other content is not the one the episodes came from."""
    from fcplan.scenario import load_scenario

    sc = load_scenario("practice")
    demonstrations("greedy", [sc], [0], env_kwargs=KW, checkpoint=tmp_path, progress=False)
    with pytest.raises(FcplanError, match="scenario 'practice' differs"):
        demonstrations("greedy", [sc.replace(duration_s=sc.duration_s + 1)], [0], env_kwargs=KW,
                       checkpoint=tmp_path, progress=False)  # fmt: skip


def _rewrite(path, name, array):
    """Replace entry ``name`` of the npz ``path`` by ``array``."""
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    data[name] = array
    with open(path, "wb") as f:
        np.savez(f, **data)


DAMAGES = {
    "truncated": lambda p: p.write_bytes(p.read_bytes()[:300]),
    "not a zip": lambda p: p.write_bytes(b"hello"),
    "wrong dtype": lambda p: _rewrite(p, "actions", np.zeros((5, 4), np.int32)),
    "wrong agents": lambda p: _rewrite(p, "actions", np.zeros((5, 3), np.int64)),
    "inconsistent steps": lambda p: _rewrite(p, "rewards", np.zeros(7)),
    "object array": lambda p: _rewrite(p, "rewards", np.array([None] * 5, dtype=object)),
    "foreign episode": lambda p: _rewrite(p, "meta", np.array(json.dumps({"seed": 9}))),
    "compressed": lambda p: _compress(p),
}


def _compress(path):
    with np.load(path, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    with open(path, "wb") as f:
        np.savez_compressed(f, **data)


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_damaged_episode_is_reported_and_played_again(tmp_path, damage):
    """A damaged or foreign episode file is reported in one warning naming it and its episode
    played again (and stored whole); the dataset is the undamaged one."""
    first = demonstrations("greedy", ["practice"], [0, 1], env_kwargs=KW, checkpoint=tmp_path,
                           progress=False)  # fmt: skip
    victim = sorted((tmp_path / "episodes").glob("*-1.npz"))[0]
    DAMAGES[damage](victim)
    with pytest.warns(UserWarning, match=f"{victim.name}: .*its episode is played again"):
        again = demonstrations("greedy", ["practice"], [0, 1], env_kwargs=KW,
                               checkpoint=tmp_path, progress=False)  # fmt: skip
    _same(first, again)
    with zipfile.ZipFile(victim) as zf:
        assert zf.testzip() is None


def test_not_a_checkpoint(tmp_path):
    """A folder whose run.json is not a checkpoint's is refused in one line naming it."""
    (tmp_path / "run.json").write_text('{"format": "something else"}')
    with (
        pytest.raises(FcplanError, match="run.json: not a demonstrations checkpoint"),
        DemoCheckpoint(tmp_path, {"scheduler": "greedy"}, {}),
    ):
        pass


def test_one_run_at_a_time_holds_a_folder(tmp_path):
    """While a run holds a checkpoint folder, another one is refused in one line before any
    episode; once it is done, the folder is free again."""
    run = {"scheduler": "greedy"}
    with (
        DemoCheckpoint(tmp_path, run, {}),
        pytest.raises(FcplanError, match="another demonstrations run is writing into it"),
    ):
        demonstrations("greedy", ["practice"], [0], env_kwargs=KW, checkpoint=tmp_path,
                       progress=False)  # fmt: skip
    with DemoCheckpoint(tmp_path, run, {}):
        pass
