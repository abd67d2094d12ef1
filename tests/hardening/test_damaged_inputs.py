"""Damaged files from outside through the commands that read them (issues 15 and 17): recordings
through ``fcplan replay --video``, results folders through ``fcplan report`` and a resuming
``fcplan sweep``, legacy folders through ``fcplan import-legacy``. Every case ends in one line
and exit 2, or runs, within a time and a memory bound; nothing is left behind.

The cases are :mod:`tests.hardening.damage`'s (fixed hostile files plus seeded random damage;
the audit, ``bench/audit_hardening.py``, runs hundreds). The readers' own fuzz tests are in
``tests/fuzz``."""

from __future__ import annotations

import os
import random

import pytest

from tests.hardening import damage
from tests.hardening.options import Fixtures
from tests.hardening.runner import Outcome, run_cli, run_in_process

pytestmark = pytest.mark.skipif(
    not (os.path.isdir("/proc") and hasattr(os, "mkfifo")), reason="FIFOs and /proc (Linux)"
)

TIME_BOUND_S = 240  # a report draws its plots: ~3 s on a quiet machine, 35 s on a loaded one
MEMORY_BOUND_MB = 512  # traced Python and numpy allocations of one in-process case
RSS_BOUND_MB = 1024  # peak resident memory of a command run in its own process
RANDOM_CASES = 4  # seeded random damages per reader in the default run


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    """Valid inputs: a 3-s recording, a two-episode results folder, a 12-s legacy folder."""
    return Fixtures.make(tmp_path_factory.mktemp("fixtures"))


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FCPLAN_DATA_DIR", str(tmp_path))
    return tmp_path


def _bounded(argv: list[str], what: str) -> str:
    case = run_in_process(argv, timeout=TIME_BOUND_S)
    assert case.outcome in (Outcome.CLEAN, Outcome.RAN), (what, case.stderr[-1500:])
    assert case.peak_mb < MEMORY_BOUND_MB, (what, case.peak_mb)
    return case.outcome


def test_damaged_recordings_replay_in_one_line(fx, scratch):
    """replay --video of the adversarial recordings (bomb, 7 TiB shape, nested header, NaN and
    absurd positions, a flipped bit, a FIFO, an unknown compression, a 300 MiB sparse file) and
    of seeded random damage: one line or a video, bounded."""
    cases = damage.recordings(str(scratch / "rec"), fx.recording, fx.legacy, RANDOM_CASES,
                              random.Random(17))  # fmt: skip
    outcomes = [
        _bounded(["replay", path, "--video", str(scratch / "out.gif"), "--size", "64"], what)
        for what, path in cases
    ]
    assert outcomes.count(Outcome.CLEAN) >= len(cases) - RANDOM_CASES  # every fixed one refused


def test_damaged_results_folders_report_and_resume_in_one_line(fx, scratch):
    """report, and a sweep resuming into the folder, on results folders with a damaged row,
    foreign files (CSV, JSONL, JSON, text), FIFOs named as a row or a manifest, symlinks to
    /dev/zero or in a loop, an oversized row or manifest, a manifest nested 100,000 deep and a
    Parquet bomb: one line (naming the file) or a report, bounded; the rows already stored are
    never touched."""
    cases = damage.results_folders(str(scratch / "res"), fx.results, RANDOM_CASES,
                                   random.Random(17))  # fmt: skip
    for what, folder in cases:
        rows = sorted(p.name for p in os.scandir(folder) if p.name.endswith(".parquet"))
        report = _bounded(["report", folder, "--out", str(scratch / "report")], what)
        resume = _bounded(["sweep", fx.study, "--results", folder, "-j", "1", "-q"], what)
        if what.startswith(("CSV", "JSONL", "FIFO", "sparse", "Parquet bomb", "symlink")):
            assert (report, resume) == (Outcome.CLEAN, Outcome.CLEAN), what
        after = sorted(p.name for p in os.scandir(folder) if p.name.endswith(".parquet"))
        assert set(rows) <= set(after), what  # nothing stored was removed


def test_a_parquet_bomb_is_refused_before_it_is_decoded(fx, tmp_path):
    """A 1.5 KB row declaring 2**25 values and a 1 GiB sparse row: report refuses both in one
    line naming the file, in a process whose peak resident memory stays under the bound."""
    cases = dict(damage.results_folders(str(tmp_path / "res"), fx.results, 0, random.Random(0)))
    for what in ("Parquet bomb row", "sparse 1 GiB row", "sparse 1 GiB manifest"):
        case = run_cli(["report", cases[what]], cwd=tmp_path, timeout=120)
        assert case.outcome == Outcome.CLEAN and case.orphans == [], (what, case.stderr)
        assert case.peak_mb < RSS_BOUND_MB, (what, case.peak_mb)
        assert "zz.parquet" in case.first_line or "manifest-00" in case.first_line


def test_damaged_legacy_folders_import_in_one_line(fx, scratch):
    """import-legacy of legacy folders with one file's values or bytes edited, missing, a FIFO,
    a folder, a symlink to /dev/zero or 1 GiB sparse, and the adversarial folders: one line or a
    recording, bounded."""
    cases = damage.legacy_folders(str(scratch / "leg"), fx.legacy, fx.recording, 2 * RANDOM_CASES,
                                  random.Random(17))  # fmt: skip
    for what, folder in cases:
        _bounded(["import-legacy", folder, "--out", str(scratch / "imported.npz")], what)
