"""Sweeps that leave nothing behind (issue 17): a killed or terminated sweep leaves no worker
alive and keeps every row; a killed worker costs nothing; two sweeps never share a folder; a full
disk is one line. Each test runs real ``fcplan sweep`` processes, bounded in time."""

from __future__ import annotations

import errno
import os
import signal

import pytest

from fcplan.cli import main
from fcplan.experiments import load_results, results
from tests.hardening import sweeps

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc"), reason="reads /proc for processes")


def test_kill_9_of_the_sweep_leaves_no_worker_and_resume_completes(tmp_path):
    """kill -9 of the sweep's parent: both pool workers die within the bound, the rows stored
    read back, nothing is left half-written, and re-running completes the grid."""
    t = sweeps.kill_parent(tmp_path, signal.SIGKILL)
    assert t.status == -signal.SIGKILL
    assert t.orphans == [] and t.stray_temporaries == []
    assert 1 <= t.rows < sweeps.EPISODES
    assert (t.resume_status, t.resumed_rows) == (0, sweeps.EPISODES)


def test_sigterm_is_handled_like_ctrl_c(tmp_path):
    """SIGTERM: the sweep stops its workers and exits 143 with one line, keeping its rows."""
    t = sweeps.kill_parent(tmp_path, signal.SIGTERM)
    assert t.status == 143
    assert t.stderr.splitlines()[0] == "fcplan: terminated"
    assert "Traceback" not in t.stderr
    assert t.orphans == [] and t.rows >= 1
    assert (t.resume_status, t.resumed_rows) == (0, sweeps.EPISODES)


def test_kill_9_of_a_worker_costs_no_episode(tmp_path):
    """kill -9 of one pool worker: the pool restarts, the sweep exits 0 with every episode."""
    t = sweeps.kill_worker(tmp_path)
    assert t.status == 0 and "Traceback" not in t.stderr
    assert t.orphans == [] and t.rows == sweeps.EPISODES


def test_a_second_sweep_into_a_busy_folder_refuses_in_one_line(tmp_path):
    """While one sweep writes into a folder, a second one into it exits 2 with one line naming
    the folder; the first completes undisturbed (its live temporary files are not removed)."""
    first, second = sweeps.two_sweeps(tmp_path)
    assert second.status == 2
    lines = second.stderr.strip().splitlines()
    assert len(lines) == 1 and "another sweep is writing into this results folder" in lines[0]
    assert first.status == 0 and first.rows == sweeps.EPISODES and first.orphans == []


def test_a_full_disk_is_one_line_with_the_rows_intact(tmp_path, monkeypatch, capsys):
    """ENOSPC while writing the third row: exit 2, one line saying the disk is full, the two
    rows stored before read back, no temporary file left; a re-run with space resumes."""
    config = sweeps.write_config(tmp_path, duration=5.0)
    out = tmp_path / "results"
    import pyarrow.parquet as pq

    write_table = pq.write_table
    calls = {"n": 0}

    def full_disk(table, where, *a, **kw):
        calls["n"] += 1
        if calls["n"] > 2:
            raise OSError(errno.ENOSPC, "No space left on device")
        return write_table(table, where, *a, **kw)

    monkeypatch.setattr(pq, "write_table", full_disk)
    code = main(["sweep", str(config), "--results", str(out), "--jobs", "1", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "No space left on device" in err[0] and "disk is full" in err[0]
    assert len(load_results(out)) == 2 and not list(out.glob(".*.tmp"))
    monkeypatch.setattr(pq, "write_table", write_table)
    assert main(["sweep", str(config), "--results", str(out), "--jobs", "1", "--quiet"]) == 0
    assert len(load_results(out)) == sweeps.EPISODES


@pytest.mark.skipif(not sweeps.can_mount_tmpfs(), reason="cannot mount a tmpfs (unshare -rm)")
def test_a_real_full_disk_is_one_line_and_resumes(tmp_path):
    """A sweep (two workers) into a 64 KiB tmpfs mounted in a private namespace: the disk fills,
    the sweep exits 2 with one line saying so, every row stored reads back, no temporary file
    and no worker is left; with the tmpfs grown, the same command completes the grid."""
    t = sweeps.full_tmpfs(tmp_path)
    assert t is not None
    lines = t.stderr.strip().splitlines()
    assert t.status == 2 and len(lines) == 1, t.stderr
    assert "No space left on device" in lines[0] and "disk is full" in lines[0]
    assert t.rows < sweeps.EPISODES and t.stray_temporaries == [] and t.orphans == []
    assert (t.resume_status, t.resumed_rows) == (0, sweeps.EPISODES)


def test_stale_temporaries_go_and_live_ones_stay(tmp_path):
    """remove_stale_temporaries deletes the temporary files of dead writers (and of the old
    pid-only format) but neither a live process's nor another host's."""
    dead = os.fork()
    if dead == 0:
        os._exit(0)
    os.waitpid(dead, 0)
    host = results._host()
    names = {
        f".k1.{host}~{dead}~ab12cd34.tmp": False,
        f".k2.{host}~{os.getpid()}~ab12cd34.tmp": True,
        f".k3.otherhost~{dead}~ab12cd34.tmp": True,
        f".k4.{dead}.ab12cd34.tmp": False,
        f".manifest-0a.{dead}.tmp": False,
    }
    for name in names:
        (tmp_path / name).write_bytes(b"")
    assert results.remove_stale_temporaries(tmp_path) == 3
    assert {p.name for p in tmp_path.iterdir()} == {n for n, keep in names.items() if keep}


def test_a_huge_jobs_count_is_refused_before_any_worker_starts(tmp_path, capsys):
    """--jobs far above the CPUs (a 240-episode grid with --jobs 10**20 started 240 workers):
    sweep and compare exit 2 with one line naming the bound, no worker started, no row. A count
    beyond any machine (10**20) is refused by the range check of every --jobs (1..MAX_JOBS); one
    within that range but above this machine's worker bound by the local backend's check."""
    from fcplan.experiments.backends import max_jobs
    from fcplan.experiments.workers import MAX_JOBS

    config = tmp_path / "grid.toml"
    config.write_text('scenarios = ["1-24"]\nschedulers = ["idle"]\nseeds = "0-9"\n')
    cases = {
        "99999999999999999999": f"jobs must be an integer in 1..{MAX_JOBS}",
        str(max_jobs() + 1): f"at most {max_jobs()} may run here",
    }
    for jobs, bound in cases.items():
        for argv in (
            ["sweep", str(config), "--results", str(tmp_path / "r"), "--jobs", jobs],
            [
                "compare",
                "--schedulers",
                "idle",
                "--scenarios",
                "1-24",
                "--seeds",
                "0-9",
                "-j",
                jobs,
            ],
        ):
            assert main(argv) == 2
            err = capsys.readouterr().err.strip()
            assert "\n" not in err and bound in err, (argv, err)
    assert load_results(tmp_path / "r").empty
