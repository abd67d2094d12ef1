"""Expert demonstrations: any registered scheduler rolled out through the task-level environment.

:func:`demonstrations` plays every (scenario, seed) episode in :class:`fcplan.env.task.TaskEnv`.
At each step it runs the scheduler on the env's current task graph (through
:func:`fcplan.scheduling.solve`, so a failing solver falls back to greedy as in any episode; the
scheduler draws from the world's controller generator, as in :func:`fcplan.run_episode`), maps the
plan to env actions one to one (:func:`fcplan.env.task_actions.plan_to_actions`: the first task of
each agent's route becomes the slot that holds it; a task outside the agent's top ``k`` becomes
the nearest candidate of its kind and is counted as ``outside_top_k``), and steps the env. The
dataset therefore holds exactly what the env executed, and replaying its actions through a fresh
env with the same seed reproduces the episode (:func:`replay_actions`).

File format (``.npz``, no pickle: load with ``numpy.load(path, allow_pickle=False)``)
    One row per (episode, step, agent):

    ================  ===============  =================================================
    array             shape, dtype     meaning
    ================  ===============  =================================================
    ``agent_obs``     (N, S) float32   own-state vector (``metadata["agent_features"]``)
    ``task_obs``      (N, k, F) f32    candidate feature table (``["task_features"]``)
    ``mask``          (N, k + 1) int8  legal actions (last = no-op)
    ``action``        (N,) int64       the action taken (``k`` = no-op)
    ``reward``        (N,) float64     the step's shared team reward
    ``done``          (N,) bool        last step of its episode (truncation)
    ``episode``       (N,) int32       episode number (row of ``metadata["episodes"]``)
    ``step``          (N,) int32       step within the episode
    ``agent``         (N,) int16       agent row (scenario order)
    ``metadata``      () str           JSON: scheduler name and settings, env arguments,
                                       feature names, library versions, mapping counts,
                                       and per episode the scenario, seed, final metrics
                                       and its own mapping counts, conflicts and fallbacks
    ================  ===============  =================================================

    Scenarios are stored whole (their TOML document as JSON), so a dataset replays without the
    original files.

How an env episode differs from ``run_episode`` with the same scheduler
    In ``run_episode`` the scheduler's whole plan runs: multi-task routes, its own altitudes,
    event replans when new fire is sensed, and no candidate limit. In the env each agent executes
    only the *first* task of its route per step (then hovers until the next step), with the env's
    altitude rule, periodic steps only, the top-``k`` candidates, and the env's conflict rule.
    :func:`episode_gap` measures the resulting score difference (figures in
    ``bench/README.md``).

Examples
--------
>>> import numpy as np
>>> from fcplan.env.demonstrations import demonstrations, replay_actions
>>> demo = demonstrations("greedy", ["practice"], [0], env_kwargs={"k": 4, "max_steps": 5})
>>> demo.action.shape, demo.n_episodes
((20,), 1)
>>> replay_actions(demo, 0)["manual"] == demo.episodes[0]["metrics"]["manual"]
True
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.env.demo_checkpoint import DemoCheckpoint
from fcplan.env.demo_episodes import (
    EpisodeRecord,
    env_kwargs_from_metadata,
    episode_mapping,
    recording_episode,
    scenario_from_metadata,
)
from fcplan.env.demo_units import demo_units, play_units
from fcplan.env.task import TaskEnv
from fcplan.env.task_actions import MappingCounts
from fcplan.env.task_candidates import AGENT_FEATURES, TASK_FEATURES
from fcplan.errors import FcplanError
from fcplan.mission import ScenarioLike, as_scenario
from fcplan.provenance import library_versions
from fcplan.scheduling import (
    Scheduler,
    deterministic_spec,
    make_scheduler,
    parse_scheduler_spec,
)
from fcplan.world import seed_list

__all__ = [
    "Demonstrations",
    "DemonstrationError",
    "demonstrations",
    "load_demonstrations",
    "replay_actions",
    "episode_gap",
    "FORMAT_VERSION",
]

#: Version of the file layout written by :meth:`Demonstrations.save`.
FORMAT_VERSION = 1

_ARRAYS = {
    "agent_obs": np.float32,
    "task_obs": np.float32,
    "mask": np.int8,
    "action": np.int64,
    "reward": np.float64,
    "done": np.bool_,
    "episode": np.int32,
    "step": np.int32,
    "agent": np.int16,
}


class DemonstrationError(FcplanError, ValueError):
    """A demonstrations file is missing, malformed or of another format (names the file)."""


@dataclass(frozen=True, eq=False)
class Demonstrations:
    """A demonstrations dataset (see the module docstring for the arrays).

    Attributes
    ----------
    arrays : dict of str -> ndarray
    metadata : dict
    """

    arrays: dict[str, np.ndarray]
    metadata: dict[str, Any] = field(default_factory=dict)

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = self.__dict__.get("arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)

    @property
    def episodes(self) -> list[dict[str, Any]]:
        """Per episode: ``scenario`` (name), ``seed``, ``steps``, ``metrics`` (final, as dicts)."""
        return self.metadata["episodes"]

    @property
    def n_episodes(self) -> int:
        """Number of episodes."""
        return len(self.episodes)

    def __len__(self) -> int:
        return int(self.arrays["action"].shape[0])

    def save(self, path: str | Path) -> Path:
        """Write a compressed ``.npz`` (no pickled objects); return the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        entries: dict[str, Any] = {"metadata": np.array(json.dumps(self.metadata, sort_keys=True))}
        entries.update(self.arrays)
        with open(path, "wb") as fh:
            np.savez_compressed(fh, **entries)
        return path


