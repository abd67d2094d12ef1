"""Run one ``fcplan`` command as an attacker's case: bounded, classified, orphans counted.

:func:`run_cli` runs ``fcplan argv`` in a child process of its own session (so every process it
starts, pool workers included, can be found afterwards by session id), with an address-space
limit (``RLIMIT_AS``) and a wall-clock bound, and returns a :class:`Case`: the exit status, the
stderr text, the child's peak resident memory (``wait4``'s ``ru_maxrss``, see :data:`_LAUNCHER`),
the seconds it took, the processes of its session still alive :data:`ORPHAN_GRACE_S` after it ended (killed, then
counted as orphans) and its :class:`Outcome`.

Two ways to start the child: ``fork=True`` forks this process and calls
:func:`fcplan.cli.main` (no interpreter start-up: for the audit script, a single-threaded
process), else a fresh ``python -m fcplan`` (for the test suite, whose workers have threads).
:func:`run_in_process` runs :func:`fcplan.cli.main` in a long-lived helper process instead (no
start-up per case: for the many small cases of the test suite, see :mod:`tests.traced`): the
time bound is a ``SIGALRM``, the memory measured is the peak of ``tracemalloc`` (Python and numpy
allocations), orphans are the helper's new children.

Examples
--------
>>> import tempfile
>>> case = run_cli(["run", "nosuch"], cwd=tempfile.mkdtemp(), timeout=120)
>>> case.outcome, case.orphans
('clean error', [])
>>> case.first_line  # doctest: +ELLIPSIS
"fcplan: error: ...nosuch..."
"""

from __future__ import annotations

import contextlib
import os
import re
import resource
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from tests.deadline import deadline as time_bound
from tests.traced import traced_call

__all__ = [
    "MEMORY_LIMIT",
    "ONE_LINE",
    "ORPHAN_GRACE_S",
    "Case",
    "Outcome",
    "classify",
    "run_cli",
    "run_in_process",
    "session_members",
]

ROOT = Path(__file__).resolve().parents[2]
#: Address-space limit of a case's main process (bytes): far above any sane run, low enough
#: that a runaway allocation fails in the child instead of swapping the machine.
MEMORY_LIMIT = 6 * 2**30
#: Seconds the processes a case started may outlive it (pool workers notice their parent's
#: death within the watchdog period, 1 s) before they count as orphans.
ORPHAN_GRACE_S = 5.0


#: The one stderr line of a clean error: ``fcplan: error: ...`` or, from the argument parser,
#: ``fcplan run: error: ...``.
ONE_LINE = re.compile(r"^fcplan(?: [a-z][a-z-]*)*: error: ")


class Outcome:
    """Categories of what a command did with a bad input (the audit's columns)."""

    CLEAN = "clean error"  # exit 2, one line "fcplan[ command]: error: ..." on stderr
    RAN = "ran"  # exit 0
    TRACEBACK = "traceback"  # anything else that printed a traceback or exited otherwise
    HANG = "hang"  # over the time bound
    OOM = "OOM"  # out of memory (a MemoryError, or killed by the memory limit)
    ORPHAN = "orphan"  # a child process outlived its parent
    ALL = (CLEAN, RAN, TRACEBACK, HANG, OOM, ORPHAN)


def classify(status: int | None, stderr: str) -> str:
    """The :class:`Outcome` of a command that exited with ``status`` (None: killed for taking
    too long) and wrote ``stderr``.

    Examples
    --------
    >>> classify(2, "fcplan: error: x.toml: world_size must be ...\\n")
    'clean error'
    >>> classify(2, "fcplan replay: error: argument --end: expected seconds >= 0, got 'x'\\n")
    'clean error'
    >>> classify(1, "Traceback (most recent call last):\\n ...")
    'traceback'
    >>> classify(None, ""), classify(0, "progress\\n")
    ('hang', 'ran')
    """
    if status is None:
        return Outcome.HANG
    if "MemoryError" in stderr or "out of memory" in stderr or status in (-9, 137):
        return Outcome.OOM
    if "Traceback" in stderr:
        return Outcome.TRACEBACK
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    if status == 2 and len(lines) == 1 and ONE_LINE.match(lines[0]):
        return Outcome.CLEAN
    if status == 0:
        return Outcome.RAN
    return Outcome.TRACEBACK


