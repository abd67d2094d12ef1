"""Start-up of the ``fcplan`` command: which modules a quick command imports (not timings;
``bench/bench_startup.py`` measures the seconds)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: Libraries that cost tenths of a second (or more) to import; none is needed to show help or
#: list the shipped scenarios.
HEAVY = ("scipy", "pandas", "pyarrow", "pygame", "ortools", "cvxpy", "pyvrp", "networkx",
         "matplotlib", "dask", "imageio", "PIL", "pettingzoo", "gymnasium", "solvers")  # fmt: skip

_PROBE = """
import json, sys
from fcplan.cli import main
code = main(sys.argv[2:])
with open(sys.argv[1], "w") as fh:
    json.dump({"code": code, "modules": sorted(sys.modules)}, fh)
"""


def imported_by(tmp_path: Path, *argv: str) -> tuple[int, set[str]]:
    """Exit status and top-level packages imported by ``fcplan argv`` in a fresh interpreter."""
    out = tmp_path / "modules.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run(
        [sys.executable, "-c", _PROBE, str(out), *argv],
        check=True,
        capture_output=True,
        env=env,
        timeout=120,
    )
    doc = json.loads(out.read_text())
    return doc["code"], {m.split(".")[0] for m in doc["modules"]}


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["run", "--nope"], ["scenarios"]])
def test_quick_commands_import_no_heavy_library(tmp_path, argv):
    """``fcplan --help``, ``--version``, an argument error and ``fcplan scenarios`` import none of
    scipy, pandas, pygame, ortools, cvxpy, networkx (nor the solvers, plotting or env stacks)."""
    code, modules = imported_by(tmp_path, *argv)
    assert code == (2 if "--nope" in argv else 0)
    assert not modules & set(HEAVY), sorted(modules & set(HEAVY))


def test_help_does_not_even_import_numpy(tmp_path):
    """Building the parser imports the command modules only: ``fcplan --help`` loads no numpy."""
    code, modules = imported_by(tmp_path, "--help")
    assert code == 0 and "numpy" not in modules and "fcplan" in modules
