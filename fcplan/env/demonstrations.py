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
                                       and per episode the scenario, seed and final metrics
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

import json
import platform
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.env.task import TaskEnv
from fcplan.env.task_actions import MappingCounts, plan_to_actions
from fcplan.env.task_candidates import AGENT_FEATURES, TASK_FEATURES
from fcplan.errors import FcplanError
from fcplan.mission import ScenarioLike, as_scenario
from fcplan.scheduling import Scheduler, make_scheduler, parse_scheduler_spec, solve

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
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for dist in ("fcplan", "numpy", "scipy", "pettingzoo", "gymnasium", "ortools"):
        try:
            out[dist] = version(dist)
        except PackageNotFoundError:
            out[dist] = "not installed"
    return out


def _scheduler(spec: str | Scheduler) -> tuple[Scheduler, str, dict[str, Any]]:
    if isinstance(spec, str):
        name, settings = parse_scheduler_spec(spec)
        return make_scheduler(spec), name, settings
    settings = {
        k: v
        for k, v in vars(spec).items()
        if not k.startswith("_") and isinstance(v, (bool, int, float, str, type(None)))
    }
    return spec, getattr(spec, "name", type(spec).__name__), settings


def demonstrations(
    scheduler: str | Scheduler,
    scenarios: Iterable[ScenarioLike],
    seeds: Iterable[int],
    path: str | Path | None = None,
    *,
    time_limit: float | None = None,
    env_kwargs: dict[str, Any] | None = None,
) -> Demonstrations:
    """Roll ``scheduler`` out through the task-level env on every (scenario, seed).

    Parameters
    ----------
    scheduler : str or Scheduler
        A registered name or spec (``"milp"``, ``"greedy:route_length=2"``) or a scheduler object.
    scenarios : iterable of Scenario, str or int
    seeds : iterable of int
    path : str or Path, optional
        Also save the dataset there (``.npz``).
    time_limit : float, optional
        Seconds per scheduler call (passed to the scheduler).
    env_kwargs : dict, optional
        :class:`TaskEnv` keyword arguments (``k``, ``replan_period``, ``max_steps`` ...).

    Returns
    -------
    Demonstrations
    """
    sched, name, settings = _scheduler(scheduler)
    env_kwargs = dict(env_kwargs or {})
    env_kwargs.pop("render_mode", None)
    seeds = [int(s) for s in seeds]
    rollouts = _Rollouts(sched, time_limit)
    scen_docs: dict[str, dict[str, Any]] = {}
    for sc in scenarios:
        scenario = as_scenario(sc)
        doc = scenario.to_dict()
        key = scenario.name
        while key in scen_docs and scen_docs[key] != doc:  # same name, other content
            key += "'"
        scen_docs[key] = doc
        env = TaskEnv(scenario, **env_kwargs)
        for seed in seeds:
            rollouts.play(env, key, seed)
    meta = {
        "format": "fcplan-demonstrations",
        "version": FORMAT_VERSION,
        "scheduler": name,
        "scheduler_settings": settings,
        "time_limit": time_limit,
        "env_kwargs": _jsonable_kwargs(env_kwargs),
        "k": int(env_kwargs.get("k", 8)),
        "agent_features": list(AGENT_FEATURES),
        "task_features": list(TASK_FEATURES),
        "mapping": dict(rollouts.counts),
        "conflicts": int(rollouts.conflicts),
        "fallbacks": int(rollouts.fallbacks),
        "episodes": rollouts.episodes,
        "scenarios": scen_docs,
        "versions": _versions(),
    }
    demo = Demonstrations(rollouts.arrays(), meta)
    if path is not None:
        demo.save(path)
    return demo


class _Rollouts:
    """The rows, mapping counts and episode records of a scheduler's env rollouts."""

    def __init__(self, scheduler: Scheduler, time_limit: float | None) -> None:
        self.scheduler, self.time_limit = scheduler, time_limit
        self.parts: dict[str, list[np.ndarray]] = {k: [] for k in _ARRAYS}
        self.episodes: list[dict[str, Any]] = []
        self.counts = MappingCounts()
        self.fallbacks = self.conflicts = 0

    def play(self, env: TaskEnv, scenario_key: str, seed: int) -> None:
        """One episode of ``env`` with ``seed``: the scheduler's plan on the env's graph at each
        step, mapped to actions one to one (module docstring)."""
        parts, ids = self.parts, env.possible_agents
        env.reset(seed=seed)
        rng = env.world.controller_rng
        ep, n_a = len(self.episodes), env.n_agents
        step = 0
        first: dict[str, Any] = {}
        while env.agents:
            graph, cand = env.graph, env.candidates
            assert graph is not None and cand is not None  # (built by reset and step)
            plan = solve(self.scheduler, graph, time_limit=self.time_limit, rng=rng)
            self.fallbacks += getattr(plan.stats, "status", None) == "fallback"
            act = plan_to_actions(plan, graph, cand, self.counts)
            parts["agent_obs"].append(env._agent_obs)
            parts["task_obs"].append(env._task_obs)
            parts["mask"].append(env._mask)
            parts["action"].append(act)
            _, rew, _, trunc, infos = env.step(dict(zip(ids, act.tolist(), strict=True)))
            first = infos[ids[0]]
            self.conflicts += sum(infos[a]["conflict"] for a in ids)
            parts["reward"].append(np.full(n_a, rew[ids[0]]))
            parts["done"].append(np.full(n_a, trunc[ids[0]]))
            parts["episode"].append(np.full(n_a, ep))
            parts["step"].append(np.full(n_a, step))
            parts["agent"].append(np.arange(n_a))
            step += 1
        self.episodes.append(
            {
                "scenario": scenario_key,
                "seed": seed,
                "steps": step,
                "metrics": first["metrics"],
                "return": first["return"],
            }
        )

    def arrays(self) -> dict[str, np.ndarray]:
        """The dataset's arrays (module docstring), rows of every episode in order."""
        return {
            k: (np.concatenate(v) if v else np.zeros((0,), dt)).astype(dt, copy=False)
            for (k, dt), v in zip(_ARRAYS.items(), self.parts.values(), strict=True)
        }


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
    from fcplan.scenario import Scenario

    ep = demo.episodes[episode]
    scenario = Scenario.from_dict(demo.metadata["scenarios"][ep["scenario"]])
    kwargs = dict(demo.metadata["env_kwargs"])
    if kwargs.get("graph_params") is not None:
        from fcplan.taskgraph import TaskGraphParams

        gp = dict(kwargs["graph_params"])
        if gp.get("tile_px") is not None:
            gp["tile_px"] = tuple(gp["tile_px"])
        kwargs["graph_params"] = TaskGraphParams(**gp)
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
    (final scores) and the mapping counts of the env rollout.
    """
    from fcplan.episode import run_episode

    out = []
    for sc in scenarios:
        for seed in seeds:
            demo = demonstrations(scheduler, [sc], [seed], env_kwargs=env_kwargs)
            ref = run_episode(sc, scheduler, seed=seed)
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
