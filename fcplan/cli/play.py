"""``fcplan play``: play FireCommander yourself in a pygame window; every game is recorded.

::

    fcplan play [--scenario NAME] [--seed N] [--record PATH] [--speed X] [--fast]
                [--frame-ticks N] [--inputs FILE] [--screenshot PNG] [--screenshot-at S]
                [--exit-at-end]

Opens :class:`fcplan.game.screens.App`: without ``--scenario`` its welcome screen (scenario mode,
open-world designer, tutorial), with it a game at once. ``--inputs`` plays recorded input events
again (a JSON script, or the recording of a human game). At the end it prints the final score and
where the game was recorded.

Examples
--------
>>> from fcplan.cli.util import Parser
>>> sub = Parser(prog="fcplan").add_subparsers(dest="command", parser_class=Parser)
>>> add_parser(sub)
>>> args = sub.choices["play"].parse_args(["--scenario", "1", "--speed", "2"])
>>> args.scenario, args.speed, args.seed
('1', 2.0, None)
"""

from __future__ import annotations

import argparse

from fcplan.cli.util import (
    CliError,
    SubParsers,
    check_output,
    positive_float,
    positive_int,
    scenario_name,
    seed,
)

__all__ = ["add_parser", "run"]


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan play`` to the ``fcplan`` sub-parsers ``sub``."""
    p = sub.add_parser(
        "play",
        help="play a scenario yourself (pygame window; every game is recorded)",
        description="Play FireCommander: keys 1-9 select an agent, clicks add goals (a click "
        "near the first goal closes a patrol loop, a click on the base sends the agent home), "
        "Up/Down change altitude, Space pauses, Esc ends the game. Without --scenario the "
        "welcome screen offers the scenario mode, the open-world designer and the tutorial. "
        "Headless: SDL_VIDEODRIVER=dummy.",
    )
    p.add_argument(
        "--scenario",
        type=scenario_name,
        help="start directly in this scenario: practice, 1..24, or a TOML",
    )
    p.add_argument("--seed", type=seed, default=None, help="random seed (integer >= 0, default 0)")
    p.add_argument("--record", metavar="PATH", help="save the recording here (default: user data "
                   "folder, fcplan/recordings/)")  # fmt: skip
    p.add_argument("--speed", type=positive_float, default=1.0,
                   help="real-time factor (default 1: the scenario's own pace)")  # fmt: skip
    p.add_argument("--fast", action="store_true",
                   help="do not wait for the clock: play as fast as the machine can")  # fmt: skip
    p.add_argument("--frame-ticks", type=positive_int, default=10,
                   help="ticks per drawn frame with --fast (default 10)")  # fmt: skip
    p.add_argument(
        "--inputs",
        metavar="FILE",
        help="play these inputs again: a JSON list of input events ({tick, type, key | map}), "
        "or a recording (.npz) of a human game, whose scenario and seed are then the defaults",
    )
    p.add_argument("--screenshot", metavar="PNG", help="save the window as PNG and quit")
    p.add_argument(
        "--screenshot-at",
        type=positive_float,
        default=None,
        metavar="S",
        help="simulated seconds (> 0) at which --screenshot is taken (default: at once)",
    )
    p.add_argument(
        "--exit-at-end",
        action="store_true",
        help="quit when the game ends instead of showing the evaluation page",
    )
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Run ``fcplan play``; print where the game was recorded and its score."""
    import importlib.util

    from fcplan.errors import install_hint

    if importlib.util.find_spec("pygame") is None:  # before the display: name what is missing
        raise CliError(f"fcplan play needs pygame: {install_hint('game')}")
    from fcplan.game.app import load_script, require_display, run_app
    from fcplan.game.screens import App

    if args.record is not None:
        check_output(args.record, "--record")
    script, scenario, game_seed = [], None, args.seed
    if args.inputs and str(args.inputs).endswith(".npz"):
        from fcplan.recording import load_recording

        rec = load_recording(args.inputs)
        if rec.source != "human":
            raise CliError(
                f"--inputs {args.inputs}: a {rec.source!r} recording has no human inputs"
            )
        script, scenario = list(rec.inputs), rec.scenario
        game_seed = rec.seed if game_seed is None else game_seed
    elif args.inputs:
        script = load_script(args.inputs)
    if args.scenario is not None:
        from fcplan.scenario import load_scenario

        scenario = load_scenario(args.scenario)
    if args.screenshot is not None and scenario is None:
        raise CliError("--screenshot needs --scenario (the screenshot shows a game)")
    require_display()
    app = App(
        scenario,
        seed=0 if game_seed is None else game_seed,
        record=args.record,
        speed=args.speed,
        fast=args.fast,
        frame_ticks=args.frame_ticks,
        exit_at_end=args.exit_at_end,
    )
    run_app(
        app,
        script=script,
        screenshot=args.screenshot,
        screenshot_at_s=args.screenshot_at,
        quit_after_screenshot=args.screenshot is not None,
    )
    if app.final is not None:
        m = app.final["manual"]
        played = app.game.world.time_s
        print(f"played {played:g} of {app.scenario.duration_s:g} s: final score {m.final_score:.2f}"
              f" ({m.grade})")  # fmt: skip
    if app.recording_path is not None and app.recording_path.exists():
        print(f"recorded to {app.recording_path}")
    return 0
