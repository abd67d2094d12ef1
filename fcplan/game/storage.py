"""Where a human game is recorded: the recorder of a game and its default file.

Every ``fcplan play`` game is recorded (:class:`fcplan.recording.Recorder`, ``source="human"``,
with the game's settings: mode, speed, fast, ticks per second) so that one dataset mixes human and
scheduler demonstrations. Without ``--record PATH`` a game goes to the user's data folder
(:func:`default_recording_path`).

Examples
--------
>>> from fcplan import load_scenario
>>> rec = make_recorder(load_scenario("practice"), 0, speed=1.0)
>>> rec.source if rec is not None else "human"
'human'
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from typing import Any

__all__ = ["default_recording_path", "make_recorder"]


def default_recording_path(
    scenario: Any, seed: int, *, data_dir: str | os.PathLike[str] | None = None
) -> Path:
    """Where a game is recorded when no path is given: the user's data folder.

    ``$FCPLAN_DATA_DIR``, else ``$XDG_DATA_HOME/fcplan`` (``~/.local/share/fcplan``) on Linux,
    ``~/Library/Application Support/fcplan`` on macOS, ``%APPDATA%/fcplan`` on Windows; then
    ``recordings/<scenario>-seed<seed>-<UTC time>.npz``.

    Examples
    --------
    >>> from fcplan import load_scenario
    >>> p = default_recording_path(load_scenario(3), 7, data_dir="/tmp/x")
    >>> p.parent.as_posix(), p.name.startswith("03-seed7-")
    ('/tmp/x/recordings', True)
    """
    if data_dir is None:
        data_dir = os.environ.get("FCPLAN_DATA_DIR")
    if data_dir is None:
        if sys.platform == "win32":
            base = Path(os.environ.get("APPDATA", Path.home() / "AppData" / "Roaming"))
        elif sys.platform == "darwin":
            base = Path.home() / "Library" / "Application Support"
        else:
            base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
        data_dir = base / "fcplan"
    if scenario.number is not None:
        slug = "practice" if scenario.number == 0 else f"{scenario.number:02d}"
    else:
        slug = "".join(c if c.isalnum() else "-" for c in scenario.name).strip("-") or "design"
    stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
    return Path(data_dir) / "recordings" / f"{slug}-seed{seed}-{stamp}.npz"


def make_recorder(scenario: Any, seed: int, speed: float, fast: bool = False) -> Any:
    """A :class:`fcplan.recording.Recorder` for a human game, or None if it is unavailable."""
    try:
        from fcplan.recording import Recorder
    except ImportError:
        return None
    settings = {
        "game": "fcplan play",
        "mode": "scenario" if scenario.number is not None else "open-world",
        "speed": float(speed),
        "fast": bool(fast),
        "ticks_per_second": int(scenario.ticks_per_second),
    }
    return Recorder(scenario, seed, source="human", settings=settings)
