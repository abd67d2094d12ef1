"""Progress bars of the long single commands (``fcplan run``, ``fcplan replay --video``).

The style of ``fcplan compare`` and ``fcplan sweep`` (:mod:`fcplan.experiments.progress`), in
the units of the work: a :mod:`tqdm` bar (``tqdm.auto``, which updates in place in a terminal and
in Jupyter) on stderr, so stdout keeps only the results, which never depend on it. It appears
only when the work lasts longer than :data:`DELAY_S` seconds, so quick commands print nothing
extra; in a terminal it redraws twice a second, elsewhere (a log, a pipe) at most every
:data:`QUIET_INTERVAL_S` seconds, so a long run leaves a few lines, not hundreds.

:class:`EpisodeProgress` counts an episode in simulated seconds (an observer of the
:class:`~fcplan.mission.Mission`, updated once per simulated second, so it costs nothing
measurable per tick); :func:`progress_bar` is the bar itself, also used for video frames.

Examples
--------
>>> import io
>>> out = io.StringIO()
>>> bar = progress_bar(10, desc="video", unit="frame", file=out)
>>> bar.update(10); bar.n
10
>>> bar.close(); out.getvalue()  # done before DELAY_S: nothing drawn
''

"""

from __future__ import annotations

import sys
import warnings
from typing import IO, Any

from fcplan.mission import BaseObserver
from fcplan.world import StepInfo, World

__all__ = ["DELAY_S", "QUIET_INTERVAL_S", "EpisodeProgress", "progress_bar"]

#: Seconds of work before a bar is shown.
DELAY_S = 2.0
#: Seconds between redraws where stderr is not a terminal.
QUIET_INTERVAL_S = 15.0


def progress_bar(
    total: float,
    *,
    desc: str,
    unit: str,
    file: IO[str] | None = None,
    disable: bool = False,
) -> Any:
    """A tqdm bar on ``file`` (default stderr), shown after :data:`DELAY_S` seconds.

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
    """
    out = sys.stderr if file is None else file
    isatty = getattr(out, "isatty", None)
    tty = bool(isatty is not None and isatty())
    with warnings.catch_warnings():  # Jupyter without ipywidgets: the text bar, no warning
        warnings.simplefilter("ignore")
        from tqdm.auto import tqdm
    return tqdm(
        total=total,
        desc=desc,
        unit=f" {unit}",
        file=out,
        delay=DELAY_S,
        mininterval=0.5 if tty else QUIET_INTERVAL_S,
        dynamic_ncols=tty,
        leave=True,
        disable=disable,
    )


class EpisodeProgress(BaseObserver):
    """Moves ``bar`` (in simulated seconds) as an episode runs; ticks at ``ticks_per_second``.

    Examples
    --------
    >>> import io
    >>> from fcplan import run_episode
    >>> bar = progress_bar(180, desc="#1", unit="s", file=io.StringIO())
    >>> _ = run_episode(1, "idle", observers=[EpisodeProgress(bar, 10)])
    >>> bar.n
    180
    """

    def __init__(self, bar: Any, ticks_per_second: int) -> None:
        self.bar = bar
        self.ticks_per_second = ticks_per_second

    def on_step(self, world: World, info: StepInfo) -> None:
        """Advance the bar by one simulated second after each whole second."""
        if world.tick % self.ticks_per_second == 0:
            self.bar.update(1)
