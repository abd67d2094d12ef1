"""Progress bars of the long single commands (``fcplan run``, ``fcplan replay --video``).

One style for every command: a :mod:`tqdm` bar (``tqdm.auto``, which updates in place in a
terminal and in Jupyter) on stderr, so stdout keeps only the results. A bar appears only when the
work lasts longer than :data:`DELAY_S` seconds and stderr is a terminal: short commands, pipes,
redirections and tests print nothing extra, and the printed results never depend on it. The bar
is removed when the work is done (``leave=False``), so the results that follow stay together.

:class:`EpisodeProgress` counts an episode in simulated seconds (an observer of the
:class:`~fcplan.mission.Mission`, updated once per simulated second, so it costs nothing
measurable per tick); :func:`progress_bar` is the bar itself, also used for video frames.

Examples
--------
>>> import io
>>> progress_bar(10, desc="frames", unit="frame", file=io.StringIO()).disable  # not a terminal
True
>>> bar = progress_bar(10, desc="frames", unit="frame", file=io.StringIO(), disable=False)
>>> bar.update(10); bar.n
10
>>> bar.close()
"""

from __future__ import annotations

import sys
from typing import IO, Any

from tqdm.auto import tqdm

from fcplan.mission import BaseObserver
from fcplan.world import StepInfo, World

__all__ = ["DELAY_S", "EpisodeProgress", "progress_bar"]

#: Seconds of work before a bar is shown.
DELAY_S = 2.0


def progress_bar(
    total: float,
    *,
    desc: str,
    unit: str,
    file: IO[str] | None = None,
    disable: bool | None = None,
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
    disable : bool, optional
        None (default): shown only when ``file`` is a terminal; False: always; True: never.
    """
    out = sys.stderr if file is None else file
    if disable is None:
        disable = not (hasattr(out, "isatty") and out.isatty())
    return tqdm(
        total=total,
        desc=desc,
        unit=unit,
        file=out,
        delay=DELAY_S,
        leave=False,
        disable=disable,
    )


class EpisodeProgress(BaseObserver):
    """Moves ``bar`` (in simulated seconds) as an episode runs; ticks at ``ticks_per_second``.

    Examples
    --------
    >>> import io
    >>> from fcplan import run_episode
    >>> bar = progress_bar(180, desc="#1", unit="s", file=io.StringIO(), disable=False)
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
