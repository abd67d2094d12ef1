"""Sweeps under abuse, as real ``fcplan sweep`` processes: killed, terminated, doubled, starved of
disk. Each function returns a :class:`Trial` (what happened) for the tests to assert on and for
``bench/audit_hardening.py`` to count."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from fcplan.experiments import load_results

ROOT = Path(__file__).resolve().parents[2]
CONFIG = """\
scenarios = ["practice"]
schedulers = ["greedy"]
seeds = "0-5"
[overrides]
duration_s = {duration}
"""
EPISODES = 6
ORPHAN_BOUND_S = 10.0  # a worker alive this long after its parent died is an orphan


@dataclass
class Trial:
    """What one abuse did: exit status of the sweep (None: killed), its stderr, rows stored at the
    end of it and after a resume, and the worker processes still alive after the bound."""

    status: int | None = None
    stderr: str = ""
    rows: int = 0
    resumed_rows: int = 0
    resume_status: int | None = None
    orphans: list[int] = field(default_factory=list)
    stray_temporaries: list[str] = field(default_factory=list)


#: long enough episodes that the sweep is still running when the first of its 6 rows is stored:
#: at 120 s the whole sweep of practice took 0.8 s on a fast 2-core machine (2026-12-02), ended
#: before a test could see a row and two workers together, and the kill tests failed; at 3,600 s
#: it took 7.7 s there
DURATION_S = 3600.0


def write_config(folder: Path, duration: float = DURATION_S) -> Path:
    path = folder / "study.toml"
    path.write_text(CONFIG.format(duration=duration), encoding="utf-8")
    return path


def start_sweep(config: Path, results: Path, jobs: int = 2) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "fcplan", "sweep", str(config), "--results", str(results)]
    return subprocess.Popen(
        [*cmd, "--jobs", str(jobs), "--quiet"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def alive(pid: int) -> bool:
    """A process that exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def children(pid: int) -> list[int]:
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] != "Z":
                out.append(int(d.name))
    return out


def stored(results: Path) -> int:
    return len(list(results.glob("*.parquet"))) if results.exists() else 0


def wait_until(test, timeout: float, step: float = 0.05) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if test():
            return True
        time.sleep(step)
    return test()


def _running(proc: subprocess.Popen, results: Path, rows: int = 1, timeout: float = 120) -> list:
    """Wait until the sweep stored ``rows`` rows and runs two workers; return their pids."""
    workers: list[int] = []

    def ready() -> bool:
        nonlocal workers
        workers = children(proc.pid)
        return stored(results) >= rows and len(workers) >= 2

    if not wait_until(ready, timeout):
        proc.kill()
        raise AssertionError(f"the sweep never got going: {proc.communicate()[1]}")
    return workers


def _finish(trial: Trial, config: Path, results: Path, workers: list[int]) -> Trial:
    """Orphans, rows now, a resume to completion, and temporary files left after it."""
    wait_until(lambda: not any(alive(w) for w in workers), ORPHAN_BOUND_S)
    trial.orphans = [w for w in workers if alive(w)]
    for w in trial.orphans:
        os.kill(w, signal.SIGKILL)
    trial.rows = len(load_results(results))  # every stored row still reads back
    again = start_sweep(config, results)
    _, err = again.communicate(timeout=600)
    trial.resume_status = again.returncode
    trial.resumed_rows = len(load_results(results))
    trial.stderr += err
    # a killed writer may leave one temporary file; the resume removes it (its writer is dead)
    trial.stray_temporaries = [p.name for p in results.glob(".*.tmp")]
    return trial


def _communicate(proc: subprocess.Popen, workers: list[int], timeout: float) -> tuple[str, list]:
    """stderr of ``proc`` once it ended; if its pipe stays open past ``timeout`` (workers that
    outlived it hold it), those workers are the orphans: they are killed and returned."""
    try:
        return proc.communicate(timeout=timeout)[1], []
    except subprocess.TimeoutExpired:
        orphans = [w for w in workers if alive(w)]
        for w in orphans:
            os.kill(w, signal.SIGKILL)
        return proc.communicate()[1], orphans


def kill_parent(folder: Path, sig: int = signal.SIGKILL) -> Trial:
    """Kill (or terminate) a running sweep's parent process, then resume."""
    config, results = write_config(folder), folder / "results"
    proc = start_sweep(config, results)
    workers = _running(proc, results)
    proc.send_signal(sig)
    err, held = _communicate(proc, workers, 60)
    trial = _finish(Trial(status=proc.returncode, stderr=err), config, results, workers)
    trial.orphans += held
    return trial


