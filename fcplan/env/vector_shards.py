"""Batched environments on several cores: ``B`` worlds split into shards stepped at once.

A batched env (:class:`fcplan.env.vector_motion.VectorMotionEnv`,
:class:`fcplan.env.vector_task.VectorTaskEnv`) steps all its worlds in one process, so on one
core. :class:`ShardedVectorEnv` splits the ``B`` worlds into ``processes`` shards (as even as
:func:`numpy.array_split` makes them): the first is a batched env in this process, each other
one a batched env in a worker process, and every step runs all of them at once. It is itself a
``gymnasium.vector.VectorEnv`` of all ``B`` worlds with the batched env's spaces, steps,
autoreset modes and infos: to the batched env what ``gymnasium.vector.AsyncVectorEnv`` is to
``SyncVectorEnv``, the same worlds on more cores.

World ``i`` is world ``i`` of one batched env of ``B`` worlds (and so the single env reset
with seed ``s + i``): ``reset``'s seeds are given to each world by the batched envs' rule
(:func:`fcplan.env.vector_base.reset_seeds`) and handed to its shard, and every world's random
streams are its own whichever process steps it (``tests/env/test_vector_shards.py`` compares
the two step for step, episode ends and autoresets included).

How data moves. The observations of every shard are written into arrays in shared memory (one
per observation key, ``(B, ...)``, each shard its rows), so the largest part of a step, the
motion level's crops, is copied once and never pickled; ``copy=True`` (the default, as
Gymnasium's) returns copies of them, ``copy=False`` the shared arrays themselves, which the
next ``step``/``reset`` overwrites. Actions, rewards, flags and infos go through one pipe per
worker. The actions are checked here before any shard steps (the batched envs' own rule), so a
bad action raises :class:`fcplan.errors.EnvError` and leaves every world as it was. A failure
in a shard's ``reset`` or ``step``, or a worker's exit, is reported with the shard's worlds and
message, and then the env refuses to go on (its shards may no longer be at the same step).

What it gains. Each step lasts as long as the slowest shard plus the serial work here (the
pipes, the infos, the copy of the observations), and the shards share the machine's memory
bandwidth: ``python bench/bench_vector_procs.py`` measures it against the same worlds in one
process and against independent processes (the bound of any such design), in the same rounds;
``bench/README.md`` has the project machine's figures. A learner that computes on the same
cores between steps takes from the same budget. The experts
(:meth:`fcplan.env.vector_task.VectorTaskEnv.expert_actions`,
:class:`fcplan.env.vector_expert.BatchPlanFollower`) read the worlds' graphs and simulator
objects, which are spread over the processes: :mod:`fcplan.env.vector_shard_experts` keeps one
in every shard (:meth:`ShardedVectorEnv.apply_shards`), so that each shard plans its own worlds.

Examples
--------
>>> import numpy as np
>>> from fcplan.env import vector_env
>>> env = vector_env("practice", mode="motion", num_envs=4, processes=2)
>>> env.shards
[(0, 2), (2, 4)]
>>> obs, infos = env.reset(seed=0)
>>> obs, rewards, terms, truncs, infos = env.step(np.zeros((4, 4), dtype=np.int64))
>>> obs["fov"].shape, rewards.shape
((4, 4, 7, 15, 15), (4,))
>>> env.close()
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import traceback
from collections.abc import Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from fcplan.env.vector_base import reset_rows, reset_seeds
from fcplan.env.vector_make import batched_env
from fcplan.errors import EnvError

__all__ = ["ShardedVectorEnv", "merge_infos", "shard_bounds"]


def shard_bounds(num: int, parts: int) -> list[tuple[int, int]]:
    """``(lo, hi)`` of each of ``parts`` shards of ``num`` worlds, split as evenly as
    :func:`numpy.array_split` splits.

    >>> shard_bounds(7, 3)
    [(0, 3), (3, 5), (5, 7)]
    """
    cuts = np.cumsum([0] + [len(p) for p in np.array_split(np.arange(num), parts)])
    return [(int(a), int(b)) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]


def _buffers(space: spaces.Dict, num: int, ctx: Any) -> dict[str, Any]:
    """One shared byte array per observation key, the size of ``num`` rows of it."""
    out = {}
    for key, sub in space.spaces.items():
        assert isinstance(sub, spaces.Box)  # (the batched envs' observations are boxes)
        n = num * int(np.prod(sub.shape)) * np.dtype(sub.dtype).itemsize
        out[key] = (ctx.RawArray("b", max(n, 1)), np.dtype(sub.dtype).str, tuple(sub.shape))
    return out


def _views(buffers: dict[str, Any], num: int) -> dict[str, np.ndarray]:
    """``(num, ...)`` numpy views of :func:`_buffers`' arrays."""
    return {
        key: np.frombuffer(raw, dtype=np.dtype(dt), count=num * int(np.prod(shape))).reshape(
            num, *shape
        )
        for key, (raw, dt, shape) in buffers.items()
    }


