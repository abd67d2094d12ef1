"""Golden-digest machinery shared by the golden tests (simulator traces, task env, motion env).

A golden file holds, per run, SHA-256 digests of every stream of values the run produced, in two
forms: ``exact`` (raw little-endian bytes, floats bit for bit; compared only on the platform the
file was written on, because libm and SIMD builds may round transcendental functions differently
in the last bit) and ``portable`` (floats quantised to 1e-6, non-finite values as sentinels;
compared everywhere). :class:`GoldenFile` compares a run with the file and regenerates the file,
which is done only after an intended behaviour change.
"""

from __future__ import annotations

import hashlib
import json
import platform
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

__all__ = ["platform_key", "Digests", "GoldenFile"]


def platform_key() -> str:
    """Where exact (bit-level) float digests are reproducible."""
    try:
        from numpy._core._multiarray_umath import __cpu_features__ as feats
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_features__ as feats
    simd = "avx512" if feats.get("AVX512_SKX") else ("avx2" if feats.get("AVX2") else "base")
    return f"{sys.platform}-{platform.machine()}-numpy{np.__version__}-{simd}"


class Digests:
    """Values collected per named stream, hashed at the end (exact and portable).

    Parameters
    ----------
    ints_as_int64 : bool
        Hash integer streams as int64 (True) or in their own width (False); each golden file
        keeps the form it was written with.
    """

    def __init__(self, *, ints_as_int64: bool = False) -> None:
        self.items: dict[str, list] = {}
        self.ints_as_int64 = ints_as_int64

    def add(self, name: str, value) -> None:
        """Append one value (array, scalar, tuple of numbers or strings, None) to stream ``name``."""
        if value is None:
            value = np.zeros(0, np.int8)
        elif not (isinstance(value, tuple) and value and isinstance(value[0], str)):
            value = np.array(value)  # a copy: the caller may change its array later
        self.items.setdefault(name, []).append(value)

    def _digest(self, values: list) -> tuple[str, str]:
        if isinstance(values[0], tuple):
            h = hashlib.sha256("\x1e".join("\x1f".join(v) for v in values).encode()).hexdigest()
            return h[:16], h[:16]
        head = np.array([d for a in values for d in (a.ndim, *a.shape)], dtype="<i8").tobytes()
        dtypes = ",".join(a.dtype.str for a in values).encode()
        flat = np.concatenate([a.ravel() for a in values])
        if flat.dtype.kind == "f":
            exact = hashlib.sha256(dtypes + head + flat.astype("<f8").tobytes()).hexdigest()
            fin = np.isfinite(flat)
            q = np.rint(np.where(fin, flat, 0.0) * 1e6).astype("<i8")
            q[np.isposinf(flat)] = np.iinfo(np.int64).max
            q[np.isneginf(flat)] = np.iinfo(np.int64).min
            q[np.isnan(flat)] = np.iinfo(np.int64).min + 1
            port = hashlib.sha256(head + q.tobytes()).hexdigest()
        elif flat.dtype.kind in "iub":
            if self.ints_as_int64:
                data = flat.astype(np.int64).astype("<i8").tobytes()
            else:  # in their own width, little-endian (the same bytes on every platform)
                data = flat.astype(flat.dtype.newbyteorder("<"), copy=False).tobytes()
            port = hashlib.sha256(flat.dtype.kind.encode() + head + data).hexdigest()
            exact = hashlib.sha256(dtypes + port.encode()).hexdigest()
        else:
            raise TypeError(f"cannot digest dtype {flat.dtype}")
        return exact[:16], port[:16]

    def result(self) -> dict[str, dict[str, str]]:
        """``{"exact": {name: hex}, "portable": {name: hex}}`` (16 hex digits each)."""
        out: dict[str, dict[str, str]] = {"exact": {}, "portable": {}}
        for name in sorted(self.items):
            out["exact"][name], out["portable"][name] = self._digest(self.items[name])
        return out


class GoldenFile:
    """A golden file and the runs it pins.

    Parameters
    ----------
    path : Path
        The JSON file (``{"platform": key, "runs": {run id: digests}}``).
    runs : sequence of tuples
        The runs; ``run[0]`` is the run id.
    digest : callable
        ``digest(run) -> {"exact": {...}, "portable": {...}}``.
    """

    def __init__(self, path: Path, runs: Sequence[tuple], digest: Callable[[tuple], dict]):
        self.path, self.runs, self.digest = path, runs, digest

    def load(self) -> dict:
        """The file's contents."""
        return json.loads(self.path.read_text())

    def check(self, run: tuple) -> None:
        """Assert that ``run`` reproduces its recorded digests (exact ones on the same platform)."""
        golden = self.load()
        want = golden["runs"][run[0]]
        got = self.digest(run)
        kinds = ["portable"] + (["exact"] if golden["platform"] == platform_key() else [])
        for kind in kinds:
            bad = sorted(k for k in want[kind] if got[kind].get(k) != want[kind][k])
            extra = sorted(set(got[kind]) - set(want[kind]))
            assert not bad and not extra, f"{run[0]}: {kind} digests differ for {bad + extra}"

    def check_covers_runs(self) -> None:
        """Assert that the file holds exactly the runs."""
        assert sorted(self.load()["runs"]) == sorted(r[0] for r in self.runs)

    def regenerate(self) -> None:
        """Write the file from the current code (only after an intended behaviour change)."""
        out = {"platform": platform_key(), "runs": {r[0]: self.digest(r) for r in self.runs}}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.path.write_text(json.dumps(out, indent=1, sort_keys=True) + "\n")
        print(f"wrote {self.path} ({len(self.runs)} runs, platform {out['platform']})")

    def main(self, argv: list[str], script: str) -> None:
        """Command line of a golden test module: ``--regenerate`` or a usage line."""
        if argv == ["--regenerate"]:
            self.regenerate()
        else:
            sys.exit(f"usage: python {script} --regenerate")
