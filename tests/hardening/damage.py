"""Damaged copies of the files fcplan reads from outside: recordings, results folders and legacy
folders, each made from a valid one (:class:`tests.hardening.options.Fixtures`) by a seeded
generator, for the commands that read them (``replay``, ``report`` and ``sweep``,
``import-legacy``).

* :func:`recordings`: the adversarial recordings of :mod:`tests.fuzz.cases` (decompression bomb,
  7 TiB declared shape, nested header, NaN and absurd positions, a flipped bit, a FIFO, ...), byte
  edits of the archive, byte edits of one entry re-packed in a valid archive, truncations, an
  oversized (sparse) file;
* :func:`results_folders`: a two-episode results folder with one damage: a row truncated or with
  bytes edited, foreign files (CSV, JSONL, JSON, text), a FIFO, a symlink to ``/dev/zero`` or a
  loop named as a row or a manifest, an oversized row (sparse), a Parquet bomb (a tiny file that
  decodes to gigabytes), a manifest nested 100,000 deep, a folder named as a row;
* :func:`legacy_folders`: the 12-s synthetic legacy folder with one file's values or bytes edited,
  a file missing, replaced by a FIFO, a folder, a symlink to ``/dev/zero`` or a 1 GiB sparse
  file, and the adversarial folders of :mod:`tests.fuzz.cases`.

Each function writes its cases under a folder and returns ``[(description, path), ...]``.

Examples
--------
>>> import random
>>> edits = random_edits(random.Random(0))
>>> 1 <= len(edits) <= 4 and all(k in EDIT_KINDS for k, _, _ in edits)
True
"""

from __future__ import annotations

import json
import os
import pickle
import random
import shutil
import subprocess
import sys
from pathlib import Path

from tests.fuzz.cases import (
    EDIT_KINDS,
    ODD_VALUES,
    _legacy_with,
    adversarial_cases,
    make_npz,
    mutate_bytes,
    mutate_value,
    npz_entries,
)

__all__ = [
    "legacy_folders",
    "random_edits",
    "recordings",
    "results_folders",
    "write_parquet_bomb",
]

Cases = list[tuple[str, str]]


def random_edits(rng: random.Random) -> list[tuple[str, int, bytes]]:
    """One to four byte edits (kind, position, payload) for :func:`tests.fuzz.cases.mutate_bytes`."""
    return [
        (rng.choice(EDIT_KINDS), rng.randrange(2**31), rng.randbytes(rng.randint(1, 8)))
        for _ in range(rng.randint(1, 4))
    ]


def _write(path: Path, data: bytes) -> str:
    path.write_bytes(data)
    return str(path)


def _sparse(path: Path, size: int) -> str:
    with open(path, "wb") as fh:
        fh.truncate(size)
    return str(path)


def recordings(folder: str, seed_path: str, legacy: str, n: int, rng: random.Random) -> Cases:
    """Damaged recordings (see the module docstring): the adversarial ones, then ``n`` random."""
    d = Path(folder)
    d.mkdir(parents=True, exist_ok=True)
    seed = Path(seed_path).read_bytes()
    cases = _adversarial(d / "adv", legacy, seed, "recording")
    cases.append(("sparse 300 MiB file", _sparse(d / "sparse.npz", 300 * 2**20)))
    cases.append(("empty file", _write(d / "empty.npz", b"")))
    for k in range(n):
        kind = rng.random()
        if kind < 0.4:
            data, what = mutate_bytes(seed, random_edits(rng)), "archive bytes edited"
        elif kind < 0.55:
            cut = rng.randrange(len(seed))
            data, what = seed[:cut], f"truncated at {cut} of {len(seed)} bytes"
        else:
            entries = npz_entries(seed)
            name = rng.choice(sorted(entries))
            entries[name] = mutate_bytes(entries[name], random_edits(rng))
            data, what = make_npz(entries), f"entry {name} edited"
        cases.append((what, _write(d / f"m{k}.npz", data)))
    return cases


def _adversarial(folder: Path, legacy: str, recording: bytes, target: str) -> Cases:
    """The adversarial cases of :mod:`tests.fuzz.cases` for ``target``, written in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    cases = adversarial_cases(str(folder), legacy, recording)
    return [(name, path) for name, (t, path) in cases.items() if t == target]


def _parquet_bomb(path: Path) -> str:
    """:func:`write_parquet_bomb` in a child process (writing it takes 2 GB, which a forked
    case would then count as its own)."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    code = (
        f"from tests.hardening.damage import write_parquet_bomb; write_parquet_bomb({str(path)!r})"
    )
    subprocess.run([sys.executable, "-c", code], env=env, check=True, timeout=300)
    return str(path)