def _serve(env: Any, out: dict[str, np.ndarray], kept: dict[str, Any], command: str,
           arg: Any) -> Any:  # fmt: skip
    """Run one request on a shard's batched env (here or in a worker); the observations go
    into ``out``, the shard's rows of the shared arrays; ``"apply"`` runs ``fn(env, kept,
    *args)``, ``kept`` being the objects the shard keeps for its callers (its experts)."""
    if command in ("reset", "step"):
        obs, *rest = env.reset(**arg) if command == "reset" else env.step(arg)
        for k, v in out.items():
            v[...] = obs[k]
        return rest[0] if command == "reset" else rest
    if command == "call":
        name, args, kw = arg
        value = getattr(env, name)
        return value(*args, **kw) if callable(value) else value
    if command == "apply":
        fn, args = arg
        return fn(env, kept, *args)
    raise ValueError(f"unknown command {command!r}")


def _worker(conn: Any, make: tuple[Any, str, int, dict[str, Any]], rows: tuple[int, int],
            buffers: dict[str, Any], num: int) -> None:  # fmt: skip
    """A worker process: one batched env of the worlds ``rows`` of the batch, serving
    ``(command, argument)`` requests until ``close`` (module docstring)."""
    scenario, mode, n, kwargs = make
    lo, hi = rows
    try:
        env = batched_env(scenario, mode, n, **kwargs)
        conn.send(("ok", None))
    except Exception as exc:  # (reported to the caller, which raises it)
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        conn.close()
        return
    out = {k: v[lo:hi] for k, v in _views(buffers, num).items()}
    kept: dict[str, Any] = {}
    try:
        while True:
            command, arg = conn.recv()
            if command == "close":
                env.close()
                conn.send(("ok", None))
                break
            try:
                conn.send(("ok", _serve(env, out, kept, command, arg)))
            except Exception as exc:
                conn.send(("error", traceback.format_exception_only(type(exc), exc)[-1].strip()))
    except (KeyboardInterrupt, EOFError, BrokenPipeError):
        pass
    finally:
        conn.close()


def merge_infos(parts: Sequence[dict[str, Any]], sizes: Sequence[int]) -> dict[str, Any]:
    """One vector env's infos from its shards' (``parts[j]`` for ``sizes[j]`` worlds).

    A value with a leading axis of its shard's size is concatenated along it; a key that some
    shards lack gets their rows filled as Gymnasium fills a world without the key (``0``,
    ``False``, ``None``). Any other value becomes an object array with the shard's value at
    each of its worlds.

    Examples
    --------
    >>> m = merge_infos([{"x": np.array([1, 2])}, {}], [2, 1])
    >>> m["x"].tolist()
    [1, 2, 0]
    """
    keys: dict[str, None] = {}
    for part in parts:
        keys.update(dict.fromkeys(part))
    out = {}
    for key in keys:
        like = next(p[key] for p in parts if key in p)
        rows = []
        for part, n in zip(parts, sizes, strict=True):
            v = part.get(key)
            if isinstance(v, np.ndarray) and v.ndim and v.shape[0] == n:
                rows.append(v)
            elif v is None and isinstance(like, np.ndarray) and like.ndim:
                fill = None if like.dtype == object else 0
                rows.append(np.full((n, *like.shape[1:]), fill, dtype=like.dtype))
            else:
                filled = np.empty(n, dtype=object)
                filled[:] = [v] * n
                rows.append(filled)
        out[key] = np.concatenate(rows) if len({r.dtype for r in rows}) == 1 else (
            np.concatenate([r.astype(object) for r in rows])
        )  # fmt: skip
    return out


