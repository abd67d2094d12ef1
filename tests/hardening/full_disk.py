"""A sweep into a real full disk: run as ``unshare -rm python -m tests.hardening.full_disk CONFIG
MNT`` (a private user and mount namespace, so the tmpfs is invisible outside and vanishes with
the process).

Mounts a 64 KiB tmpfs at ``MNT`` (room for the manifest and about two rows), runs
``fcplan sweep CONFIG --results MNT/results --jobs 2`` until the disk is full, counts the rows
that read back and the temporary files left, grows the tmpfs to 16 MiB and runs the same command
again (the resume). Prints one JSON object: ``status``, ``stderr`` of the first run, ``rows``
stored by it, ``stray`` temporary files, ``resume_status`` and ``resumed_rows``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from fcplan.experiments import load_results


def _sweep(config: str, results: Path) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "fcplan", "sweep", config, "--results", str(results), "-j", "2",
           "-q"]  # fmt: skip
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


def main(config: str, mnt: str) -> None:
    """Fill a tmpfs at ``mnt`` with the sweep of ``config``, then resume with room."""
    os.makedirs(mnt, exist_ok=True)
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", mnt], check=True)
    results = Path(mnt) / "results"
    first = _sweep(config, results)
    rows = len(load_results(results)) if results.exists() else 0
    stray = [p.name for p in results.glob(".*.tmp")] if results.exists() else []
    subprocess.run(["mount", "-o", "remount,size=16m", mnt], check=True)
    again = _sweep(config, results)
    print(json.dumps({
        "status": first.returncode, "stderr": first.stderr, "rows": rows, "stray": stray,
        "resume_status": again.returncode, "resumed_rows": len(load_results(results)),
    }))  # fmt: skip


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