def load_demonstrations(path: str | Path) -> Demonstrations:
    """Load a dataset written by :meth:`Demonstrations.save` (never unpickles anything).

    Raises
    ------
    DemonstrationError
        If the file is missing, not an npz of this format, or lacks an array.
    """
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError) as exc:
        raise DemonstrationError(f"{path}: not a demonstrations file ({exc})") from None
    missing = sorted((set(_ARRAYS) | {"metadata"}) - set(data))
    if missing:
        raise DemonstrationError(f"{path}: missing arrays {', '.join(missing)}")
    try:
        meta = json.loads(str(data.pop("metadata")))
    except ValueError as exc:
        raise DemonstrationError(f"{path}: metadata is not JSON ({exc})") from None
    if meta.get("format") != "fcplan-demonstrations" or meta.get("version") != FORMAT_VERSION:
        raise DemonstrationError(
            f"{path}: format {meta.get('format')!r} version {meta.get('version')!r}, "
            f"expected 'fcplan-demonstrations' version {FORMAT_VERSION}"
        )
    return Demonstrations({k: data[k] for k in _ARRAYS}, meta)


def _versions() -> dict[str, str]:
    return library_versions(("fcplan", "numpy", "scipy", "pettingzoo", "gymnasium", "ortools"))


def _scheduler(
    spec: str | Scheduler, deterministic: bool
) -> tuple[Scheduler, str | Scheduler, str, dict[str, Any]]:
    """The scheduler, the spec the units rebuild it from, its name and settings; a spec of a
    scheduler with a deterministic mode gets ``deterministic=true`` when ``deterministic`` and
    the spec does not set it (as :func:`fcplan.experiments.compare.scheduler_variant` does)."""
    if not isinstance(deterministic, bool):
        raise DemonstrationError(f"deterministic: must be True or False (got {deterministic!r})")
    if isinstance(spec, str):
        if deterministic:
            spec = deterministic_spec(spec)
        name, settings = parse_scheduler_spec(spec)
        return make_scheduler(spec), spec, name, settings
    settings = {
        k: v
        for k, v in vars(spec).items()
        if not k.startswith("_") and isinstance(v, (bool, int, float, str, type(None)))
    }
    return spec, spec, getattr(spec, "name", type(spec).__name__), settings