@dataclass
class Case:
    """What one command did: see the module docstring."""

    argv: list[str]
    outcome: str
    status: int | None
    stderr: str
    seconds: float
    peak_mb: float
    orphans: list[int] = field(default_factory=list)

    @property
    def first_line(self) -> str:
        """The first non-blank stderr line (cut to 200 characters)."""
        return next((ln for ln in self.stderr.splitlines() if ln.strip()), "")[:200]

    @property
    def error_lines(self) -> list[str]:
        """The non-blank stderr lines that are not progress lines."""
        lines = [ln for ln in self.stderr.splitlines() if ln.strip()]
        return [ln for ln in lines if not ln.startswith(("compare: ", "sweep: "))]


def _stat(pid: int) -> list[str] | None:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return None


def session_members(sid: int) -> list[int]:
    """Pids of the live (non-zombie) processes in session ``sid`` (Linux ``/proc``)."""
    out = []
    for d in Path("/proc").iterdir():
        fields = _stat(int(d.name)) if d.name.isdigit() else None
        if fields is not None and fields[0] != "Z" and int(fields[3]) == sid:
            out.append(int(d.name))
    return out


def _orphans(sid: int, grace: float) -> list[int]:
    """The processes of session ``sid`` alive ``grace`` seconds from now (then killed)."""
    deadline = time.monotonic() + grace
    while (left := session_members(sid)) and time.monotonic() < deadline:
        time.sleep(0.1)
    for pid in left:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    return left


def _limit(memory: int) -> None:
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))


def _forked(
    argv: list[str], memory: int, err: int, prepare: Callable[[], None] | None, cwd: str
) -> int:
    """Start ``fcplan argv`` in a forked child (its own session, in ``cwd``); its pid."""
    pid = os.fork()
    if pid:
        return pid
    code = 1
    try:  # the child: never returns
        os.setsid()
        os.chdir(cwd)
        with contextlib.suppress(OSError):  # peak RSS from now on, not the parent's (Linux)
            Path("/proc/self/clear_refs").write_text("5")
        _limit(memory)
        os.dup2(err, 2)
        os.dup2(os.open(os.devnull, os.O_RDWR), 1)
        os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
        if prepare is not None:
            prepare()
        from fcplan.cli import main

        code = main(argv)
    except BaseException:  # noqa: BLE001 - anything escaping main is the finding
        traceback.print_exc()
    finally:
        sys.stderr.flush()
        os._exit(code)


#: A small interpreter between this process and a spawned case: it forks the case, which sets
#: its memory limit and execs ``python -m fcplan``, waits for it and writes its ``ru_maxrss`` (KiB)
#: to a file. A process forked from a large one (a test worker of 1 GB) keeps that one's resident
#: size as its peak across ``exec`` (Linux records the old memory's high-water mark), so the
#: case's own peak is only measurable in a child of a small process. The launcher exits as its
#: case did (the same code, or killed by the same signal).
_LAUNCHER = """
import os, resource, signal, sys
out, memory, cmd = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
pid = os.fork()
if pid == 0:
    resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    os.execv(cmd[0], cmd)
_, raw, usage = os.wait4(pid, 0)
with open(out, "w") as f:
    f.write(str(usage.ru_maxrss))
if os.WIFSIGNALED(raw):
    signal.signal(os.WTERMSIG(raw), signal.SIG_DFL)
    os.kill(os.getpid(), os.WTERMSIG(raw))
sys.exit(os.waitstatus_to_exitcode(raw))
"""


