"""Demonstrations as a Minari dataset (Farama's format for offline RL and imitation learning).

``demonstrations(..., format="minari")`` (:mod:`fcplan.env.demonstrations`) writes its episodes
(:class:`fcplan.env.demo_episodes.EpisodeRecord`: a scheduler's rollouts, recorded human games)
with :func:`write_minari` as one Minari dataset (``arrow`` storage, so no HDF5 library is
needed). Load it with ``minari.load_dataset(dataset_id)`` (the same datasets root), iterate
``dataset.iterate_episodes()``, and :func:`replay_episode` plays an episode's actions again
through the task env of the dataset's options (``fcplan/Task-v1``'s defaults unless the
dataset names others: a dataset whose options name no ``dump_altitude`` replays by
``fcplan/Task-v0``'s rule, the default when it was written).

==========================  ==========================================================================
Minari field                content
==========================  ==========================================================================
observation space           ``Dict(agents=Box(-10, 10, (A, 17)), tasks=Box(-10, 10, (A, k, 17)),
                            action_mask=Box(0, 1, (A, k + 1), int8))``: the Gymnasium view's
action space                ``MultiDiscrete([k + 1] * A)``: a candidate slot per agent, ``k`` the no-op
episode ``observations``    ``T + 1`` rows (the last: after the last step)
``actions``, ``rewards``    ``T`` rows; the reward is the env's (minus the manual's negative reward)
``terminations``            all False (the task level has no terminal state)
``truncations``             True on the last step
``infos``                   ``tick`` ``(T + 1,)``; ``illegal``, ``conflict`` ``(T + 1, A)`` (row 0 False)
episode ``seed``            the world's seed
episode ``options``         ``scenario`` (key into the metadata's scenarios), ``source`` (the
                            scheduler's name, or ``"human"``), ``metrics`` (final, both
                            definitions), ``return``, and how its plans became actions:
                            ``mapping`` (the episode's mapping counts), ``conflicts``,
                            ``fallbacks`` (:func:`~fcplan.env.demo_episodes.episode_mapping`)
``algorithm_name``          the sources, joined by ``+`` (``"greedy+human"``)
metadata ``fcplan``         JSON: the npz format's metadata (env arguments, feature names, every
                            scenario's TOML document, library versions, mapping counts)
==========================  ==========================================================================

A dataset holds one team size and one ``k`` (Minari keeps one observation space).

Examples
--------
>>> import os, tempfile
>>> from fcplan.env.demonstrations import demonstrations
>>> root = tempfile.mkdtemp()
>>> ds = demonstrations("greedy", ["practice"], [0], root, format="minari",
...                     dataset_id="fcplan/doc/greedy-v0", env_kwargs={"k": 4, "max_steps": 3})
>>> ds.total_episodes, ds.total_steps
(1, 3)
>>> out = replay_episode(ds, 0)
>>> out["metrics"] == episode_options(ds, 0)["metrics"], out["observations_equal"]
(True, True)
"""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.env.demo_episodes import (
    OBS_KEYS,
    EpisodeRecord,
    env_kwargs_from_metadata,
    episode_mapping,
    scenario_from_metadata,
)
from fcplan.errors import FcplanError

__all__ = ["write_minari", "replay_episode", "dataset_metadata", "episode_options"]


class _RootDir:
    """Point Minari at ``root`` (its ``MINARI_DATASETS_PATH``) for the duration of a block."""

    def __init__(self, root: str | Path | None) -> None:
        self.root, self.old = root, os.environ.get("MINARI_DATASETS_PATH")

    def __enter__(self) -> None:
        if self.root is not None:
            os.environ["MINARI_DATASETS_PATH"] = str(Path(self.root).resolve())

    def __exit__(self, *exc: Any) -> None:
        if self.root is None:
            return
        if self.old is None:
            os.environ.pop("MINARI_DATASETS_PATH", None)
        else:
            os.environ["MINARI_DATASETS_PATH"] = self.old


def _spaces(records: Sequence[EpisodeRecord]) -> tuple[Any, Any]:
    from gymnasium import spaces

    from fcplan.env.task_candidates import FEATURE_BOUND

    first = records[0].observations
    shapes = {k: first[k].shape[1:] for k in OBS_KEYS}
    for r in records[1:]:
        got = {k: r.observations[k].shape[1:] for k in OBS_KEYS}
        if got != shapes:
            raise FcplanError(
                f"minari: one dataset holds one team size and k (episode shapes {shapes} and {got})"
            )
    b = FEATURE_BOUND
    obs = spaces.Dict(
        {
            "agents": spaces.Box(-b, b, shapes["agents"], np.float32),
            "tasks": spaces.Box(-b, b, shapes["tasks"], np.float32),
            "action_mask": spaces.Box(0, 1, shapes["action_mask"], np.int8),
        }
    )
    n_a, n_act = shapes["action_mask"]
    return obs, spaces.MultiDiscrete(np.full(n_a, n_act, dtype=np.int64))