def demonstrations(
    scheduler: str | Scheduler,
    scenarios: Iterable[ScenarioLike],
    seeds: Iterable[int],
    path: str | Path | None = None,
    *,
    time_limit: float | None = None,
    env_kwargs: dict[str, Any] | None = None,
    recordings: Iterable[Any] = (),
    format: str = "npz",
    dataset_id: str | None = None,
    num_envs: int = 1,
    jobs: int = 1,
    dask: str | None = None,
    checkpoint: str | Path | None = None,
    progress: Any = True,
    deterministic: bool = True,
) -> Any:
    """Roll ``scheduler`` out through the task-level env on every (scenario, seed).

    Parameters
    ----------
    scheduler : str or Scheduler
        A registered name or spec (``"milp"``, ``"greedy:route_length=2"``) or a scheduler object.
    scenarios : iterable of Scenario, str or int
    seeds : int or iterable of int
        World seeds (integers >= 0; a repeated seed is played once; the rule of
        :func:`fcplan.world.seed_list`, a bad seed a one-line :class:`~fcplan.errors.SeedError`).
    path : str or Path, optional
        Also save the dataset there: the ``.npz`` file, or with ``format="minari"`` the Minari
        datasets root (default: Minari's own, ``MINARI_DATASETS_PATH`` or ``~/.minari/datasets``).
    time_limit : float, optional
        Seconds per scheduler call (passed to the scheduler).
    env_kwargs : dict, optional
        :class:`TaskEnv` keyword arguments (``k``, ``replan_period``, ``max_steps`` ...).
    recordings : iterable of fcplan.recording.Recording
        Recorded games (a human's: ``source="human"``) added as episodes of the same dataset
        (:func:`fcplan.env.demo_episodes.recording_episode`), after the scheduler's.
    format : {"npz", "minari"}
        ``"npz"``: the :class:`Demonstrations` rows (module docstring); ``"minari"``: a Minari
        dataset (:mod:`fcplan.env.demo_minari`; needs ``pip install fcplan[minari]``).
    dataset_id : str, optional
        The Minari dataset id (``format="minari"``; default ``"fcplan/task/<scheduler>-v0"``).
    num_envs : int
        Roll up to this many seeds of a scenario out at once in a batched task env
        (:func:`fcplan.env.demo_episodes.batched_rollouts`; greedy plans every world in one call,
        ``plan_batch``, other schedulers one instance per world); the dataset of ``num_envs=1``
        for schedulers that keep no state between episodes.
    jobs : int or None
        Worker processes (None: one per CPU), the pool of ``compare`` and ``sweep``, playing the
        episodes in units (:mod:`fcplan.env.demo_units`): the dataset of ``jobs=1``, for
        schedulers that keep no state between episodes (a scheduler object goes pickled).
    dask : str, optional
        Play the units on Dask instead, as ``sweep`` does: ``"local"`` (a LocalCluster of
        ``jobs`` workers) or a scheduler's address (needs ``pip install fcplan[dask]``).
    checkpoint : str or Path, optional
        A folder that every episode is written into as it finishes; a call with the same folder
        plays only the episodes not in it (:mod:`fcplan.env.demo_checkpoint`).
    progress : bool or callable
        ``True`` (default): a progress bar on stderr counted in episodes, the one of ``compare``
        and ``sweep`` (:mod:`fcplan.experiments.progress`; in place in Jupyter); ``False``:
        silent; or a ``progress(done, total, row)`` callback.
    deterministic : bool
        Run a scheduler named by a spec in its deterministic mode if it has one (work limits,
        not the wall clock: the same dataset on any machine and load), as ``compare`` and
        ``sweep`` do, unless the spec sets ``deterministic``; ``False`` leaves the mode to the
        spec. A scheduler object runs as it was built.

    Returns
    -------
    Demonstrations, or minari.MinariDataset with ``format="minari"``
    """
    from fcplan.experiments.progress import episode_progress

    workers = _check_args(format, num_envs, jobs, dask)
    sched, spec, name, settings = _scheduler(scheduler, deterministic)
    env_kwargs = _env_kwargs(env_kwargs)
    seeds = seed_list(seeds)
    scenarios, recordings = list(scenarios), list(recordings)
    bar = episode_progress(progress, "demonstrations")
    rollouts = _Rollouts(bar, len(scenarios) * len(seeds) + len(recordings))
    run = {"scheduler": name, "scheduler_settings": settings, "time_limit": time_limit,
           "env_kwargs": _jsonable_kwargs(env_kwargs)}  # fmt: skip
    try:
        scen_docs = _roll_out(rollouts, sched, spec, scenarios, seeds, recordings, env_kwargs,
                              time_limit, num_envs, workers,
                              None if checkpoint is None else (checkpoint, run))  # fmt: skip
    finally:
        getattr(bar, "close", lambda: None)()
    meta = _metadata(run, env_kwargs, rollouts, scen_docs)
    if format == "minari":
        from fcplan.env.demo_minari import write_minari

        return write_minari(rollouts.records, meta, dataset_id or f"fcplan/task/{name}-v0", path)
    demo = Demonstrations(rollouts.arrays(), meta)
    if path is not None:
        demo.save(path)
    return demo


