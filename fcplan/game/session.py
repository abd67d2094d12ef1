"""One human game: world, controls, online scores and recording, without any window.

:class:`GameSession` is the part of ``fcplan play`` that decides what happens; the pygame front end
(:mod:`fcplan.game.app`) only turns mouse and keyboard events into input dicts, calls :meth:`step`
at the scenario's pace and draws. The game is a :class:`fcplan.mission.Mission` whose commands
come from a human instead of a scheduler; the recorder is one of its observers. Each tick:

1. the inputs received since the last tick (stamped with the current tick) go to the
   :class:`~fcplan.game.controls.Controller` and, as raw dicts, to the observers' ``on_input``;
2. the controller's commands go to :meth:`Mission.step <fcplan.mission.Mission.step>`, which
   tells the observers (``on_commands``, so a recording re-simulates exactly), advances the world
   and updates the team's belief (the fire the player can see) and tells them ``on_step`` (the
   online scores are recomputed from the world's trace when the display asks for them).

Because the controller is deterministic, :func:`replay_inputs` plays the same inputs at the same
ticks and reaches the same outcome as the original game.

Examples
--------
>>> from fcplan import load_scenario
>>> s = load_scenario("practice").replace(duration_s=2)
>>> game = GameSession(s, seed=0)
>>> game.input({"type": "key", "key": "3"})
>>> game.input({"type": "click", "map": [300, 500]})
>>> while not game.done:
...     game.step()
>>> game.world.tick, len(game.inputs)
(20, 2)
>>> again = replay_inputs(s, 0, game.inputs)
>>> again.metrics().final_score == game.metrics().final_score
True
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from fcplan.belief import Belief
from fcplan.game.controls import Controller
from fcplan.game.scores import OnlineScores
from fcplan.metrics import Metrics, compute_all
from fcplan.mission import EpisodeObserver, Mission
from fcplan.scenario import Scenario
from fcplan.team import Command
from fcplan.world import StepInfo, World

__all__ = ["GameSession", "replay_inputs"]


class GameSession:
    """A game of one scenario played by a human (or a script of inputs).

    Parameters
    ----------
    scenario : fcplan.scenario.Scenario
    seed : int
        Seed of the world (fire, sensing and pruning draws).
    recorder : EpisodeObserver, optional
        A :class:`fcplan.recording.Recorder` (or any observer of the game's mission).
    observers : iterable of EpisodeObserver
        More observers of the game's mission.

    Attributes
    ----------
    mission : fcplan.mission.Mission
        The game's episode (world, belief, observers).
    world : fcplan.world.World
    controller : Controller
    scores : OnlineScores
    belief : fcplan.belief.Belief
        What the team knows (the fire the player can see).
    inputs : list of dict
        Every input so far, each with its ``"tick"``.
    commands : list of (int, dict)
        Every non-empty command dict given to the world, with the tick it was applied at.
    last_info : fcplan.world.StepInfo or None
        What the last tick did.
    """

    def __init__(
        self,
        scenario: Scenario,
        seed: int = 0,
        *,
        recorder: EpisodeObserver | None = None,
        observers: Iterable[EpisodeObserver] = (),
    ) -> None:
        self.scenario = scenario
        self.seed = seed
        self.recorder = recorder
        watchers = [*([recorder] if recorder is not None else []), *observers]
        self.mission = Mission(scenario, seed, observers=watchers)
        self.world: World = self.mission.world
        belief = self.mission.belief
        assert belief is not None  # (a mission keeps a belief by default)
        self.belief: Belief = belief
        self.controller = Controller(self.world)
        self.scores = OnlineScores(self.world)
        self.inputs: list[dict[str, Any]] = []
        self.commands: list[tuple[int, dict[str, Command]]] = []
        self.last_info: StepInfo | None = None

    @property
    def done(self) -> bool:
        """True once the scenario's duration has been played."""
        return self.world.done

    @property
    def tick(self) -> int:
        """Ticks played."""
        return self.world.tick

    def input(self, event: Mapping[str, Any]) -> None:
        """Take one input dict (see :mod:`fcplan.game.controls`); it applies at the next tick."""
        if self.done:
            return
        ev = {k: v for k, v in event.items() if k != "tick"}
        ev["tick"] = self.world.tick
        self.controller.handle(ev)
        self.inputs.append(ev)
        self.mission.notify_input(dict(ev))

    def step(self) -> None:
        """Advance the world one tick with the commands collected since the last tick."""
        if self.done:
            return
        commands = self.controller.take_commands()
        if commands:
            self.commands.append((self.world.tick, commands))
        self.last_info = self.mission.step(commands or None)

    def metrics(self) -> Metrics:
        """The manual metrics so far (online, cheap)."""
        return self.scores.metrics()

    def final_metrics(self) -> dict[str, Metrics]:
        """Both metric definitions computed from the world's full trace."""
        return compute_all(self.world.trace())


def replay_inputs(
    scenario: Scenario, seed: int, inputs: Iterable[Mapping[str, Any]]
) -> GameSession:
    """Play a whole game from recorded inputs (dicts with a ``"tick"``) and return it.

    Each input is applied when the world reaches its tick, before that tick's step, as in the
    original game.

    Examples
    --------
    >>> from fcplan import load_scenario
    >>> s = load_scenario("practice").replace(duration_s=1)
    >>> replay_inputs(s, 0, [{"type": "key", "key": "2", "tick": 3}]).controller.selected
    1
    """
    game = GameSession(scenario, seed)
    events = sorted(inputs, key=lambda e: int(e["tick"]))  # stable: keeps same-tick order
    k = 0
    while not game.done:
        while k < len(events) and int(events[k]["tick"]) <= game.tick:
            game.input(events[k])
            k += 1
        game.step()
    return game
