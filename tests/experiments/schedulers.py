"""Run-time schedulers shared by the experiment tests (registered with monkeypatch.setitem)."""

from __future__ import annotations

import os
from pathlib import Path

from fcplan import scheduling


class DiesOnce:
    """A scheduler whose first plan() call anywhere kills its worker process (os._exit).

    The ``marker`` file records that it happened; with no marker it is plain greedy.
    """

    name = "dies-once"

    def __init__(self, marker: str = ""):
        self.marker = Path(marker)
        self._greedy = scheduling.make_scheduler("greedy")

    def plan(self, graph, *, time_limit=None, rng=None):
        if self.marker.name and not self.marker.exists():
            self.marker.touch()
            os._exit(3)
        return self._greedy.plan(graph, time_limit=time_limit, rng=rng)