def _metadata(
    run: dict[str, Any], env_kwargs: dict[str, Any], rollouts: _Rollouts, scen_docs: dict
) -> dict[str, Any]:
    """A dataset's metadata (module docstring): the run, the features, the totals, the
    episodes and scenarios, the library versions."""
    return {
        "format": "fcplan-demonstrations",
        "version": FORMAT_VERSION,
        **run,
        "k": int(env_kwargs.get("k", 8)),
        "agent_features": list(AGENT_FEATURES),
        "task_features": list(TASK_FEATURES),
        **rollouts.totals(),
        "episodes": rollouts.episodes,
        "scenarios": scen_docs,
        "versions": _versions(),
    }


def _check_args(format: Any, num_envs: Any, jobs: Any, dask: Any) -> tuple[int, str | None]:
    """``(jobs, dask)``: ``jobs`` as an int (None: one per CPU) and the Dask address, after
    checking them, the format and ``num_envs`` (one-line errors)."""
    from fcplan.experiments.workers import check_dask, check_jobs

    if format not in ("npz", "minari"):
        raise DemonstrationError(f"format: must be 'npz' or 'minari' (got {format!r})")
    jobs = check_jobs(jobs)
    if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
        raise DemonstrationError(f"num_envs: must be an integer >= 1 (got {num_envs!r:.40})")
    return jobs, check_dask(dask)


def _roll_out(
    rollouts: _Rollouts,
    sched: Scheduler,
    spec: str | Scheduler,
    scenarios: list[ScenarioLike],
    seeds: list[int],
    recordings: list[Any],
    env_kwargs: dict[str, Any],
    time_limit: float | None,
    num_envs: int,
    workers: tuple[int, str | None],
    checkpoint: tuple[Any, dict[str, Any]] | None,
) -> dict[str, dict[str, Any]]:
    """Add every (scenario, seed) episode (:mod:`fcplan.env.demo_units`; those stored in the
    ``(folder, run identity)`` of ``checkpoint`` read back, the others played and stored) and
    every recording to ``rollouts``; the scenario documents by dataset key."""
    scen_docs: dict[str, dict[str, Any]] = {}
    keyed = []
    for sc in scenarios:
        scenario = as_scenario(sc)
        probe = TaskEnv(scenario, **env_kwargs)  # (bad env arguments: the env's error, here)
        keyed.append((scenario, _scenario_key(scen_docs, scenario), probe))
    with contextlib.ExitStack() as stack:
        store = None
        if checkpoint is not None:
            store = stack.enter_context(DemoCheckpoint(*checkpoint, dict(scen_docs)))
        got = _play_episodes(rollouts, store, keyed, seeds, sched, spec, env_kwargs, time_limit,
                             num_envs, workers)  # fmt: skip
    progress, rollouts.progress = rollouts.progress, None
    for _, key, _ in keyed:
        for seed in seeds:
            rollouts.add(got[(key, seed)])
    rollouts.progress = progress
    for rec in recordings:
        scenario = rec.scenario
        key = _scenario_key(scen_docs, scenario)
        rollouts.add(recording_episode(rec, TaskEnv(scenario, **env_kwargs), key))
    return scen_docs


