"""Provenance: every stored result names its libraries and the code that produced it."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from fcplan import provenance
from fcplan.experiments.config import load_sweep_config
from fcplan.experiments.play import code_version, play_episode

ROOT = Path(__file__).resolve().parents[1]


def test_code_identity_names_the_source_digest_and_the_checkout():
    """The digest is 16 hex digits; in a git checkout the commit is HEAD's and dirty says
    whether the packages' files differ from it."""
    ident = provenance.code_identity()
    assert re.fullmatch(r"[0-9a-f]{16}", ident["source"])
    head = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True
    )
    if head.returncode != 0 or provenance._package_dirs()[0].parent != ROOT:
        pytest.skip("not running from a git checkout of fcplan")
    assert ident["commit"] == head.stdout.strip()
    status = subprocess.run(
        ["git", "-C", str(ROOT), "status", "--porcelain", "--", "fcplan", "solvers"],
        capture_output=True,
        text=True,
    ).stdout
    assert ident["dirty"] is bool(status)


def test_the_digest_covers_every_python_file_of_both_packages():
    """Every .py file of fcplan/ and solvers/ is hashed (paths and bytes), so leaving one out
    changes the digest."""
    files = provenance.source_files()
    dirs = provenance._package_dirs()
    names = {
        f"{d.name}/{p.relative_to(d).as_posix()}" for p in files for d in dirs if d in p.parents
    }
    assert "fcplan/provenance.py" in names and "solvers/greedy.py" in names
    assert provenance._digest(files) == provenance.code_identity()["source"]
    assert provenance._digest(files[1:]) != provenance._digest(files)


def test_library_versions_leave_out_what_is_not_installed():
    """Python is always named; installed libraries by version; missing ones left out."""
    v = provenance.library_versions(("numpy", "surely-not-a-distribution"))
    assert set(v) == {"python", "numpy"}


def test_every_sweep_row_names_its_code():
    """A sweep episode's row carries ``code``: the JSON of code_identity() of its worker."""
    spec = load_sweep_config(
        {"scenarios": ["practice"], "schedulers": ["idle"], "seeds": [0],
         "overrides": {"duration_s": 2}}
    ).episodes()[0]  # fmt: skip
    row = play_episode(spec)
    assert json.loads(row["code"]) == provenance.code_identity()
    assert row["code"] == code_version()