class ShardedVectorEnv(VectorEnv):
    """``num_envs`` worlds of a batched env split over ``processes`` processes, this one
    included (module docstring).

    Parameters
    ----------
    scenario : Scenario, str or int
        As :func:`fcplan.env.vector_env` (it must pickle: a name, path or
        :class:`fcplan.scenario.Scenario`).
    mode : {"motion", "task"}
        The level.
    num_envs : int
        Worlds ``B`` in all.
    processes : int
        Processes that step the worlds, ``1 <= processes <= num_envs``: this one (the first
        shard) and ``processes - 1`` worker processes.
    context : str, optional
        The :mod:`multiprocessing` start method of the workers (``"spawn"``, ``"forkserver"``,
        ``"fork"``; default the platform's).
    copy : bool
        Return copies of the observations (default), or views of the shared arrays that the
        next ``step``/``reset`` overwrites.
    **kwargs
        The level's options (``autoreset_mode``, ...), passed to every shard.
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(
        self,
        scenario: Any,
        mode: str = "motion",
        num_envs: int = 1,
        *,
        processes: int = 2,
        context: str | None = None,
        copy: bool = True,
        **kwargs: Any,
    ) -> None:
        self.num_envs, processes = int(num_envs), int(processes)
        if self.num_envs < 1:
            raise EnvError(f"num_envs: must be >= 1 (got {num_envs})")
        if not 1 <= processes <= self.num_envs:
            raise EnvError(f"processes: must be in 1..num_envs={self.num_envs} (got {processes})")
        self.mode, self.copy = mode, bool(copy)
        #: ``(lo, hi)``: the worlds of each shard (the first stepped in this process)
        self.shards = shard_bounds(self.num_envs, processes)
        self._sizes = [hi - lo for lo, hi in self.shards]
        self._broken: str | None = None
        self._fresh: dict[str, np.ndarray] | None = None
        self._closed = self._dead = False
        self._conns: list[Any] = []
        self._kept: dict[str, Any] = {}  # (the first shard's objects kept for "apply")
        self._procs: list[Any] = []
        ctx = mp.get_context(context)
        self._method = ctx.get_start_method()
        try:
            self._start(ctx, scenario, mode, kwargs)
        except BaseException:
            self._terminate()
            raise

    def _start(self, ctx: Any, scenario: Any, mode: str, kwargs: dict[str, Any]) -> None:
        """Make the first shard's env here (its spaces; a bad option fails here, before any
        process starts), the shared arrays, then the workers."""
        first = self.shards[0]
        #: the batched env of the first shard, stepped in this process (a bad ``mode`` or
        #: option fails here: :func:`fcplan.env.vector_make.batched_env`)
        self.local = batched_env(scenario, mode, first[1] - first[0], **kwargs)
        self.autoreset_mode = self.local.autoreset_mode
        self.metadata = {**self.metadata, "autoreset_mode": self.autoreset_mode}
        self.single_observation_space: spaces.Dict = self.local.single_observation_space
        self.single_action_space = self.local.single_action_space
        buffers = _buffers(self.single_observation_space, self.num_envs, ctx)
        for j, (lo, hi) in enumerate(self.shards[1:], start=1):
            parent, child = ctx.Pipe()
            proc = ctx.Process(
                target=_worker,
                args=(child, (scenario, mode, hi - lo, kwargs), (lo, hi), buffers, self.num_envs),
                name=f"fcplan-shard-{j}",
                daemon=True,
            )
            proc.start()
            child.close()
            self._conns.append(parent)
            self._procs.append(proc)
        for j in range(1, len(self.shards)):
            ok, value = self._receive(j)
            if not ok:
                raise EnvError(f"shard {j}: {value}")
        self._obs = _views(buffers, self.num_envs)
        self._local_out = {k: v[first[0] : first[1]] for k, v in self._obs.items()}
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

    # ------------------------------------------------------------------ requests
    def _receive(self, j: int) -> tuple[bool, Any]:
        """Worker ``j``'s (``j >= 1``) answer to the last request: (ok, value or message)."""
        try:
            status, value = self._conns[j - 1].recv()
        except (EOFError, ConnectionError, OSError):
            return self._exited(j)
        return status == "ok", value

    def _exited(self, j: int) -> tuple[bool, str]:
        """The failure of worker ``j``, whose process is gone."""
        self._dead = True
        proc = self._procs[j - 1]
        proc.join(timeout=1)
        value = f"the worker process exited (exit code {proc.exitcode})"
        if self._method != "fork":
            value += (
                f"; with the {self._method!r} start method, a script must make the env "
                "under `if __name__ == '__main__':`"
            )
        return False, value

    def _request(self, command: str, args: Sequence[Any], *, breaks: bool = True) -> list[Any]:
        """``(command, args[j])`` on every shard: sent to the workers, run here on the first
        shard meanwhile, then the workers' answers collected. A failure raises
        :class:`~fcplan.errors.EnvError` naming the first failed shard; after a failed
        ``reset`` or ``step`` (``breaks``), or a worker's exit, the env refuses to go on."""
        if self._closed:
            raise EnvError(f"{command}: the env is closed")
        if self._broken is not None:
            raise EnvError(f"{command}: a shard failed earlier ({self._broken}); make a new env")
        sent = []
        for conn, arg in zip(self._conns, args[1:], strict=True):
            try:
                conn.send((command, arg))
                sent.append(True)
            except (BrokenPipeError, ConnectionError, OSError):
                sent.append(False)
        results: list[tuple[bool, Any]] = []
        try:
            out = self._local_rows(command)
            results.append((True, _serve(self.local, out, self._kept, command, args[0])))
        except Exception as exc:
            results.append((False, traceback.format_exception_only(type(exc), exc)[-1].strip()))
        # (every worker's answer is read, failed or not: the pipes stay in step)
        for j, ok in enumerate(sent, start=1):
            results.append(self._receive(j) if ok else self._exited(j))
        for j, (ok, value) in enumerate(results):
            if not ok:
                lo, hi = self.shards[j]
                message = f"shard {j} (worlds {lo}..{hi - 1}): {value}"
                if breaks or self._dead:
                    self._broken = message
                raise EnvError(f"{command}: {message}")
        return [value for _, value in results]

    def _local_rows(self, command: str) -> dict[str, np.ndarray]:
        """Where the first shard's observations go: with ``copy``, straight into the rows of
        new arrays (written while the workers step; :meth:`_observation` adds the workers'
        rows), else into the shared arrays."""
        if not (self.copy and command in ("reset", "step")):
            self._fresh = None
            return self._local_out
        self._fresh = {k: np.empty_like(v) for k, v in self._obs.items()}
        lo, hi = self.shards[0]
        return {k: v[lo:hi] for k, v in self._fresh.items()}

    def _observation(self) -> dict[str, np.ndarray]:
        """The observations of the last ``reset``/``step`` (module docstring: ``copy``)."""
        if self._fresh is None:
            return dict(self._obs)
        hi = self.shards[0][1]
        for k, v in self._fresh.items():
            v[hi:] = self._obs[k][hi:]
        return self._fresh

    # ------------------------------------------------------------------ the VectorEnv API
    def reset(
        self, *, seed: int | list | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start episodes as the batched env does (``seed`` by
        :func:`fcplan.env.vector_base.reset_seeds`, ``options["reset_mask"]``), each shard its
        own worlds' with their seeds."""
        rows = reset_rows(self.num_envs, seed, options)
        seeds = reset_seeds(self.num_envs, rows, seed)
        mask = np.zeros(self.num_envs, dtype=bool)
        mask[rows] = True
        of_world: dict[int, Any] = dict(zip(rows.tolist(), seeds, strict=True))
        args = []
        for lo, hi in self.shards:
            opts = {**(options or {}), "reset_mask": mask[lo:hi]}
            mine = [of_world[b] for b in range(lo, hi) if mask[b]]
            args.append({"seed": mine, "options": opts})
        infos = self._request("reset", args)
        return self._observation(), merge_infos(infos, self._sizes)

    def step(
        self, actions: Any
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One step of every world (the batched env's ``step``), the shards in parallel."""
        act = self.local.check_actions(actions, self.num_envs)  # (the batched envs' rule)
        answers = self._request("step", [act[lo:hi] for lo, hi in self.shards])
        rewards = np.concatenate([a[0] for a in answers])
        terms = np.concatenate([a[1] for a in answers])
        truncs = np.concatenate([a[2] for a in answers])
        infos = merge_infos([a[3] for a in answers], self._sizes)
        return self._observation(), rewards, terms, truncs, infos

    def call_shards(self, name: str, *args: Any, **kwargs: Any) -> list[Any]:
        """``getattr(shard_env, name)(*args, **kwargs)`` (or the attribute) of every shard's
        batched env, in shard order."""
        return self._request("call", [(name, args, kwargs)] * len(self.shards), breaks=False)

    def apply_shards(self, fn: Any, args: Sequence[tuple[Any, ...]]) -> list[Any]:
        """``fn(shard_env, kept, *args[j])`` on every shard ``j`` at once, in shard order: ``fn``
        a module-level function (it is pickled to the workers), ``kept`` a dict the shard keeps
        between calls (:mod:`fcplan.env.vector_shard_experts` keeps its experts there). A
        failure raises :class:`~fcplan.errors.EnvError` and leaves the env usable."""
        if len(args) != len(self.shards):
            raise EnvError(
                f"apply_shards: need {len(self.shards)} argument tuples (got {len(args)})"
            )
        return self._request("apply", [(fn, tuple(a)) for a in args], breaks=False)

    def state(self) -> np.ndarray:
        """The global state of every world (the motion level's ``state()``, ``(B, 8, nc, nc)``)."""
        if self.mode != "motion":
            raise EnvError("state: only the motion level has a global state")
        return np.concatenate(self.call_shards("state"))

    def close_extras(self, **kwargs: Any) -> None:
        """Stop the workers (and wait for them) and close the first shard's env."""
        if self._closed:
            return
        self._closed = True
        for conn in self._conns:
            with contextlib.suppress(BrokenPipeError, OSError):
                conn.send(("close", None))
        for conn in self._conns:
            try:
                if conn.poll(10):
                    conn.recv()
            except (EOFError, OSError):
                pass
        self._terminate()
        if getattr(self, "local", None) is not None:
            self.local.close()

    def __reduce_ex__(self, protocol: Any) -> Any:
        """Refuse ``pickle``, ``copy.copy`` and ``copy.deepcopy`` before anything is copied:
        the worlds live in worker processes, and a copy of the pipes to them would close the
        original's when collected (``os.close`` on the same descriptors)."""
        raise EnvError(
            "a ShardedVectorEnv cannot be copied or pickled: its worlds live in worker "
            "processes; copy a one-process env (processes=1) or make a new one"
        )

    def _terminate(self) -> None:
        for proc in self._procs:
            proc.join(timeout=5)
            if proc.is_alive():
                proc.terminate()
                proc.join(timeout=5)
        for conn in self._conns:
            conn.close()
        self._conns, self._procs = [], []
        self._closed = True

    def __del__(self) -> None:
        try:
            if not getattr(self, "_closed", True):
                self.close()
        except Exception:
            pass
