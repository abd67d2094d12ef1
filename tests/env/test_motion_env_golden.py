"""Golden rollouts of the motion-level environments, so speed work cannot change what they return.

Every run below plays the motion env (:class:`fcplan.env.motion.MotionEnv` on a shortened shipped
scenario) or a preset (``base``, ``cmplx1``, ``cmplx2``) with random legal actions, drawn from
each agent's ``action_mask`` by a seeded Generator, until its step cap; when an episode ends
within the cap the env is reset without a seed and play goes on. Every array the env hands out is
digested at every step: the observations of every agent (``fov``, ``agent``, ``action_mask``) and
the order of their keys, ``state()``, the rewards, terminations, truncations, the live agents, and
the infos (final metrics included), as well as the ``reset`` observations and infos. Each stream
goes into a SHA-256 in the two forms of ``tests/test_golden.py``:

* ``exact``: the raw little-endian bytes (floats bit for bit), compared only on the platform the
  golden file was written on;
* ``portable``: floats quantised to 1e-6 (non-finite values as sentinels), integers as int64,
  compared everywhere.

Regenerate the file only after an intended behaviour change (and say so in the commit)::

    python tests/env/test_motion_env_golden.py --regenerate
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
if __name__ == "__main__":  # (run as a script: make ``tests`` and ``fcplan`` importable)
    sys.path.insert(0, str(ROOT))

from fcplan.env.motion import MotionEnv, parallel_env  # noqa: E402
from tests.conftest import scenario_with  # noqa: E402
from tests.golden import GoldenFile  # noqa: E402

GOLDEN = ROOT / "tests" / "data" / "golden_motion_env.json"

# (run id, env name, env keyword arguments, episode seed, step cap)
RUNS: list[tuple[str, str, dict, int, int]] = []
for _name, _dur in (("practice", 20.0), ("1", 40.0), ("24", 60.0), ("open_world_example", 25.0)):
    for _seed in (0, 1):
        RUNS.append((f"motion-{_name}-{_seed}", _name, {"duration_s": _dur}, _seed, 700))
RUNS.append(
    (
        "motion-24-shaped-2",
        "24",
        {
            "duration_s": 30.0,
            "idle_rule": True,
            "sense_bonus": 0.5,
            "prune_bonus": 2.0,
            "dump_cost": 0.25,
            "cell_px": 30,
            "view": 9,
            "stale_s": 5.0,
        },
        2,
        400,
    )
)
for _seed in (0, 1):
    RUNS.append((f"base-{_seed}", "base", {"max_steps": 150}, _seed, 400))
    RUNS.append((f"cmplx1-{_seed}", "cmplx1", {"max_steps": 80}, _seed, 200))
    RUNS.append((f"cmplx2-{_seed}", "cmplx2", {"max_steps": 80}, _seed, 200))
RUNS += [
    (
        "base-variant-3",
        "base",
        {
            "max_steps": 100,
            "reward": "rf1",
            "termination_reward": True,
            "water_dump": False,
            "no_op": False,
            "vision": 2,
            "world_size": 12,
            "n_fires": 20,
        },
        3,
        250,
    ),
    ("base-stationary-4", "base", {"stationary_fire": True, "center_init": True}, 4, 300),
    ("cmplx1-change-5", "cmplx1", {"max_steps": 60, "rf1_mode": "change"}, 5, 120),
    ("cmplx2-rf3-6", "cmplx2", {"max_steps": 60, "reward": "rf3", "n_regions": 3}, 6, 120),
    ("cmplx2-rf2-7", "cmplx2", {"max_steps": 60, "reward": "rf2", "world_size": 60}, 7, 120),
]


def make_env(name: str, kwargs: dict):
    """The env of one run: a preset, or MotionEnv on a shipped scenario with ``duration_s``."""
    if name in ("base", "cmplx1", "cmplx2"):
        return parallel_env(preset=name, **kwargs)
    kw = dict(kwargs)
    sc = scenario_with(name, duration_s=kw.pop("duration_s"))
    return MotionEnv(sc, **kw)


class Streams:
    """Incremental exact and portable SHA-256 digests per named stream."""

    def __init__(self) -> None:
        self.h: dict[str, tuple] = {}

    def add(self, name: str, value) -> None:
        """Hash one value (array, number, bool or a tuple of strings) into stream ``name``."""
        if name not in self.h:
            self.h[name] = (hashlib.sha256(), hashlib.sha256())
        exact, port = self.h[name]
        if isinstance(value, tuple) and all(isinstance(v, str) for v in value):
            data = ("\x1f".join(value) + "\x1e").encode()
            exact.update(data)
            port.update(data)
            return
        a = np.array(value)  # a copy in its own dtype
        head = np.array([a.ndim, *a.shape], dtype="<i8").tobytes()
        if a.dtype.kind == "f":
            exact.update(a.dtype.str.encode() + head + a.astype("<f8").tobytes())
            flat = a.astype(np.float64).ravel()
            fin = np.isfinite(flat)
            q = np.rint(np.where(fin, flat, 0.0) * 1e6).astype("<i8")
            q[np.isposinf(flat)] = np.iinfo(np.int64).max
            q[np.isneginf(flat)] = np.iinfo(np.int64).min
            q[np.isnan(flat)] = np.iinfo(np.int64).min + 1
            port.update(b"f" + head + q.tobytes())
        elif a.dtype.kind in "iub":
            exact.update(
                a.dtype.str.encode() + head + a.astype(a.dtype.newbyteorder("<")).tobytes()
            )
            port.update(b"i" + head + a.astype("<i8").tobytes())
        else:
            raise TypeError(f"cannot digest dtype {a.dtype} in {name}")

    def add_tree(self, name: str, value) -> None:
        """Hash a nested dict/list of numbers, bools, strings and None: keys and strings into
        ``name.keys``, numbers into ``name.values`` (as float64), in iteration order."""
        keys: list[str] = []
        nums: list[float] = []

        def walk(v, path: str) -> None:
            if isinstance(v, dict):
                keys.append(f"{path}{{{len(v)}")
                for k, x in v.items():
                    walk(x, f"{path}/{k}")
            elif isinstance(v, (list, tuple)):
                keys.append(f"{path}[{len(v)}")
                for j, x in enumerate(v):
                    walk(x, f"{path}/{j}")
            elif v is None or isinstance(v, str):
                keys.append(f"{path}={v!r}")
            elif isinstance(v, (bool, np.bool_)):
                keys.append(f"{path}:{type(v).__name__}")
                nums.append(float(v))
            else:
                keys.append(f"{path}:{type(v).__name__}")
                nums.append(float(v))

        walk(value, "")
        self.add(f"{name}.keys", tuple(keys))
        self.add(f"{name}.values", np.array(nums, dtype=np.float64))

    def result(self) -> dict[str, dict[str, str]]:
        """``{"exact": {name: hex}, "portable": {name: hex}}`` (16 hex digits each)."""
        out: dict[str, dict[str, str]] = {"exact": {}, "portable": {}}
        for name in sorted(self.h):
            exact, port = self.h[name]
            out["exact"][name] = exact.hexdigest()[:16]
            out["portable"][name] = port.hexdigest()[:16]
        return out


def _digest_obs(d: Streams, prefix: str, obs: dict) -> None:
    d.add(f"{prefix}.agents", tuple(obs))
    for a, o in obs.items():
        d.add(f"{prefix}.keys", tuple(o))
        for key, arr in o.items():
            assert isinstance(arr, np.ndarray), f"{prefix} {a} {key}: not an array"
            d.add(f"{prefix}.{key}", arr)


def run_digest(run) -> dict[str, dict[str, str]]:
    """Play one run and digest everything the env returned."""
    _, name, kwargs, seed, cap = run
    env = make_env(name, kwargs)
    rng = np.random.default_rng(seed + 1000)
    d = Streams()
    obs, infos = env.reset(seed=seed)
    _digest_obs(d, "reset.obs", obs)
    d.add_tree("reset.infos", infos)
    d.add("state", env.state())
    for _ in range(cap):
        if not env.agents:
            obs, infos = env.reset()
            _digest_obs(d, "reset.obs", obs)
            d.add_tree("reset.infos", infos)
            d.add("state", env.state())
        actions = {}
        for a in env.agents:
            legal = np.flatnonzero(obs[a]["action_mask"])
            actions[a] = int(legal[rng.integers(legal.size)])
        obs, rewards, terms, truncs, infos = env.step(actions)
        _digest_obs(d, "obs", obs)
        d.add_tree("rewards", rewards)
        d.add_tree("terminations", terms)
        d.add_tree("truncations", truncs)
        d.add_tree("infos", infos)
        d.add("live_agents", tuple(env.agents) or ("",))
        d.add("state", env.state())
    env.close()
    return d.result()


GOLDEN_FILE = GoldenFile(GOLDEN, RUNS, run_digest)


@pytest.mark.parametrize("run", RUNS, ids=[r[0] for r in RUNS])
def test_motion_env_golden(run):
    """A run reproduces the recorded digests of every observation, state, reward, flag and info
    of every step."""
    GOLDEN_FILE.check(run)


def test_motion_golden_file_covers_every_run():
    """The golden file holds exactly the runs this module plays."""
    GOLDEN_FILE.check_covers_runs()


if __name__ == "__main__":
    GOLDEN_FILE.main(sys.argv[1:], "tests/env/test_motion_env_golden.py")
