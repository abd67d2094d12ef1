"""The hostile files of issues 15 and 17, each read in a forked child with its peak memory
measured (``resource.getrusage``): every one gives the reader's own error (or, for a recording
with a decompression bomb in an undocumented entry, loads without decompressing it), quickly and
within a small memory bound; never a crash, a hang or an out-of-memory."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from tests.fuzz.cases import adversarial_cases, mini_legacy_folder, short_recording

pytestmark = pytest.mark.skipif(
    not (hasattr(os, "fork") and os.path.exists("/proc/self/statm")),
    reason="the worker forks and reads /proc (Linux)",
)

#: peak resident memory a hostile input may add (the old readers took 2-5 GB, or crashed)
MAX_GROWTH_MB = 128
#: seconds a hostile input may take (the old readers took up to 59 s)
MAX_SECONDS = 20


@pytest.fixture(scope="module")
def seeds(tmp_path_factory):
    """A short synthetic legacy folder and a 3-s recording, the bases of the hostile inputs."""
    tmp = tmp_path_factory.mktemp("fuzzseeds")
    mini_legacy_folder(str(tmp / "folder"))
    return str(tmp / "folder"), short_recording(str(tmp / "seed.npz"))


def test_hostile_inputs_give_clean_errors_within_bounds(seeds, tmp_path):
    """Every adversarial input (object array from raw bytes, memo index 3e8, shared and deep
    nesting, NaN world size, decompression bomb, 7 TiB declared shape, nested header JSON,
    missing scenario, NaN and absurd positions, unknown compression, a flipped bit, FIFOs) gives
    the reader's own error (the bomb's undocumented entry is ignored: it loads), in a child that
    grows by less than 128 MB and finishes within 20 s."""
    folder, rec = seeds
    cases = adversarial_cases(str(tmp_path), folder, rec)
    listing = tmp_path / "cases.json"
    listing.write_text(json.dumps([[n, t, p] for n, (t, p) in cases.items()]))
    env = dict(os.environ, PYTHONPATH=os.getcwd() + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.run(
        [sys.executable, "-m", "tests.fuzz.worker", str(listing), "--timeout", str(MAX_SECONDS)],
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
        check=True,
    )
    results = [json.loads(line) for line in proc.stdout.splitlines()]
    assert [r["name"] for r in results] == list(cases)
    for r in results:
        want = "loaded" if "bomb" in r["name"] else "clean"
        assert r["outcome"] == want, r
        assert r["rss_growth_mb"] < MAX_GROWTH_MB and r["seconds"] < MAX_SECONDS, r
        if want == "clean":
            assert cases[r["name"]][1] in r["message"], r  # the file (or folder) is named
