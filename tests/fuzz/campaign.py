"""The long fuzz run: mutated valid files through each reader, every input isolated in a forked
child (time and memory bounds, crash detection), and a table of outcomes.

Usage (POSIX, from the repository root)::

    PYTHONPATH=$PWD nice python -m tests.fuzz.campaign --n 1000 --seed 0
    PYTHONPATH=$PWD nice python -m tests.fuzz.campaign --n 1000 --seed 0 --code /path/to/other/checkout

``--code`` runs the same inputs against another checkout's fcplan (e.g. before a change);
``--adversarial`` runs the hostile inputs of issues 15 and 17 instead, one row each. The
inputs are drawn with a seeded numpy generator, so a run is reproducible; ``--keep DIR`` keeps
them. Outcomes (see :mod:`tests.fuzz.worker`): tried, clean (the reader's own error), loaded,
traceback, hang, oom, crash; the first few non-clean messages are printed under the table.

Targets: ``pickle`` (``restricted_load`` on byte-edited pickles: the small seeds of
:func:`tests.fuzz.cases.pickle_seeds` and the files of a 12-s synthetic legacy folder),
``legacy`` (``import_legacy`` on that folder with one file value-edited or byte-edited),
``recording`` (``load_recording`` on a 3-s recording with its archive or one entry byte-edited).
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
from typing import Any

import numpy as np

from tests.fuzz.cases import (
    EDIT_KINDS,
    ODD_VALUES,
    Edit,
    adversarial_cases,
    make_npz,
    mini_legacy_folder,
    mutate_bytes,
    mutate_value,
    npz_entries,
    pickle_seeds,
    short_recording,
)

OUTCOMES = ("clean", "loaded", "traceback", "hang", "oom", "crash")


def _edits(rng: np.random.Generator) -> list[Edit]:
    return [
        (
            str(rng.choice(EDIT_KINDS)),
            int(rng.integers(0, 2**31)),
            rng.bytes(int(rng.integers(1, 9))),
        )
        for _ in range(int(rng.integers(1, 5)))
    ]


def _write(path: str, data: bytes) -> str:
    with open(path, "wb") as f:
        f.write(data)
    return path


def make_inputs(out: str, n: int, seed: int, targets: list[str]) -> list[list[str]]:
    """``n`` mutated inputs per target under ``out``: ``[[name, target, path], ...]``."""
    rng = np.random.default_rng(seed)
    folder = os.path.join(out, "seed_folder")
    mini_legacy_folder(folder)
    rec = short_recording(os.path.join(out, "seed.npz"))
    files = {}
    for f in sorted(os.listdir(folder)):
        with open(os.path.join(folder, f), "rb") as fh:
            files[f] = fh.read()
    small = {**pickle_seeds(), **{f: b for f, b in files.items() if len(b) < 200_000}}
    cases: list[list[str]] = []
    for i in range(n):
        if "pickle" in targets:
            name = sorted(small)[int(rng.integers(len(small)))]
            path = _write(os.path.join(out, f"p{i}.pkl"), mutate_bytes(small[name], _edits(rng)))
            cases.append([f"pickle {name}", "pickle", path])
        if "legacy" in targets:
            cases.append(_legacy_input(out, i, folder, files, rng))
        if "recording" in targets:
            cases.append(_recording_input(out, i, rec, rng))
    return cases


def _legacy_input(
    out: str, i: int, folder: str, files: dict[str, bytes], rng: np.random.Generator
) -> list[str]:
    game = os.path.join(out, f"g{i}")
    os.makedirs(game)
    name = sorted(files)[int(rng.integers(len(files)))]
    for f in files:
        if f != name:
            os.symlink(os.path.join(folder, f), os.path.join(game, f))
    if rng.random() < 0.5:
        odd = ODD_VALUES[int(rng.integers(len(ODD_VALUES)))]
        value = mutate_value(pickle.loads(files[name]), int(rng.integers(10**6)), odd)
        data, how = pickle.dumps(value, protocol=2), "value"
    else:
        data, how = mutate_bytes(files[name], _edits(rng)), "bytes"
    _write(os.path.join(game, name), data)
    return [f"legacy {name} {how}", "legacy", game]


def _recording_input(out: str, i: int, rec: bytes, rng: np.random.Generator) -> list[str]:
    if rng.random() < 0.5:
        data, how = mutate_bytes(rec, _edits(rng)), "archive"
    else:
        entries = npz_entries(rec)
        name = sorted(entries)[int(rng.integers(len(entries)))]
        entries[name] = mutate_bytes(entries[name], _edits(rng))
        data, how = make_npz(entries), name
    return [f"recording {how}", "recording", _write(os.path.join(out, f"r{i}.npz"), data)]


def adversarial_inputs(out: str) -> list[list[str]]:
    """The hostile inputs of :func:`tests.fuzz.cases.adversarial_cases`, written under ``out``."""
    folder = os.path.join(out, "seed_folder")
    mini_legacy_folder(folder)
    rec = short_recording(os.path.join(out, "seed.npz"))
    return [[n, t, p] for n, (t, p) in adversarial_cases(out, folder, rec).items()]


def adversarial_table(results: list[dict[str, Any]], out: str = "") -> str:
    """One row per hostile input: outcome, seconds, peak RSS growth, message."""
    lines = ["| input | outcome | s | RSS growth MB | message |", "|---|---|---|---|---|"]
    for r in results:
        msg = r.get("message", "").replace(out, "").replace("|", "/")[:90]
        lines.append(
            f"| {r['name']} | {r['outcome']} | {r.get('seconds', '')} | "
            f"{r.get('rss_growth_mb', '')} | {msg} |"
        )
    return "\n".join(lines)


def run(cases: list[list[str]], out: str, code: str | None, timeout: float) -> list[dict[str, Any]]:
    """Run the cases through :mod:`tests.fuzz.worker` with fcplan from ``code`` (default: this
    checkout)."""
    listing = _write(os.path.join(out, "cases.json"), json.dumps(cases).encode())
    here = os.getcwd()
    path = os.pathsep.join([code, here] if code else [here])
    env = dict(os.environ, PYTHONPATH=path)
    cmd = [sys.executable, "-m", "tests.fuzz.worker", listing, "--timeout", str(timeout)]
    # (python -m puts the working directory first on sys.path: run from the code's checkout)
    proc = subprocess.run(
        cmd, capture_output=True, text=True, env=env, check=True, cwd=code or here
    )
    return [json.loads(line) for line in proc.stdout.splitlines()]


def table(results: list[dict[str, Any]]) -> str:
    """Markdown table of outcome counts per target, then examples of non-clean outcomes."""
    counts: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
    for r in results:
        counts[r["target"]][r["outcome"]] += 1
    lines = [
        "| target | tried | " + " | ".join(OUTCOMES) + " |",
        "|---" * (len(OUTCOMES) + 2) + "|",
    ]
    for target, c in counts.items():
        cells = " | ".join(str(c[o]) for o in OUTCOMES)
        lines.append(f"| {target} | {sum(c.values())} | {cells} |")
    bad = [r for r in results if r["outcome"] not in ("clean", "loaded")]
    for r in bad[:8]:
        lines.append(f"  {r['outcome']}: {r['name']}: {r.get('message', '')[:160]}")
    peak = max((r.get("rss_growth_mb", 0) for r in results), default=0)
    slow = max((r.get("seconds", 0) for r in results), default=0)
    lines.append(f"  largest RSS growth {peak:.1f} MB, slowest input {slow:.2f} s")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=300, help="inputs per target")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--targets", default="pickle,legacy,recording")
    ap.add_argument("--timeout", type=float, default=30.0)
    ap.add_argument("--code", default=None, help="another checkout whose fcplan to fuzz")
    ap.add_argument("--keep", default=None, help="keep the inputs in this folder")
    ap.add_argument(
        "--adversarial", action="store_true", help="run the hostile inputs of issues 15 and 17"
    )
    args = ap.parse_args(argv)
    out = args.keep or tempfile.mkdtemp(prefix="fcplan-fuzz-")
    os.makedirs(out, exist_ok=True)
    try:
        if args.adversarial:
            results = run(adversarial_inputs(out), out, args.code, args.timeout)
            print(adversarial_table(results, out + os.sep))
        else:
            cases = make_inputs(out, args.n, args.seed, args.targets.split(","))
            print(table(run(cases, out, args.code, args.timeout)))
    finally:
        if not args.keep:
            shutil.rmtree(out, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
