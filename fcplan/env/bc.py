"""Behaviour cloning baseline: a conditional-logit policy over candidate tasks, in plain numpy.

The learner loop of the task-level env in its smallest form: fit a policy to scheduler
demonstrations (:mod:`fcplan.env.demonstrations`) and play it.

Model (multinomial logistic regression over the candidates, shared by all agents)
    Candidate slot ``j`` of an agent gets the logit ``w . phi_j`` with
    ``phi_j = [f_j, can_sense * f_j, can_act * f_j]`` (``f_j`` the slot's row of the task-feature
    table, so each role weighs the features its own way); the no-op gets ``v . [s, 1]`` (``s``
    the agent's own-state vector). Masked slots get ``-inf``; a masked softmax gives the action
    probabilities. Training minimises the mean negative log-likelihood of the expert's actions
    plus ``l2 / 2 |w|^2`` with L-BFGS (scipy): convex, deterministic, a second or so on a few
    thousand agent-steps. Playing takes the most likely legal action.

DAgger (:func:`dagger`)
    Behaviour cloning only sees the states the expert visits; :func:`dagger` also rolls out the
    current policy, labels every state it visits with the scheduler's action (its plan mapped to
    actions as in the demonstrations), adds them to the data and refits. On #24 (4 training
    seeds, 5 held-out seeds, whole episodes) 1-3 rounds took the held-out mean final score from
    194 (plain BC) to 213-220; milp itself scores 260 through the env.

Examples
--------
>>> from fcplan.env.demonstrations import demonstrations
>>> from fcplan.env.bc import fit_bc, evaluate
>>> demo = demonstrations("greedy", ["practice"], [0], env_kwargs={"k": 4, "max_steps": 20})
>>> policy = fit_bc(demo)
>>> scores = evaluate(policy, "practice", [1], env_kwargs={"k": 4, "max_steps": 20})
>>> scores.shape
(1,)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from fcplan.mission import ScenarioLike
    from fcplan.scheduling import Scheduler

__all__ = [
    "BCPolicy",
    "fit_bc",
    "dagger",
    "random_policy",
    "evaluate",
    "rollout",
    "scheduler_scores",
]

#: A policy maps ``(agent_obs (A, S), task_obs (A, k, F), mask (A, k + 1))`` to ``(A,)`` actions.
Policy = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]

_S_SENSE, _S_ACT = 5, 6  # columns of can_sense / can_act in the own-state vector


def _phi(agent_obs: np.ndarray, task_obs: np.ndarray) -> np.ndarray:
    """(N, k, 3F) role-crossed candidate features."""
    sense = agent_obs[:, _S_SENSE, None, None]
    act = agent_obs[:, _S_ACT, None, None]
    f = task_obs.astype(np.float64)
    return np.concatenate([f, sense * f, act * f], axis=2)


def _noop_x(agent_obs: np.ndarray) -> np.ndarray:
    return np.concatenate([agent_obs.astype(np.float64), np.ones((len(agent_obs), 1))], axis=1)


@dataclass(frozen=True)
class BCPolicy:
    """A fitted conditional-logit policy (see the module docstring).

    Attributes
    ----------
    w_task : ndarray, (3F,) float64
    w_noop : ndarray, (S + 1,) float64
    """

    w_task: np.ndarray
    w_noop: np.ndarray

    def logits(self, agent_obs: np.ndarray, task_obs: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """(A, k + 1) masked logits (``-inf`` where illegal)."""
        z = np.concatenate(
            [_phi(agent_obs, task_obs) @ self.w_task, (_noop_x(agent_obs) @ self.w_noop)[:, None]],
            axis=1,
        )
        return np.where(mask.astype(bool), z, -np.inf)

    def __call__(self, agent_obs: np.ndarray, task_obs: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """(A,) most likely legal action of every agent (ties: lower slot)."""
        return np.argmax(self.logits(agent_obs, task_obs, mask), axis=1)


def fit_bc(demo: Any, *, l2: float = 1e-3, max_iter: int = 300) -> BCPolicy:
    """Fit :class:`BCPolicy` to a :class:`~fcplan.env.demonstrations.Demonstrations` dataset (or
    anything with its ``agent_obs``, ``task_obs``, ``mask`` and ``action`` arrays)."""
    from scipy.optimize import minimize

    phi = _phi(demo.agent_obs, demo.task_obs)  # (N, k, P)
    x0 = _noop_x(demo.agent_obs)  # (N, Q)
    mask = demo.mask.astype(bool)
    y = demo.action.astype(np.int64)
    n, k, p = phi.shape
    q = x0.shape[1]
    onehot = np.zeros((n, k + 1))
    onehot[np.arange(n), y] = 1.0

    def loss(theta: np.ndarray) -> tuple[float, np.ndarray]:
        w, v = theta[:p], theta[p:]
        z = np.concatenate([phi @ w, (x0 @ v)[:, None]], axis=1)
        z = np.where(mask, z, -np.inf)
        zmax = z.max(axis=1, keepdims=True)
        e = np.exp(z - zmax)
        s = e.sum(axis=1, keepdims=True)
        logp = z[np.arange(n), y] - zmax[:, 0] - np.log(s[:, 0])
        g = (e / s - onehot) / n  # d loss / d z
        grad = np.concatenate([np.einsum("nk,nkp->p", g[:, :k], phi), g[:, k] @ x0])
        return -logp.mean() + 0.5 * l2 * theta @ theta, grad + l2 * theta

    res = minimize(
        loss, np.zeros(p + q), jac=True, method="L-BFGS-B", options={"maxiter": max_iter}
    )
    return BCPolicy(w_task=res.x[:p].copy(), w_noop=res.x[p:].copy())


def dagger(
    scheduler: str | Scheduler,
    scenarios: Sequence[ScenarioLike],
    seeds: Sequence[int],
    *,
    rounds: int = 2,
    env_kwargs: dict[str, Any] | None = None,
    time_limit: float | None = None,
    l2: float = 1e-3,
) -> BCPolicy:
    """DAgger with ``scheduler`` as the expert: BC on its demonstrations, then ``rounds`` times:
    play the policy on every (scenario, seed), label the visited states with the scheduler's
    actions, aggregate and refit. Returns the last policy."""
    from types import SimpleNamespace

    from fcplan.env.demonstrations import _scheduler, demonstrations
    from fcplan.env.task import TaskEnv
    from fcplan.env.task_actions import plan_to_actions
    from fcplan.scheduling import solve

    demo = demonstrations(scheduler, scenarios, seeds, env_kwargs=env_kwargs, time_limit=time_limit)
    data = {k: [demo.arrays[k]] for k in ("agent_obs", "task_obs", "mask", "action")}
    policy = fit_bc(demo, l2=l2)
    expert = _scheduler(scheduler, True)[0]  # (the demonstrations' expert: deterministic mode)
    for _ in range(int(rounds)):
        for sc in scenarios:
            env = TaskEnv(sc, **(env_kwargs or {}))
            for seed in seeds:
                env.reset(seed=seed)
                rng = env.world.controller_rng
                while env.agents:
                    graph, cand = env.graph, env.candidates
                    assert graph is not None and cand is not None  # (built by reset and step)
                    plan = solve(expert, graph, time_limit=time_limit, rng=rng)
                    data["action"].append(plan_to_actions(plan, graph, cand))
                    data["agent_obs"].append(env._agent_obs)
                    data["task_obs"].append(env._task_obs)
                    data["mask"].append(env._mask)
                    act = policy(env._agent_obs, env._task_obs, env._mask)
                    env.step(dict(zip(env.possible_agents, act.tolist(), strict=True)))
        policy = fit_bc(SimpleNamespace(**{k: np.concatenate(v) for k, v in data.items()}), l2=l2)
    return policy


def random_policy(rng: np.random.Generator) -> Policy:
    """A policy drawing a uniformly random legal action per agent from ``rng``."""

    def act(agent_obs: np.ndarray, task_obs: np.ndarray, mask: np.ndarray) -> np.ndarray:
        u = rng.random(mask.shape) * mask
        return np.argmax(u, axis=1)

    return act


def rollout(
    policy: Policy, scenario: ScenarioLike, seed: int, *, env_kwargs: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Play one episode of ``policy`` in the task env; return the final ``infos`` of agent 0."""
    from fcplan.env.task import TaskEnv

    env = TaskEnv(scenario, **(env_kwargs or {}))
    env.reset(seed=seed)
    ids = env.possible_agents
    infos: dict[str, Any] = {}
    while env.agents:
        act = policy(env._agent_obs, env._task_obs, env._mask)
        _, _, _, _, infos = env.step(dict(zip(ids, np.asarray(act).tolist(), strict=True)))
    return infos[ids[0]]


def evaluate(
    policy: Policy,
    scenario: ScenarioLike,
    seeds: Sequence[int],
    *,
    env_kwargs: dict[str, Any] | None = None,
    metric: str = "final_score",
) -> np.ndarray:
    """(len(seeds),) manual ``metric`` of ``policy`` on ``scenario`` for each seed."""
    return np.array(
        [
            rollout(policy, scenario, s, env_kwargs=env_kwargs)["metrics"]["manual"][metric]
            for s in seeds
        ],
        dtype=np.float64,
    )


def scheduler_scores(
    scheduler: str | Scheduler,
    scenario: ScenarioLike,
    seeds: Sequence[int],
    *,
    env_kwargs: dict[str, Any] | None = None,
    metric: str = "final_score",
) -> np.ndarray:
    """(len(seeds),) manual ``metric`` of a scheduler played through the task env (its plans
    mapped to actions as in :func:`fcplan.env.demonstrations.demonstrations`)."""
    from fcplan.env.demonstrations import demonstrations

    demo = demonstrations(scheduler, [scenario], seeds, env_kwargs=env_kwargs)
    return np.array([e["metrics"]["manual"][metric] for e in demo.episodes], dtype=np.float64)
