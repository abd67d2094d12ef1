"""Argument abuse (issue 17): every command, given bad arguments, bad scheduler specs or special
files, exits 2 with one line on stderr and no traceback, at once."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from fcplan.cli import main
from tests.cli.helpers import one_line_error

ROOT = Path(__file__).resolve().parents[2]

BAD_SPECS = [
    ("milp:slots=0", "slots"),
    ("milp:slots=x", "slots"),
    ("routing:time_limit=nan", "time_limit"),
    ("routing:time_limit=0", "time_limit"),
    ("routing:time_limit=-1", "time_limit"),
    ("greedy:route_length=0", "route_length"),
    ("greedy:route_length=x", "route_length"),
    ("greedy:route_length=1e999", "route_length"),
    ("greedy:nope=1", "unknown setting"),
    ("random:keep_probability=2", "keep_probability"),
    ("idle:x=1", "unknown setting"),
    ("nosuch", "unknown scheduler"),
    ("greedy:", "name:key=value"),
    ("greedy:=1", "name:key=value"),
    ("cbba:search_altitude=nan", "search_altitude"),
]
# Settings that make a scheduler meaningless (routing:max_visits=0 is not one: it lifts the cap,
# the tour mode of solvers.routing).
MEANINGLESS = ["routing:max_visits=-1", "routing:time_limit=0", "routing-pyvrp:iterations=0",
               "routing:scale=1e300", "routing-pyvrp:seed=99999999999999999999",
               "milp-cvxpy:time_limit=-1"]  # fmt: skip


def _sweep_file(folder: Path, spec: str) -> str:
    path = folder / "study.toml"
    path.write_text(f'scenarios = ["practice"]\nschedulers = ["{spec}"]\nseeds = "0"\n')
    return str(path)


@pytest.mark.parametrize("spec, named", BAD_SPECS)
@pytest.mark.parametrize("command", ["run", "compare", "sweep"])
def test_bad_scheduler_specs_are_one_line_for_every_command(command, spec, named, capsys, tmp_path):
    """run, compare and sweep check a spec through the same path (make_scheduler) and report
    it in one line naming the problem, before any episode runs."""
    argv = {
        "run": ["run", "practice", "-s", spec],
        "compare": ["compare", "--schedulers", spec, "--scenarios", "practice", "--seeds", "0"],
        "sweep": ["sweep", _sweep_file(tmp_path, spec), "--results", str(tmp_path / "r")],
    }[command]
    one_line_error(argv, capsys, named)
    assert not (tmp_path / "r").exists() or not list((tmp_path / "r").glob("*.parquet"))


@pytest.mark.parametrize("spec", MEANINGLESS)
def test_meaningless_settings_of_other_schedulers_are_refused(spec, capsys):
    """Settings that make routing, cbba or milp-cvxpy meaningless are refused in one line."""
    one_line_error(["run", "practice", "-s", spec], capsys, spec.split(":")[1].split("=")[0])


def _special(tmp_path: Path) -> dict[str, str]:
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:
        fh.truncate(2**30)  # sparse: 1 GiB that costs nothing
    return {"/dev/zero": "not a regular file", str(fifo): "not a regular file",
            str(big): "larger than 2 MiB", str(tmp_path): "not a regular file"}  # fmt: skip


@pytest.mark.parametrize("command", ["run", "validate", "compare", "sweep", "replay"])
def test_special_files_are_refused_without_reading_them(command, capsys, tmp_path):
    """A device, a FIFO (which would block a reader), a 1 GiB file and a folder given as a
    scenario, a sweep file or a recording are refused at once, in one line."""
    for path, problem in _special(tmp_path).items():
        argv = {
            "run": ["run", path],
            "validate": ["scenario", "validate", path],
            "compare": ["compare", "--schedulers", "idle", "--scenarios", path],
            "sweep": ["sweep", path, "--results", str(tmp_path / "r")],
            "replay": ["replay", path],
        }[command]
        if command == "replay" and "larger" in problem:
            continue  # recordings may be large; a sparse file fails as a bad recording instead
        one_line_error(argv, capsys, path if command != "replay" else "not a regular file")


BAD_ARGUMENTS = [
    ["run", "practice", "--seed", "-1"],
    ["run", "practice", "--replan-period", "nan"],
    ["run", "practice", "--time-limit", "0"],
    ["run", "practice", "--time-limit", "inf"],
    ["run", "nosuch"],
    ["run", "missing.toml"],
    ["run", "practice", "--record", "/nonexistent/x.npz"],
    ["compare", "--schedulers", ""],
    ["compare", "--schedulers", "greedy", "--seeds", "5-1"],
    ["compare", "--schedulers", "greedy", "--jobs", "0"],
    ["compare", "--schedulers", "greedy", "--scenarios", "99"],
    ["compare", "--schedulers", "greedy", "--json", "/nonexistent/x.json"],
    ["sweep", "missing.toml"],
    ["sweep", "study.toml", "--jobs", "-3"],
    ["report", "/nonexistent"],
    ["report", "/dev/null"],
    ["replay", "/nonexistent.npz"],
    ["replay", "x.npz", "--fps", "0"],
    ["scenario", "validate"],
    ["scenario", "nosuch"],
    ["scenario", "validate", "nosuch"],
    ["import-legacy", "/nonexistent"],
    ["import-legacy", "/dev/zero"],
    ["play", "--seed", "x"],
    ["play", "--speed", "-1"],
    ["scenarios", "--nope"],
    ["--nope"],
    [],
]


@pytest.mark.parametrize("argv", BAD_ARGUMENTS, ids=lambda a: " ".join(a) or "(none)")
def test_bad_arguments_are_one_line_for_every_command(argv, capsys):
    """Bad values, missing files and unknown options of every command: exit 2, one line."""
    one_line_error(argv, capsys)


def test_long_messages_stay_one_short_line(capsys, tmp_path):
    """A message quoting a huge value is cut to MAX_MESSAGE characters, still one line."""
    from fcplan.cli.parser import MAX_MESSAGE
    from fcplan.scenario import load_scenario
    from tests.hardening.mutate import to_toml

    doc = load_scenario("practice").to_dict()
    doc["notes"] = [1] * 100_000
    f = tmp_path / "notes.toml"
    f.write_text(to_toml(doc))
    assert main(["scenario", "validate", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and len(err) <= MAX_MESSAGE and err.endswith("...")


def test_the_console_script_prints_no_traceback(tmp_path):
    """Through a real interpreter (no pytest around it): /dev/zero, a FIFO and a bad spec give
    exit 2 and a single stderr line; nothing blocks."""
    fifo = tmp_path / "f.toml"
    os.mkfifo(fifo)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for argv in (["run", "/dev/zero"], ["run", str(fifo)], ["run", "1", "-s", "milp:slots=0"]):
        p = subprocess.run(
            [sys.executable, "-m", "fcplan", *argv],
            capture_output=True,
            text=True,
            env=env,
            timeout=120,
        )
        assert p.returncode == 2, p.stderr
        assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
