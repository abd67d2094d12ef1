"""Progress bars of the long single commands (``fcplan run``, ``fcplan replay --video``).

The style of ``fcplan compare`` and ``fcplan sweep`` (:mod:`fcplan.experiments.progress`), in
the units of the work: a :mod:`tqdm` bar (``tqdm.auto``, which updates in place in a terminal and
in Jupyter) on stderr, so stdout keeps only the results, which never depend on it. It appears
only when the work lasts longer than :data:`DELAY_S` seconds, so quick commands print nothing
extra; in a terminal it redraws twice a second, elsewhere (a log, a pipe) at most every
:data:`QUIET_INTERVAL_S` seconds, so a long run leaves a few lines, not hundreds.

:class:`EpisodeProgress` counts an episode in simulated seconds (an observer of the
:class:`~fcplan.mission.Mission`, updated once per simulated second, so it costs nothing
measurable per tick); :class:`LazyBar` is the bar itself, also used for video frames.

Examples
--------
>>> import io
>>> out = io.StringIO()
>>> bar = LazyBar(10, desc="video", unit="frame", file=out)
>>> bar.update(10); bar.n
10
>>> bar.close(); out.getvalue()  # done before DELAY_S: nothing drawn (tqdm not even imported)
''

"""

from __future__ import annotations

import sys
import time
import warnings
from typing import IO, Any

from fcplan.mission import BaseObserver
from fcplan.world import StepInfo, World

__all__ = ["DELAY_S", "QUIET_INTERVAL_S", "EpisodeProgress", "LazyBar"]

#: Seconds of work before a bar is shown.
DELAY_S = 2.0
#: Seconds between redraws where stderr is not a terminal.
QUIET_INTERVAL_S = 15.0


class LazyBar:
    """A bar on ``file`` (default stderr): counts work and becomes a :class:`tqdm.auto.tqdm` bar
    once it has lasted :data:`DELAY_S` seconds, so a quick command never imports tqdm (about
    0.1 s of start-up with its asyncio support). Use it as a context manager, or call
    :meth:`close`.

    Parameters
    ----------
    total : float
        Units of work.
    desc, unit : str
        Label before the bar, and the name of one unit (``"frame"``, ``"s"``).
    file : text stream, optional
        Where the bar goes (default ``sys.stderr``).
    disable : bool
        Draw nothing.

    Attributes
    ----------
    n : float
        Work done so far.
    """

    def __init__(
        self,
        total: float,
        *,
        desc: str,
        unit: str,
        file: IO[str] | None = None,
        disable: bool = False,
    ) -> None:
        self.total, self.desc, self.unit, self.disable = total, desc, unit, disable
        self.file = sys.stderr if file is None else file
        self.n: float = 0
        self._start = time.monotonic()
        self._bar: Any = None

    def update(self, k: float = 1) -> None:
        """Count ``k`` more units; draw (or start drawing) the bar when it is due."""
        self.n += k
        if self._bar is not None:
            self._bar.update(k)
        elif not self.disable and time.monotonic() - self._start >= DELAY_S:
            self._bar = self._open()

    def _open(self) -> Any:
        isatty = getattr(self.file, "isatty", None)
        tty = bool(isatty is not None and isatty())
        with warnings.catch_warnings():  # Jupyter without ipywidgets: the text bar, no warning
            warnings.simplefilter("ignore")
            from tqdm.auto import tqdm
        bar = tqdm(
            total=self.total,
            initial=self.n,
            desc=self.desc,
            unit=f" {self.unit}",
            file=self.file,
            mininterval=0.5 if tty else QUIET_INTERVAL_S,
            dynamic_ncols=tty,
            leave=True,
        )
        bar.start_t -= (
            time.monotonic() - self._start
        )  # its rate and elapsed time count from the start
        return bar

    def close(self) -> None:
        """End the bar's line (nothing if it never appeared)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> LazyBar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class EpisodeProgress(BaseObserver):
    """Moves ``bar`` (in simulated seconds) as an episode runs; ticks at ``ticks_per_second``.

    Examples
    --------
    >>> import io
    >>> from fcplan import run_episode
    >>> bar = LazyBar(180, desc="#1", unit="s", file=io.StringIO())
    >>> _ = run_episode(1, "idle", observers=[EpisodeProgress(bar, 10)])
    >>> bar.n
    180
    """

    def __init__(self, bar: LazyBar, ticks_per_second: int) -> None:
        self.bar = bar
        self.ticks_per_second = ticks_per_second

    def on_step(self, world: World, info: StepInfo) -> None:
        """Advance the bar by one simulated second after each whole second."""
        if world.tick % self.ticks_per_second == 0:
            self.bar.update(1)