def write_parquet_bomb(path: str) -> None:
    """A one-row fcplan-tagged Parquet file of 1.5 KB whose list column decodes to 2**25 values
    (run-length encoded: the file declares a few hundred uncompressed bytes for them)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from fcplan.experiments.results import FORMAT

    n = 2**25
    bomb = pa.ListArray.from_arrays(pa.array([0, n], pa.int32()), pa.nulls(n, pa.int8()))
    table = pa.table({"key": ["bomb"], "status": ["ok"], "error": [""], "bomb": bomb})
    table = table.replace_schema_metadata({b"fcplan": json.dumps(FORMAT).encode()})
    pq.write_table(table, path, compression="zstd")


def results_folders(folder: str, valid: str, n: int, rng: random.Random) -> Cases:
    """Copies of the results folder ``valid``, each with one damage (see the module docstring)."""
    base = Path(valid)
    rows = sorted(p.name for p in base.glob("*.parquet"))
    manifest = next(p.name for p in base.glob("manifest-*.json"))
    cases: Cases = []

    def copy(name: str) -> Path:
        d = Path(folder) / name
        shutil.copytree(base, d)
        return d

    for what, damage in _FOLDER_DAMAGES:
        d = copy(what.replace(" ", "_").replace("/", "_"))
        damage(d, rows[0], manifest)
        cases.append((what, str(d)))
    for k in range(n):
        d = copy(f"m{k}")
        row = d / rng.choice(rows)
        data = row.read_bytes()
        if rng.random() < 0.3:
            cut = rng.randrange(len(data))
            row.write_bytes(data[:cut])
            cases.append((f"row truncated at {cut} of {len(data)} bytes", str(d)))
        else:
            row.write_bytes(mutate_bytes(data, random_edits(rng)))
            cases.append(("row bytes edited", str(d)))
    return cases


def _symlink(target: str):
    def damage(d: Path, row: str, manifest: str) -> None:
        (d / "zz.parquet").symlink_to(target)

    return damage


_FOLDER_DAMAGES = (
    ("CSV file", lambda d, r, m: (d / "episodes.csv").write_text("key,score\nabc,1\n")),
    ("JSONL file", lambda d, r, m: (d / "episodes.jsonl").write_text('{"key": "abc"}\n')),
    ("foreign JSON", lambda d, r, m: (d / "notes.json").write_text("{}")),
    ("text file", lambda d, r, m: (d / "README").write_text("hello")),
    ("empty row", lambda d, r, m: (d / r).write_bytes(b"")),
    ("FIFO row", lambda d, r, m: os.mkfifo(d / "zz.parquet")),
    ("FIFO manifest", lambda d, r, m: os.mkfifo(d / "manifest-00.json")),
    ("symlink row to /dev/zero", _symlink("/dev/zero")),
    ("dangling symlink row", _symlink("missing/x.parquet")),
    ("symlink loop row", lambda d, r, m: (d / "zz.parquet").symlink_to(d / "zz.parquet")),
    ("folder named as a row", lambda d, r, m: (d / "zz.parquet").mkdir()),
    ("sparse 1 GiB row", lambda d, r, m: _sparse(d / "zz.parquet", 2**30)),
    ("sparse 1 GiB manifest", lambda d, r, m: _sparse(d / "manifest-00.json", 2**30)),
    ("manifest nested 100,000 deep",
     lambda d, r, m: (d / m).write_text("[" * 100_000 + "]" * 100_000)),
    ("manifest not JSON", lambda d, r, m: (d / m).write_text("{not json")),
    ("Parquet bomb row", lambda d, r, m: _parquet_bomb(d / "zz.parquet")),
    ("foreign Parquet row", lambda d, r, m: _foreign_parquet(d / "zz.parquet")),
)  # fmt: skip


def _foreign_parquet(path: Path) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"a": [1, 2]}), path)


def legacy_folders(folder: str, valid: str, recording: str, n: int, rng: random.Random) -> Cases:
    """Copies of the legacy folder ``valid``, each with one file damaged (see the module
    docstring), then the adversarial folders of :mod:`tests.fuzz.cases`."""
    from fcplan.legacy import LEGACY_FILES

    cases: Cases = []

    def copy(name: str) -> Path:
        d = Path(folder) / name
        shutil.copytree(valid, d)
        return d

    for k in range(n):
        d = copy(f"m{k}")
        file = rng.choice(LEGACY_FILES)
        path = d / file
        kind = rng.random()
        if kind < 0.5:
            odd = rng.randrange(len(ODD_VALUES))
            value = mutate_value(pickle.loads(path.read_bytes()), rng.randrange(10**6),
                                 ODD_VALUES[odd])  # fmt: skip
            path.write_bytes(pickle.dumps(value, protocol=2))
            cases.append((f"{file}: a value set to {ODD_VALUES[odd]!r:.30}", str(d)))
        elif kind < 0.85:
            path.write_bytes(mutate_bytes(path.read_bytes(), random_edits(rng)))
            cases.append((f"{file}: bytes edited", str(d)))
        else:
            special = rng.choice(("missing", "FIFO", "folder", "/dev/zero", "sparse 1 GiB"))
            path.unlink()
            if special == "FIFO":
                os.mkfifo(path)
            elif special == "folder":
                path.mkdir()
            elif special == "/dev/zero":
                path.symlink_to("/dev/zero")
            elif special == "sparse 1 GiB":
                _sparse(path, 2**30)
            cases.append((f"{file}: {special}", str(d)))
    adv = Path(folder) / "adv"
    adv.mkdir()
    for name, (target, path) in adversarial_cases(
        str(adv), valid, Path(recording).read_bytes()
    ).items():
        if target == "legacy":
            cases.append((name, path))
        elif target == "pickle":  # the hostile pickles as a folder's Agent_States.pkl
            where = str(adv / f"pkl-{len(cases)}")
            data = Path(path).read_bytes()
            cases.append(
                (
                    f"{name} as Agent_States.pkl",
                    _legacy_with(where, valid, "Agent_States.pkl", data),
                )
            )
    return cases
