"""Progress of long experiments: one ``tqdm`` bar, counted in episodes, for compare and sweep.

:func:`~fcplan.experiments.compare` and :func:`~fcplan.experiments.sweep` take
``progress=True`` (the default: a bar on stderr), ``progress=False`` (silent; ``--quiet`` on the
command line) or a ``progress(done, total, row)`` callback of your own, called after each finished
episode (``row`` is the episode's result; a non-empty ``row["error"]`` counts as failed, and
sweeps mark failed rows with ``status``).

The bar is :class:`tqdm.auto.tqdm`: in a terminal it redraws one line in place (``compare:
40%|####      | 8/20 episodes [00:04<00:06, 1.90ep/s, failed=1]``); in Jupyter it is a widget updated in
place when ``ipywidgets`` is installed (the ``notebooks`` extra), else one text line redrawn at
most every 15 s, so an executed notebook stores a handful of updates instead of a line per
episode. Wherever stderr is not a terminal (logs, pipes, notebooks without widgets) it redraws at
most every 15 s. Its total may grow while it runs (``--seeds auto`` adds batches).

Examples
--------
>>> import io
>>> out = io.StringIO()
>>> with EpisodeBar("sweep", file=out) as bar:
...     bar(1, 2, {}); bar(2, 2, {"error": "boom"})
>>> "2/2" in out.getvalue() and "failed=1" in out.getvalue()
True
"""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from types import TracebackType
from typing import IO, Any

from fcplan.errors import FcplanError

__all__ = ["EpisodeBar", "Progress", "ProgressCallback", "episode_progress"]

ProgressCallback = Callable[[int, int, dict[str, Any]], None]
"""``progress(done, total, row)``, called after each finished episode."""

Progress = bool | ProgressCallback | None
"""What the ``progress`` argument of compare and sweep accepts."""

_QUIET_INTERVAL_S = 15.0  # redraw interval where stderr is not a terminal
_FORMAT = (
    "{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} episodes "
    "[{elapsed}<{remaining}, {rate_fmt}{postfix}]"
)


def _tqdm() -> Any:
    """:class:`tqdm.auto.tqdm`, imported without its 'IProgress not found' warning (a Jupyter
    kernel without ipywidgets gets the text bar, which is what the warning would say)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from tqdm.auto import tqdm
    return tqdm


def _failed(row: dict[str, Any]) -> bool:
    return bool(row.get("error")) or row.get("status", "ok") != "ok"


class EpisodeBar:
    """A ``progress(done, total, row)`` callback that draws a :class:`tqdm.auto.tqdm` bar.

    Use it as a context manager (or call :meth:`close`), which ends the bar's line.

    Parameters
    ----------
    label : str
        The bar's description (``"compare"``, ``"sweep"``).
    file : stream, optional
        Where to draw (default ``sys.stderr``).
    initial : int
        Episodes already done before the first call (a resumed sweep's stored episodes).
    """

    def __init__(self, label: str, *, file: IO[str] | None = None, initial: int = 0) -> None:
        self.label = label
        self.file = file if file is not None else sys.stderr
        self.initial = initial
        self.failed = 0
        self._bar: Any = None

    def _open(self, total: int) -> Any:
        isatty = getattr(self.file, "isatty", None)
        tty = bool(isatty is not None and isatty())
        return _tqdm()(
            total=total + self.initial,
            initial=self.initial,
            desc=self.label,
            unit="ep",
            bar_format=_FORMAT,
            file=self.file,
            mininterval=0.5 if tty else _QUIET_INTERVAL_S,
            dynamic_ncols=tty,
            leave=True,
        )

    def __call__(self, done: int, total: int, row: dict[str, Any]) -> None:
        if self._bar is None:
            self._bar = self._open(total)
        bar = self._bar
        if total + self.initial != bar.total:
            bar.total = total + self.initial
        if _failed(row):
            self.failed += 1
            bar.set_postfix(failed=self.failed, refresh=False)
        bar.update(done + self.initial - bar.n)

    def close(self) -> None:
        """Draw the final state and end the line (a no-op if nothing was drawn)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> EpisodeBar:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


def episode_progress(
    progress: Progress, label: str, *, initial: int = 0
) -> ProgressCallback | None:
    """The callback for a ``progress`` argument: an :class:`EpisodeBar` for ``True``, None for
    ``False``/None, a callable as given.

    Raises
    ------
    fcplan.FcplanError
        Anything else (one line).

    Examples
    --------
    >>> episode_progress(False, "compare") is None
    True
    """
    if progress is True:
        return EpisodeBar(label, initial=initial)
    if progress is False or progress is None:
        return None
    if callable(progress):
        return progress
    raise FcplanError(f"progress must be True, False or a callable, got {progress!r}")
