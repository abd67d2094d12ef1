"""Tests of fcplan.cli.play that need no game: what ``fcplan play`` says when pygame is missing."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# an interpreter in which pygame cannot be found or imported, as on a machine without the extra
_NO_PYGAME = """
import sys
sys.modules["pygame"] = None
from fcplan.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_play_without_pygame_names_the_extra_before_the_display():
    """Without pygame, ``fcplan play`` says so (with both install forms) even on a machine with
    no display: the missing library is the first thing to fix, not the display."""
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "SDL_VIDEODRIVER")}
    p = subprocess.run(
        [sys.executable, "-c", _NO_PYGAME, "play", "--scenario", "1"],
        capture_output=True,
        text=True,
        env={**env, "PYTHONPATH": str(ROOT)},
        timeout=120,
    )
    assert p.returncode == 2
    assert p.stderr == (
        'fcplan: error: fcplan play needs pygame: pip install "fcplan[game]" '
        '(from a checkout: pip install -e ".[game]")\n'
    )
