"""Every notebook in ``notebooks/`` runs top to bottom (executed with nbclient).

Convention for notebooks (``notebooks/NN_topic.ipynb``; follow it when adding one):

* **Small-settings switch.** The first code cell reads the environment variable
  ``FCPLAN_NOTEBOOK_SMALL`` and sets ``SMALL``::

      import os
      SMALL = os.environ.get("FCPLAN_NOTEBOOK_SMALL", "0") == "1"  # tests run with 1

  and every expensive number in the notebook derives from it (fewer scenarios, seeds, episodes,
  shorter ``duration_s``, smaller teams, fewer training steps), e.g.
  ``scenario = load_scenario(1).replace(duration_s=20 if SMALL else 180)``. With ``SMALL`` the
  whole notebook must run in <= ~20 s on a loaded 2-core machine (this test runs every notebook,
  90 s in all); without it, in a few minutes.
* **No dependence on the working directory or HOME.** The test runs each notebook in a fresh
  temporary working directory with ``HOME`` set to a temporary folder. Load scenarios through
  ``fcplan.load_scenario`` (names, not repo paths). Write outputs (Parquet results, figures)
  under the working directory (e.g. ``Path("results")``) or ``tempfile.mkdtemp()``.
* **Headless plots.** ``MPLBACKEND=Agg`` is set; use matplotlib (``plt.show()`` is harmless).
  No widgets, no ``input()``, no network, no display.
* **Determinism.** Seed everything explicitly (``seed=...`` / ``numpy.random.default_rng(seed)``).
* **Stored without outputs** (clear them before saving: ``jupyter nbconvert --clear-output
  --inplace notebooks/NN_topic.ipynb``), kernel ``python3``; the test replaces the kernel by the
  interpreter that runs pytest, so a fresh CI virtualenv works without any registered kernel.
* A notebook fails the test with the failing cell's number, source head and error.

How it runs: each notebook is executed by :class:`nbclient.NotebookClient` with a kernelspec that
this test writes into a temporary ``JUPYTER_PATH`` (``argv`` = ``sys.executable -m
ipykernel_launcher``), environment ``FCPLAN_NOTEBOOK_SMALL=1``, ``MPLBACKEND=Agg``, temporary
``HOME``/``IPYTHONDIR``, working directory ``tmp_path``, 300 s per cell.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))
KERNEL = "fcplan-test-python3"


def _kernelspec(root: Path) -> Path:
    """Write a kernelspec for the current interpreter under ``root``; return the JUPYTER_PATH."""
    kdir = root / "jupyter" / "kernels" / KERNEL
    kdir.mkdir(parents=True)
    spec = {
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "fcplan test (current interpreter)",
        "language": "python",
    }
    (kdir / "kernel.json").write_text(json.dumps(spec), encoding="utf-8")
    return root / "jupyter"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The notebook executes top to bottom with small settings, headless, in a temporary HOME."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    home = tmp_path / "home"
    work = tmp_path / "work"
    home.mkdir()
    work.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setenv("IPYTHONDIR", str(home / ".ipython"))
    monkeypatch.setenv("JUPYTER_PATH", str(_kernelspec(tmp_path)))
    monkeypatch.setenv("JUPYTER_CONFIG_DIR", str(home / ".jupyter"))
    monkeypatch.setenv("JUPYTER_DATA_DIR", str(home / ".local" / "share" / "jupyter"))
    monkeypatch.setenv("JUPYTER_RUNTIME_DIR", str(tmp_path / "runtime"))
    monkeypatch.setenv("JUPYTER_PLATFORM_DIRS", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("FCPLAN_NOTEBOOK_SMALL", "1")
    monkeypatch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        kernel_name=KERNEL,
        timeout=300,
        resources={"metadata": {"path": str(work)}},
    )
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as exc:
        idx, src = _failing_cell(nb)
        trace = re.sub(r"\x1b\[[0-9;]*m", "", str(exc))  # no terminal colours in the report
        pytest.fail(
            f"{path.name}: cell {idx} failed: {exc.ename}: {exc.evalue}\n--- cell source ---\n"
            f"{src}\n--- traceback ---\n{trace[-3000:]}",
            pytrace=False,
        )


def _failing_cell(nb) -> tuple[int | str, str]:
    """The index (among all cells) and source head of the first cell with an error output."""
    for i, cell in enumerate(nb.cells):
        for out in cell.get("outputs", []):
            if out.get("output_type") == "error":
                return i, "\n".join(cell.source.splitlines()[:15])
    return "?", ""