def _spawned(
    argv: list[str], memory: int, err: int, env: dict[str, str] | None, cwd: str, peak: str
) -> int:
    """Start ``python -m fcplan argv`` (its own session, in ``cwd``) through :data:`_LAUNCHER`,
    which writes the case's peak resident memory to ``peak``; the launcher's pid."""
    full = {**os.environ, **(env or {})}
    full["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), full.get("PYTHONPATH", "")) if p)
    proc = subprocess.Popen(  # noqa: S603 - our own interpreter and module
        [
            sys.executable,
            "-S",
            "-c",
            _LAUNCHER,
            peak,
            str(memory),
            sys.executable,
            "-m",
            "fcplan",
            *argv,
        ],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=err,
        env=full,
        cwd=cwd,
        start_new_session=True,
    )
    proc.returncode = 0  # reaped below with wait4; Popen must not wait for it again
    return proc.pid


def run_cli(
    argv: list[str],
    *,
    cwd: str | os.PathLike[str],
    timeout: float,
    memory: int = MEMORY_LIMIT,
    fork: bool = False,
    prepare: Callable[[], None] | None = None,
    env: dict[str, str] | None = None,
    grace: float = ORPHAN_GRACE_S,
) -> Case:
    """Run ``fcplan argv`` in the folder ``cwd`` as a bounded case (see the module docstring).

    ``cwd`` should be a scratch folder: relative paths in hostile arguments (an output named
    ``nan`` or ``-1``) land there. ``prepare`` runs in a forked child before the command (``fork=True`` only), e.g. to inject a
    fault; ``env`` adds environment variables (spawned children only). A case over ``timeout``
    seconds is killed with its whole process group and is a hang.
    """
    if (prepare is not None and not fork) or (env is not None and fork):
        raise ValueError("prepare needs fork=True and env needs fork=False")
    with tempfile.TemporaryFile() as err, tempfile.TemporaryDirectory() as scratch:
        peak = os.path.join(scratch, "peak")
        t0 = time.monotonic()
        if fork:
            pid = _forked(argv, memory, err.fileno(), prepare, os.fspath(cwd))
        else:
            pid = _spawned(argv, memory, err.fileno(), env, os.fspath(cwd), peak)
        status, rss_kb = None, 0
        while time.monotonic() - t0 < timeout:
            done, raw, usage = os.wait4(pid, os.WNOHANG)
            if done:
                status, rss_kb = os.waitstatus_to_exitcode(raw), usage.ru_maxrss
                break
            time.sleep(0.02)
        else:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pid, signal.SIGKILL)
            rss_kb = os.wait4(pid, 0)[2].ru_maxrss
        seconds = time.monotonic() - t0
        orphans = _orphans(pid, grace)
        # the launcher's report of its case
        with contextlib.suppress(OSError, ValueError), open(peak) as f:
            rss_kb = int(f.read())
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    outcome = Outcome.ORPHAN if orphans else classify(status, text)
    return Case(list(argv), outcome, status, text, seconds, rss_kb / 1024, orphans)


class _HangError(Exception):
    pass


def _children() -> set[int]:
    """Live (non-zombie) child processes of this process."""
    me = os.getpid()
    out = set()
    for d in Path("/proc").iterdir():
        fields = _stat(int(d.name)) if d.name.isdigit() else None
        if fields is not None and fields[0] != "Z" and int(fields[1]) == me:
            out.add(int(d.name))
    return out


def run_in_process(argv: list[str], *, timeout: int, grace: float = ORPHAN_GRACE_S) -> Case:
    """Run :func:`fcplan.cli.main` on ``argv`` in this process's traced helper (see the module
    docstring and :mod:`tests.traced`), in this process's working folder, which must not be the
    checkout: relative paths in hostile arguments (an output named ``-`` or ``0x10``) land there.

    Examples
    --------
    >>> import os, tempfile
    >>> here = os.getcwd()
    >>> os.chdir(tempfile.mkdtemp())
    >>> run_in_process(["run", "nosuch"], timeout=60).outcome
    'clean error'
    >>> os.chdir(here)
    """
    if Path.cwd().resolve() == ROOT:
        raise RuntimeError(f"run_in_process: run cases in a scratch folder, not in {ROOT}")
    case, peak = traced_call(_in_helper, list(argv), timeout, grace)
    case.peak_mb = peak / 2**20
    return case


def _in_helper(argv: list[str], timeout: int, grace: float) -> Case:
    """The case of :func:`run_in_process`, run in the helper's main thread (``peak_mb`` 0)."""
    import io

    from fcplan.cli import main

    before = _children()
    err, status = io.StringIO(), None
    t0 = time.monotonic()
    try:
        with (
            time_bound(timeout, _HangError),
            contextlib.redirect_stderr(err),
            contextlib.redirect_stdout(io.StringIO()),
        ):
            status = main(argv)
    except _HangError:
        status = None
    except BaseException:  # noqa: BLE001 - anything escaping main is the finding
        err.write(traceback.format_exc())
        status = 1
    finally:
        seconds = time.monotonic() - t0
    deadline = time.monotonic() + grace
    while (left := _children() - before) and time.monotonic() < deadline:
        time.sleep(0.1)
    for pid in left:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    text = err.getvalue()
    outcome = Outcome.ORPHAN if left else classify(status, text)
    return Case(list(argv), outcome, status, text, seconds, 0.0, sorted(left))