def write_minari(
    records: Sequence[EpisodeRecord],
    metadata: dict[str, Any],
    dataset_id: str,
    root: str | Path | None = None,
) -> Any:
    """Write ``records`` as the Minari dataset ``dataset_id`` under ``root`` (module docstring);
    return the ``minari.MinariDataset``.

    Raises
    ------
    fcplan.errors.FcplanError
        For no episodes, episodes of different shapes, or an id already taken under ``root``.
    """
    try:
        import minari
        from minari.data_collector import EpisodeBuffer
    except ImportError:
        raise FcplanError(
            "format='minari' needs the minari package: pip install fcplan[minari]"
        ) from None
    if not records:
        raise FcplanError("minari: no episodes to write")
    obs_space, act_space = _spaces(records)
    buffers = [_buffer(i, r, EpisodeBuffer) for i, r in enumerate(records)]
    sources = "+".join(dict.fromkeys(r.source for r in records))
    with _RootDir(root), warnings.catch_warnings():
        # (Minari's advice to name an e-mail, a code permalink and an evaluation env)
        warnings.filterwarnings("ignore", message=r"`(author_email|code_permalink|eval_env)`")
        warnings.filterwarnings("ignore", message="env_spec is None")
        if dataset_id in minari.list_local_datasets():
            raise FcplanError(f"minari: dataset {dataset_id!r} exists already under this root")
        ds = minari.create_dataset_from_buffers(
            dataset_id,
            buffers,
            observation_space=obs_space,
            action_space=act_space,
            algorithm_name=sources,
            author="fcplan.env.demonstrations",
            description="fcplan task-level demonstrations (fcplan.env.demo_minari)",
            data_format="arrow",
        )
        ds.storage.update_metadata({"fcplan": json.dumps(metadata, sort_keys=True)})
    return ds


def _buffer(i: int, r: EpisodeRecord, cls: Any) -> Any:
    """Minari's episode buffer of record ``r`` (episode id ``i``)."""
    n, n_a = r.steps, r.actions.shape[1]
    first = np.zeros((1, n_a), dtype=bool)
    return cls(
        id=i,
        seed=int(r.seed),
        options={
            "scenario": r.scenario,
            "source": r.source,
            "metrics": r.metrics,
            "return": r.return_,
            **episode_mapping(r),
        },  # fmt: skip
        observations={k: r.observations[k] for k in OBS_KEYS},
        actions=r.actions,
        rewards=r.rewards.tolist(),
        terminations=[False] * n,
        truncations=[False] * (n - 1) + [True],
        infos={
            "tick": r.ticks.tolist(),  # (a list: Minari's arrow infos keep 1-D arrays as lists)
            "illegal": np.concatenate([first, r.illegal]),
            "conflict": np.concatenate([first, r.conflict]),
        },
    )


def dataset_metadata(dataset: Any) -> dict[str, Any]:
    """The fcplan metadata of a Minari dataset written by :func:`write_minari`."""
    meta: dict[str, Any] = json.loads(dataset.storage.metadata["fcplan"])
    return meta


def episode_options(dataset: Any, index: int) -> dict[str, Any]:
    """Seed and options (scenario, source, metrics, return) of episode ``index``."""
    meta = next(iter(dataset.storage.get_episode_metadata([index])))
    return {"seed": meta.get("seed"), **meta.get("options", {})}


def replay_episode(dataset: Any, index: int) -> dict[str, Any]:
    """Play episode ``index``'s actions through a fresh task env (offline: the scenario and env
    arguments come from the dataset's metadata).

    Returns
    -------
    dict
        ``metrics`` (the replay's final metrics), ``observations_equal`` and ``rewards_equal``
        (every observation and reward equals the stored one). A scheduler's episode replays to
        its own metrics; a human game does not (:mod:`fcplan.env.demo_episodes`).
    """
    from fcplan.env.gym_view import TaskGymEnv

    meta, opts = dataset_metadata(dataset), episode_options(dataset, index)
    ep = next(iter(dataset.iterate_episodes([index])))
    env = TaskGymEnv(
        scenario_from_metadata(meta, opts["scenario"]), **env_kwargs_from_metadata(meta)
    )
    obs, _ = env.reset(seed=opts["seed"])
    same_obs = all(np.array_equal(obs[k], ep.observations[k][0]) for k in OBS_KEYS)
    same_rew, info = True, dict[str, Any]()
    for t, act in enumerate(ep.actions):
        obs, rew, _, _, info = env.step(act)
        same_obs &= all(np.array_equal(obs[k], ep.observations[k][t + 1]) for k in OBS_KEYS)
        same_rew &= bool(rew == ep.rewards[t])
    return {"metrics": info.get("metrics"), "observations_equal": bool(same_obs),
            "rewards_equal": bool(same_rew)}  # fmt: skip