def _play_episodes(
    rollouts: _Rollouts,
    store: DemoCheckpoint | None,
    keyed: list[tuple[Any, str, TaskEnv]],
    seeds: list[int],
    sched: Scheduler,
    spec: str | Scheduler,
    env_kwargs: dict[str, Any],
    time_limit: float | None,
    num_envs: int,
    workers: tuple[int, str | None],
) -> dict[tuple[str, int], EpisodeRecord]:
    """Every (scenario key, seed) episode: read back from ``store``, or played in units (stored
    as they finish) by ``workers`` (jobs, Dask address); progress counted in episodes."""
    jobs, dask = workers
    got: dict[tuple[str, int], EpisodeRecord] = {}
    todo = []
    for scenario, key, probe in keyed:
        for seed in seeds:
            rec = None if store is None else store.load(key, seed, probe.n_agents, probe.k)
            if rec is not None:
                got[(key, seed)] = rec
        todo.append((scenario, key, [s for s in seeds if (key, s) not in got]))
    units = demo_units(todo, sched, spec, env_kwargs=env_kwargs, time_limit=time_limit,
                       num_envs=int(num_envs), jobs=jobs)  # fmt: skip

    def finished(unit: Any, result: Any) -> None:
        for rec in result.records:
            got[(rec.scenario, rec.seed)] = rec
            if store is not None:
                store.save(rec)
        if rollouts.progress is not None:
            rollouts.progress(len(got), rollouts.total, {})

    if got and rollouts.progress is not None:
        rollouts.progress(len(got), rollouts.total, {})  # (the stored episodes)
    play_units(units, jobs, dask=dask, on_unit=finished)
    return got


def _scenario_key(docs: dict[str, dict[str, Any]], scenario: Any) -> str:
    """The dataset's key of ``scenario`` (its name, primed while another one holds it)."""
    doc = scenario.to_dict()
    key = scenario.name
    while key in docs and docs[key] != doc:  # same name, other content
        key += "'"
    docs[key] = doc
    return str(key)


class _Rollouts:
    """The rows, mapping counts and episode records of a dataset's episodes."""

    def __init__(self, progress: Any = None, total: int = 0) -> None:
        self.progress, self.total = progress, total
        self.parts: dict[str, list[np.ndarray]] = {k: [] for k in _ARRAYS}
        self.episodes: list[dict[str, Any]] = []
        self.records: list[EpisodeRecord] = []

    def add(self, rec: EpisodeRecord) -> None:
        """Append one episode: its rows (one per step and agent) and its record; count it on
        the progress callback."""
        parts, ep = self.parts, len(self.episodes)
        n, n_a = rec.steps, rec.actions.shape[1]
        obs = rec.observations
        parts["agent_obs"].append(obs["agents"][:n].reshape(n * n_a, -1))
        parts["task_obs"].append(obs["tasks"][:n].reshape(n * n_a, *obs["tasks"].shape[2:]))
        parts["mask"].append(obs["action_mask"][:n].reshape(n * n_a, -1))
        parts["action"].append(rec.actions.reshape(-1))
        parts["reward"].append(np.repeat(rec.rewards, n_a))
        parts["done"].append(np.repeat(np.arange(n) == n - 1, n_a))
        parts["episode"].append(np.full(n * n_a, ep))
        parts["step"].append(np.repeat(np.arange(n), n_a))
        parts["agent"].append(np.tile(np.arange(n_a), n))
        self.records.append(rec)
        self.episodes.append(
            {
                "scenario": rec.scenario,
                "seed": rec.seed,
                "steps": n,
                "metrics": rec.metrics,
                "return": rec.return_,
                "source": rec.source,
                **episode_mapping(rec),
            }
        )
        if self.progress is not None:
            self.progress(len(self.episodes), self.total, {})

    def totals(self) -> dict[str, Any]:
        """The dataset's ``mapping``, ``conflicts`` and ``fallbacks``: the sums of its episodes'
        entries (:func:`~fcplan.env.demo_episodes.episode_mapping`)."""
        counts = MappingCounts()
        for e in self.episodes:
            counts.add(e["mapping"])
        return {
            "mapping": dict(counts),
            "conflicts": sum(e["conflicts"] for e in self.episodes),
            "fallbacks": sum(e["fallbacks"] for e in self.episodes),
        }

    def arrays(self) -> dict[str, np.ndarray]:
        """The dataset's arrays (module docstring), rows of every episode in order."""
        return {
            k: (np.concatenate(v) if v else np.zeros((0,), dt)).astype(dt, copy=False)
            for (k, dt), v in zip(_ARRAYS.items(), self.parts.values(), strict=True)
        }


