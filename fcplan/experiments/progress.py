"""Progress reporting for long experiments: a terminal progress bar, or plain lines.

Both are ``progress(done, total, row)`` callbacks, called after each finished episode (``row`` is
the episode's result dict; a non-empty ``row["error"]`` counts as failed).

* :class:`ProgressPrinter` prints throttled plain lines (``sweep: 12/40 episodes (30%), 2.1/s,
  elapsed 0:06, ETA 0:13``): for logs, CI and pipes.
* :class:`ProgressBar` redraws one line in place (``\\r``) with a bar, the rate and the ETA, when
  its stream is a terminal, and falls back to :class:`ProgressPrinter` lines otherwise.

:func:`make_progress` picks the right one for a stream.

Examples
--------
>>> import io
>>> out = io.StringIO()
>>> bar = make_progress(out, label="sweep")  # not a terminal: plain lines
>>> bar(1, 2, {}); bar(2, 2, {"error": "boom"})
>>> print(out.getvalue().splitlines()[-1])  # doctest: +ELLIPSIS
sweep: 2/2 episodes (100%), ... 1 failed
"""

from __future__ import annotations

import math
import sys
import time
from typing import IO, Any

__all__ = ["ProgressBar", "ProgressPrinter", "make_progress"]


def _clock(seconds: float) -> str:
    s = int(round(seconds)) if math.isfinite(seconds) else 0
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class ProgressPrinter:
    """A ``progress`` callback that prints plain lines, throttled.

    Each line reads ``compare: 12/40 episodes (30%), 2.1/s, elapsed 0:06, ETA 0:13`` (plus the
    number of failed episodes, if any). At most one line per ``interval`` seconds, and always one
    for the last episode.

    Parameters
    ----------
    stream : file, optional
        Where to print (default ``sys.stderr``).
    interval : float
        Minimum seconds between lines.
    label : str
        The line's prefix.
    """

    def __init__(
        self, stream: IO[str] | None = None, interval: float = 1.0, label: str = "compare"
    ):
        self.stream = stream
        self.interval = interval
        self.label = label
        self._t0 = time.perf_counter()
        self._last = -math.inf
        self._errors = 0

    def _status(self, done: int, total: int) -> tuple[str, float, float]:
        elapsed = time.perf_counter() - self._t0
        rate = done / elapsed if elapsed > 0 else math.inf
        eta = (total - done) / rate if rate > 0 and math.isfinite(rate) else 0.0
        return f"{rate:.1f}/s", elapsed, eta

    def _due(self, done: int, total: int, row: dict[str, Any]) -> bool:
        """Count a failed episode; say whether a line is due (throttled; always at the end)."""
        if row.get("error"):
            self._errors += 1
        now = time.perf_counter()
        if done < total and now - self._last < self.interval:
            return False
        self._last = now
        return True

    def __call__(self, done: int, total: int, row: dict[str, Any]) -> None:
        if not self._due(done, total, row):
            return
        rate, elapsed, eta = self._status(done, total)
        text = (
            f"{self.label}: {done}/{total} episodes ({100 * done / max(total, 1):.0f}%), {rate}, "
            f"elapsed {_clock(elapsed)}, ETA {_clock(eta)}"
        )
        if self._errors:
            text += f", {self._errors} failed"
        print(text, file=self.stream or sys.stderr, flush=True)


class ProgressBar(ProgressPrinter):
    """A one-line progress bar redrawn in place (for terminals).

    ``sweep [##########----------] 12/40 30% 2.1 ep/s ETA 0:13, 1 failed``; redrawn at most every
    ``interval`` seconds and ended with a newline after the last episode.
    """

    def __init__(
        self,
        stream: IO[str] | None = None,
        interval: float = 0.2,
        label: str = "sweep",
        width: int = 24,
    ):
        super().__init__(stream, interval, label)
        self.width = width

    def __call__(self, done: int, total: int, row: dict[str, Any]) -> None:
        if not self._due(done, total, row):
            return
        elapsed = time.perf_counter() - self._t0
        rate = done / elapsed if elapsed > 0 else 0.0
        eta = (total - done) / rate if rate > 0 else math.nan
        fill = int(round(self.width * done / max(total, 1)))
        bar = "#" * fill + "-" * (self.width - fill)
        text = (
            f"\r{self.label} [{bar}] {done}/{total} {100 * done / max(total, 1):3.0f}% "
            f"{60 * rate:.1f} ep/min ETA {_clock(eta) if eta == eta else '?'}"
        )
        if self._errors:
            text += f", {self._errors} failed"
        stream = self.stream or sys.stderr
        stream.write(text + "\x1b[K" + ("\n" if done >= total else ""))
        stream.flush()


def make_progress(stream: IO[str] | None = None, *, label: str = "sweep") -> ProgressPrinter:
    """A :class:`ProgressBar` if ``stream`` (default stderr) is a terminal, else plain lines."""
    stream = stream or sys.stderr
    isatty = getattr(stream, "isatty", None)
    if isatty is not None and isatty():
        return ProgressBar(stream, label=label)
    return ProgressPrinter(stream, label=label)
