"""A checkpoint folder of a demonstrations run: episodes written as they finish, so that an
interrupted recording (Ctrl-C, a crash, a killed machine) resumes where it stopped.

:func:`fcplan.env.demonstrations.demonstrations` with ``checkpoint=folder`` writes every episode
it plays into the folder as soon as its unit finishes, and a call with the same folder plays
only the (scenario, seed) episodes not in it: the dataset is the one an uninterrupted call gives
(``tests/env/test_demo_checkpoint.py``). More seeds or scenarios than the first call had may be
asked for (the stored ones are reused); other scheduler settings, env arguments, time limit or
scenario content are refused in one line, naming what differs, since the stored episodes would
then not be episodes of this call. One run at a time holds a folder (an exclusive ``flock``,
the lock of a sweep's results folder): a second run started on it meanwhile is refused.

Layout
    ``run.json``: ``{"format": "fcplan-demonstrations-checkpoint", "version": 1, "run":
    {scheduler, scheduler_settings, time_limit, env_kwargs}, "scenarios": {key: document}}``.

    ``episodes/<scenario hash>-<seed>.npz``: one :class:`~fcplan.env.demo_episodes.EpisodeRecord`,
    its arrays as ``.npy`` entries (``obs.agents``, ``obs.tasks``, ``obs.action_mask``,
    ``actions``, ``rewards``, ``ticks``, ``illegal``, ``conflict``) and its scenario key, seed,
    source, metrics, fallbacks and mapping counts as JSON (``meta``). Written under a temporary
    name and renamed, so a file is either whole or absent.

An episode file is outside data when read back: no pickle, and every entry's declared dtype and
shape is checked against what the run dictates (the scenario's agents, the env's ``k`` and
feature counts, a length that fits the entry's bytes) before its bytes are read. A damaged or
foreign file is reported in one line (a :class:`UserWarning` naming the file and what is wrong)
and its episode played again.

Examples
--------
>>> import tempfile
>>> from fcplan.env.demonstrations import demonstrations
>>> folder = tempfile.mkdtemp()
>>> kw = {"k": 4, "max_steps": 3}
>>> first = demonstrations("greedy", ["practice"], [0], env_kwargs=kw, checkpoint=folder,
...                        progress=False)
>>> again = demonstrations("greedy", ["practice"], [0, 1], env_kwargs=kw, checkpoint=folder,
...                        progress=False)  # plays seed 1 only
>>> again.episodes[0] == first.episodes[0], again.n_episodes
(True, 2)
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import warnings
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.env.demo_episodes import OBS_KEYS, EpisodeRecord
from fcplan.env.task_candidates import AGENT_FEATURES, TASK_FEATURES
from fcplan.errors import FcplanError

__all__ = ["DemoCheckpoint", "CHECKPOINT_FORMAT", "CHECKPOINT_VERSION"]

CHECKPOINT_FORMAT = "fcplan-demonstrations-checkpoint"
CHECKPOINT_VERSION = 1
#: longest episode a stored file may declare (steps)
_MAX_STEPS = 10**6
_META_BYTES = 1 << 20


class _DamagedError(Exception):
    """An episode file that cannot be used (the message says why)."""


class DemoCheckpoint:
    """The checkpoint folder of one demonstrations run (module docstring).

    Parameters
    ----------
    folder : str or Path
        Created if missing.
    run : dict
        The run's identity (scheduler, settings, time limit, env arguments), JSON.
    scenarios : dict of str -> dict
        The run's scenario documents by dataset key.

    Raises
    ------
    FcplanError
        On entering: another process is writing into the folder, or it belongs to another run
        (what differs is named), or it is not a checkpoint.
    """

    def __init__(self, folder: str | os.PathLike[str], run: dict, scenarios: dict) -> None:
        self.folder = Path(folder)
        self.episodes = self.folder / "episodes"
        self.run = json.loads(json.dumps(run))  # (as it reads back: tuples become lists ...)
        self.scenarios = scenarios
        self._held = contextlib.ExitStack()

    def __enter__(self) -> DemoCheckpoint:
        """Hold the folder for this run (one run at a time: ``flock``, as a sweep holds its
        results folder), then check or write its ``run.json``."""
        from fcplan.experiments.results import hold_folder

        self.episodes.mkdir(parents=True, exist_ok=True)
        busy = (f"checkpoint {self.folder}: another demonstrations run is writing into it; wait "
                "for it to finish (then re-run to resume) or use another folder")  # fmt: skip
        self._held.enter_context(hold_folder(self.folder, lambda: FcplanError(busy)))
        try:
            self._check_run()
        except BaseException:
            self._held.close()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        self._held.close()

    def _check_run(self) -> None:
        run, scenarios = self.run, self.scenarios
        path = self.folder / "run.json"
        stored_scenarios: dict[str, Any] = {}
        if path.exists():
            old = self._read_run(path)
            for name, value in run.items():
                if old["run"].get(name) != value:
                    raise FcplanError(
                        f"checkpoint {self.folder}: made by a run with {name} "
                        f"{old['run'].get(name)!r:.80}, this one has {value!r:.80}; use another "
                        "folder"
                    )
            stored_scenarios = old["scenarios"]
            for key, doc in scenarios.items():
                if key in stored_scenarios and stored_scenarios[key] != doc:
                    raise FcplanError(
                        f"checkpoint {self.folder}: scenario {key!r} differs from the one its "
                        "episodes were recorded on; use another folder"
                    )
        doc = {"format": CHECKPOINT_FORMAT, "version": CHECKPOINT_VERSION, "run": run,
               "scenarios": {**stored_scenarios, **scenarios}}  # fmt: skip
        _write_atomic(path, json.dumps(doc, indent=1, sort_keys=True).encode())

    def _read_run(self, path: Path) -> dict:
        try:
            doc = json.loads(path.read_bytes()[:_META_BYTES])
        except (OSError, ValueError) as exc:
            raise FcplanError(f"{path}: not a demonstrations checkpoint ({exc})") from None
        ok = (isinstance(doc, dict) and doc.get("format") == CHECKPOINT_FORMAT
              and isinstance(doc.get("run"), dict) and isinstance(doc.get("scenarios"), dict))  # fmt: skip
        if not ok or doc.get("version") != CHECKPOINT_VERSION:
            raise FcplanError(
                f"{path}: not a demonstrations checkpoint of version {CHECKPOINT_VERSION}"
            )
        return doc

    def path(self, key: str, seed: int) -> Path:
        """The file of episode (``key``, ``seed``)."""
        h = hashlib.sha256(key.encode()).hexdigest()[:12]
        return self.episodes / f"{h}-{int(seed)}.npz"

    def save(self, rec: EpisodeRecord) -> None:
        """Write ``rec`` (whole or not at all)."""
        path = self.path(rec.scenario, rec.seed)
        meta = {"scenario": rec.scenario, "seed": int(rec.seed), "source": rec.source,
                "metrics": rec.metrics, "fallbacks": int(rec.fallbacks),
                "counts": {k: int(v) for k, v in rec.counts.items()}}  # fmt: skip
        arrays: dict[str, Any] = {f"obs.{k}": rec.observations[k] for k in OBS_KEYS}
        arrays.update(actions=rec.actions, rewards=rec.rewards, ticks=rec.ticks,
                      illegal=rec.illegal, conflict=rec.conflict)  # fmt: skip
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "wb") as f:
            np.savez(f, meta=np.array(json.dumps(meta)), **arrays)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)

    def load(self, key: str, seed: int, n_agents: int, k: int) -> EpisodeRecord | None:
        """The stored episode (``key``, ``seed``) of ``n_agents`` agents and ``k`` candidates, or
        None when there is none or it is damaged (reported: module docstring)."""
        path = self.path(key, seed)
        if not path.exists():
            return None
        try:
            return _read_episode(path, key, int(seed), n_agents, k)
        except (_DamagedError, OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            warnings.warn(f"{path}: {exc}; its episode is played again", stacklevel=2)
            return None


def _write_atomic(path: Path, data: bytes) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _read_episode(path: Path, key: str, seed: int, n_agents: int, k: int) -> EpisodeRecord:
    """The episode of ``path`` after the checks of the module docstring."""
    a, fa, ft = n_agents, len(AGENT_FEATURES), len(TASK_FEATURES)
    with zipfile.ZipFile(path) as zf:
        names = {n.removesuffix(".npy") for n in zf.namelist()}
        want = {"meta", "actions", "rewards", "ticks", "illegal", "conflict"}
        want |= {f"obs.{o}" for o in OBS_KEYS}
        if names != want:
            raise _DamagedError(f"entries {sorted(names)!r:.100}, expected {sorted(want)}")
        meta = json.loads(str(_entry(zf, "meta", np.dtype("<U1"), None, unicode=True)))
        actions = _entry(zf, "actions", np.dtype(np.int64), (None, a))
        t = actions.shape[0]
        arrays = {
            "rewards": _entry(zf, "rewards", np.dtype(np.float64), (t,)),
            "ticks": _entry(zf, "ticks", np.dtype(np.int64), (t + 1,)),
            "illegal": _entry(zf, "illegal", np.dtype(bool), (t, a)),
            "conflict": _entry(zf, "conflict", np.dtype(bool), (t, a)),
        }
        obs = {
            "agents": _entry(zf, "obs.agents", np.dtype(np.float32), (t + 1, a, fa)),
            "tasks": _entry(zf, "obs.tasks", np.dtype(np.float32), (t + 1, a, k, ft)),
            "action_mask": _entry(zf, "obs.action_mask", np.dtype(np.int8), (t + 1, a, k + 1)),
        }
    ok = (isinstance(meta, dict) and meta.get("scenario") == key and meta.get("seed") == seed
          and isinstance(meta.get("source"), str) and isinstance(meta.get("metrics"), dict)
          and isinstance(meta.get("fallbacks"), int) and isinstance(meta.get("counts"), dict)
          and all(isinstance(v, int) for v in meta["counts"].values()))  # fmt: skip
    if not ok:
        raise _DamagedError(f"its metadata is not episode ({key!r}, seed {seed})'s")
    return EpisodeRecord(observations=obs, actions=actions, scenario=key, seed=seed,
                         source=meta["source"], metrics=meta["metrics"],
                         fallbacks=meta["fallbacks"], counts=meta["counts"], **arrays)  # fmt: skip


def _entry(
    zf: zipfile.ZipFile,
    name: str,
    dtype: np.dtype,
    shape: tuple[int | None, ...] | None,
    *,
    unicode: bool = False,
) -> np.ndarray:
    """Entry ``name`` if its declared dtype is ``dtype`` (any width for a ``unicode`` string)
    and its shape ``shape`` (None: any length along that axis, up to the bound; a 0-d string
    for ``shape`` None), its bytes exactly what it declares; only then read."""
    info = zf.getinfo(name + ".npy")
    if info.flag_bits & 0x1 or info.compress_type != zipfile.ZIP_STORED:
        raise _DamagedError(
            f"entry {name!r} is encrypted or compressed (checkpoints store entries)"
        )
    with zf.open(info) as f:
        version = np.lib.format.read_magic(f)
        if version not in ((1, 0), (2, 0)):
            raise _DamagedError(f"entry {name!r} has .npy version {version}")
        read = np.lib.format.read_array_header_1_0
        if version == (2, 0):
            read = np.lib.format.read_array_header_2_0
        declared, fortran, got = read(f)
        same = got.kind == "U" if unicode else got == dtype
        fits = declared == () if shape is None else (
            len(declared) == len(shape)
            and all(w is None or d == w for d, w in zip(declared, shape, strict=True)))  # fmt: skip
        nbytes = math.prod(declared) * got.itemsize
        if not (same and fits) or fortran or got.hasobject or declared[:1] > (_MAX_STEPS + 1,):
            raise _DamagedError(f"entry {name!r} is declared {got}{list(declared)}")
        if nbytes != info.file_size - f.tell() or (unicode and nbytes > _META_BYTES):
            raise _DamagedError(f"entry {name!r} holds {info.file_size - f.tell()} bytes of data, "
                           f"not the {nbytes} it declares")  # fmt: skip
        data = f.read(nbytes)
    return np.frombuffer(data, dtype=got).reshape(declared).copy()
