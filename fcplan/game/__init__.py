"""The FireCommander game: play a scenario yourself, with every game recorded.

``fcplan play`` is the interactive game of the FireCommander GUI (manual "GUI Reference Manual"):
a welcome screen with the scenario mode (practice and #1-#24 by difficulty), the open-world mode
(design a scenario step by step within the manual's limits, or load a TOML file, with a preview)
and a tutorial; in game the manual's controls, information display and online scores; at the end
the performance evaluation page with the verbal grade, and the playback. Games run at the
scenario's real-time pace and are recorded in the same format as scheduler runs
(:mod:`fcplan.recording`, ``source="human"``), so one dataset mixes human and scheduler
demonstrations.

Modules, from the bottom up (only the last two import pygame):

* :mod:`~fcplan.game.controls`: the manual's controls as :class:`fcplan.team.Command` objects;
* :mod:`~fcplan.game.scores`: the manual's metrics kept up to date tick by tick, shown as the
  metric table (:data:`fcplan.metrics.METRICS`) describes them;
* :mod:`~fcplan.game.session`: one game (world, controls, scores, recorder) and
  :func:`~fcplan.game.session.replay_inputs`;
* :mod:`~fcplan.game.designer`: the open-world designer;
* :mod:`~fcplan.game.layout`, :mod:`~fcplan.game.tutorial`, :mod:`~fcplan.game.storage`: where the
  buttons sit, the tutorial's text, where games are recorded;
* :mod:`~fcplan.game.screens`: the screens as a state machine (:class:`~fcplan.game.screens.App`);
* :mod:`~fcplan.game.view` and :mod:`~fcplan.game.app`: pygame drawing and the event loop;
* :mod:`fcplan.cli.play`: the ``fcplan play`` command.

Examples
--------
>>> from fcplan import load_scenario
>>> from fcplan.game import GameSession
>>> game = GameSession(load_scenario("practice").replace(duration_s=1), seed=0)
>>> game.input({"type": "key", "key": "1"})
>>> game.input({"type": "key", "key": "up"})
>>> while not game.done:
...     game.step()
>>> float(game.world.team.z[0])
25.0
"""

from fcplan.game.controls import Controller
from fcplan.game.designer import Design
from fcplan.game.scores import OnlineScores
from fcplan.game.session import GameSession, replay_inputs

__all__ = ["Controller", "Design", "GameSession", "OnlineScores", "replay_inputs"]