def kill_worker(folder: Path) -> Trial:
    """Kill one worker of a running sweep: the pool restarts and the sweep completes."""
    config, results = write_config(folder), folder / "results"
    proc = start_sweep(config, results)
    workers = _running(proc, results)
    os.kill(workers[0], signal.SIGKILL)
    _, err = proc.communicate(timeout=600)
    trial = Trial(status=proc.returncode, stderr=err)
    return _finish(trial, config, results, workers)


def two_sweeps(folder: Path) -> tuple[Trial, Trial]:
    """A second sweep into a folder a first one is writing: the second refuses at once.

    The first sweep's episodes must outlast the second's start-up (about a second): at 600
    simulated seconds a greedy episode took under a second, so the first could finish its six
    before the second looked at the folder; at 3,600 s the five left take about ten."""
    config, results = write_config(folder), folder / "results"
    first = start_sweep(config, results)
    workers = _running(first, results)
    second = start_sweep(config, results, jobs=1)
    _, err2 = second.communicate(timeout=120)
    _, err1 = first.communicate(timeout=600)
    t1 = _finish(Trial(status=first.returncode, stderr=err1), config, results, workers)
    t2 = Trial(status=second.returncode, stderr=err2, rows=t1.rows)
    return t1, t2


def outcome(t: Trial) -> str:
    """The audit's :class:`~tests.hardening.runner.Outcome` of a trial: orphan if a worker
    outlived the bound; traceback if one was printed or a row was lost (the resume did not
    complete the grid, or left a temporary file); else clean error (exit 2 or 143 with one
    line) or ran (exit 0, or killed by the trial and completed by the resume)."""
    from tests.hardening.runner import ONE_LINE, Outcome

    if t.orphans:
        return Outcome.ORPHAN
    lost = t.resume_status is not None and (
        t.resume_status != 0 or t.resumed_rows != EPISODES or t.stray_temporaries
    )
    if "Traceback" in t.stderr or lost:
        return Outcome.TRACEBACK
    lines = [ln for ln in t.stderr.splitlines() if ln.strip()]
    if t.status == 2 and len(lines) == 1 and ONE_LINE.match(lines[0]):
        return Outcome.CLEAN
    if t.status == 143 and lines and lines[0] == "fcplan: terminated":
        return Outcome.CLEAN
    if t.status == 0 or (t.status is not None and t.status < 0 and t.resume_status == 0):
        return Outcome.RAN
    return Outcome.TRACEBACK


def can_mount_tmpfs() -> bool:
    """Whether a tmpfs can be mounted in a new user and mount namespace (``unshare -rm``)."""
    if not shutil.which("unshare") or not shutil.which("mount"):
        return False
    probe = "d=$(mktemp -d) && mount -t tmpfs -o size=64k tmpfs $d && umount $d; rmdir $d"
    try:
        done = subprocess.run(["unshare", "-rm", "sh", "-c", probe], capture_output=True,
                              timeout=30)  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return False
    return done.returncode == 0


def full_tmpfs(folder: Path) -> Trial | None:
    """A sweep into a 64 KiB tmpfs (a real full disk): mounted in a private user and mount
    namespace, so nothing outside sees it. Inside (:mod:`tests.hardening.full_disk`): the sweep
    fills it, then the tmpfs grows to 16 MiB and the same command resumes. None when no tmpfs can
    be mounted here."""
    import json

    from tests.hardening.runner import session_members

    if not can_mount_tmpfs():
        return None
    config = write_config(folder, duration=5.0)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = ["unshare", "-rm", sys.executable, "-m", "tests.hardening.full_disk", str(config),
           str(folder / "mnt")]  # fmt: skip
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)  # fmt: skip
    out, err = proc.communicate(timeout=600)
    if proc.returncode != 0:
        return Trial(status=proc.returncode, stderr=err)
    wait_until(lambda: not session_members(proc.pid), ORPHAN_BOUND_S)
    orphans = session_members(proc.pid)
    for pid in orphans:
        os.kill(pid, signal.SIGKILL)
    r = json.loads(out)
    return Trial(status=r["status"], stderr=r["stderr"], rows=r["rows"],
                 resumed_rows=r["resumed_rows"], resume_status=r["resume_status"],
                 orphans=orphans, stray_temporaries=r["stray"])  # fmt: skip