def _env_kwargs(env_kwargs: dict[str, Any] | None) -> dict[str, Any]:
    """The caller's env arguments without ``render_mode``, with ``dump_altitude`` (the env's
    default, None, unless given): stored, so that a dataset names its hybrids' dump rule
    whatever the env's default later is."""
    out = dict(env_kwargs or {})
    out.pop("render_mode", None)
    out.setdefault("dump_altitude", None)
    return out


def _jsonable_kwargs(env_kwargs: dict[str, Any]) -> dict[str, Any]:
    """Env arguments as JSON (a TaskGraphParams becomes a dict of its fields)."""
    import dataclasses

    out = dict(env_kwargs)
    if out.get("graph_params") is not None:
        out["graph_params"] = dataclasses.asdict(out["graph_params"])
    return out


def replay_actions(demo: Demonstrations, episode: int) -> dict[str, dict]:
    """Replay one episode's recorded actions through a fresh env; return its final metrics
    (``{"manual": {...}, "reference2020": {...}}``, as in ``infos[agent]["metrics"]``)."""
    ep = demo.episodes[episode]
    scenario = scenario_from_metadata(demo.metadata, ep["scenario"])
    kwargs = env_kwargs_from_metadata(demo.metadata)
    env = TaskEnv(scenario, **kwargs)
    env.reset(seed=ep["seed"])
    rows = np.flatnonzero(demo.episode == episode)
    steps, agents, actions = demo.step[rows], demo.agent[rows], demo.action[rows]
    infos: dict = {}
    for s in range(ep["steps"]):
        sel = steps == s
        act = dict.fromkeys(env.possible_agents, env.k)
        for a, x in zip(agents[sel].tolist(), actions[sel].tolist(), strict=True):
            act[env.possible_agents[a]] = x
        _, _, _, _, infos = env.step(act)
    return infos[env.possible_agents[0]]["metrics"]


def episode_gap(
    scheduler: str,
    scenarios: Sequence,
    seeds: Sequence[int],
    *,
    env_kwargs: dict[str, Any] | None = None,
) -> list[dict[str, Any]]:
    """Manual final score of ``scheduler`` through the env vs :func:`fcplan.run_episode`.

    Returns one dict per (scenario, seed): ``scenario``, ``seed``, ``env``, ``episode``
    (final scores) and the mapping counts of the env rollout. Both run the scheduler in its
    deterministic mode if it has one (the demonstrations' default).
    """
    from fcplan.episode import run_episode

    spec = _scheduler(scheduler, True)[1]
    out = []
    for sc in scenarios:
        for seed in seeds:
            demo = demonstrations(scheduler, [sc], [seed], env_kwargs=env_kwargs)
            ref = run_episode(sc, spec, seed=seed)
            out.append(
                {
                    "scenario": demo.episodes[0]["scenario"],
                    "seed": seed,
                    "env": demo.episodes[0]["metrics"]["manual"]["final_score"],
                    "episode": ref.metrics["manual"].final_score,
                    **demo.metadata["mapping"],
                    "conflicts": demo.metadata["conflicts"],
                }
            )
    return out
