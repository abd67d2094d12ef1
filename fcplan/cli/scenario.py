"""``fcplan scenario``: validate scenario files, and draw new ones with the seeded generator.

::

    fcplan scenario validate FILE [FILE...]
    fcplan scenario generate --seed N [--preset default|hard|scale] [--<knob> VALUE | LO HI ...]
                             [-o FILE]

``validate``: each argument (a TOML file or a shipped scenario's name) is loaded and validated; an
invalid one stops the command with its one-line error (exit status 2). A valid one prints ``valid,
within the manual's limits`` or the limits of the manual's open-world GUI it exceeds, one per line
(:meth:`fcplan.scenario.Scenario.manual_limit_violations`).

``generate``: draws the scenario of ``--seed`` with :mod:`fcplan.scenario.generate` and prints its
TOML (or writes it to ``-o FILE``; ``-o -`` prints). The options are made from
:class:`~fcplan.scenario.generate.GeneratorConfig`'s fields: one per knob, named after it with
dashes (``n_regions`` is ``--n-regions``), taking one value (``--tank 3``) or, for a range knob,
one value or two (``--n-regions 2 5``: drawn uniformly in 2..5); ``--comm-range none`` turns the
communication limit off. Knobs not given keep the ``--preset``'s value. A bad value stops the
command with one line naming the option, the knob and its allowed range (exit status 2). The
scenario's notes record the exact call, so the file can be regenerated
(:func:`fcplan.scenario.recipe_of`).

Examples
--------
>>> from fcplan.cli.util import Parser
>>> p = Parser(prog="fcplan")
>>> add_parser(p.add_subparsers(dest="command", parser_class=Parser))
>>> p.parse_args(["scenario", "validate", "12", "my.toml"]).files
['12', 'my.toml']
>>> args = p.parse_args(["scenario", "generate", "--seed", "3", "--n-regions", "2", "5"])
>>> args.seed, args.preset, knob_values(args)
(3, 'default', {'n_regions': (2, 5)})
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from fcplan.cli.util import CliError, Parser, SubParsers, check_output, seed

if TYPE_CHECKING:
    from fcplan.scenario.knobs import Knob

__all__ = ["add_parser", "knob_values", "run", "run_generate"]

_RANGES = ("irange", "frange")


class _ScenarioParser(Parser):
    """A :class:`~fcplan.cli.util.Parser` that adds the generator's options (``generator=True``)
    only when it is used, so building ``fcplan``'s parser does not import the generator (and
    numpy) for every command."""

    def __init__(self, *args: Any, generator: bool = False, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._pending = generator

    def _complete(self) -> None:
        if self._pending:
            self._pending = False
            _add_generator_options(self)

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        self._complete()
        return super().parse_known_args(args, namespace)

    def format_usage(self) -> str:
        self._complete()
        return super().format_usage()

    def format_help(self) -> str:
        self._complete()
        return super().format_help()


def add_parser(sub: SubParsers) -> None:
    """Add ``fcplan scenario validate`` and ``fcplan scenario generate`` to ``sub``."""
    sc = sub.add_parser("scenario", help="scenario file tools: validate, generate")
    scs = sc.add_subparsers(dest="scenario_command", required=True, parser_class=_ScenarioParser)
    v = scs.add_parser("validate", help="validate scenario files and list manual limits exceeded")
    v.add_argument("files", nargs="+", help="TOML files or shipped scenario names")
    v.set_defaults(run=run)
    g = scs.add_parser(
        "generate",
        generator=True,
        help="draw a scenario with the seeded generator and print or write its TOML",
        description="Draw a scenario from --seed and the generator's knobs (one option per knob; "
        "a range knob takes one value or LO HI). Knobs not given keep the preset's value.",
    )
    g.add_argument("--seed", type=seed, required=True, help="generator seed (integer >= 0)")
    g.add_argument(
        "-o", "--output", metavar="FILE", default=None, help="write the TOML here ('-': print)"
    )
    g.set_defaults(run=run_generate)


def _add_generator_options(g: argparse.ArgumentParser) -> None:
    """``--preset`` and one option per knob of :class:`~fcplan.scenario.generate.GeneratorConfig`."""
    from fcplan.scenario.generate import PRESETS, GeneratorConfig
    from fcplan.scenario.knobs import knobs_of

    g.add_argument(
        "--preset",
        choices=list(PRESETS),
        default="default",
        help="starting knob values (default: the generator's defaults)",
    )
    knobs = g.add_argument_group("knobs", "one option per GeneratorConfig knob")
    for name, (spec, default) in knobs_of(GeneratorConfig).items():
        kwargs: dict[str, Any] = {"type": _parse_value(name, spec), "dest": f"knob_{name}"}
        if spec.kind in _RANGES:
            kwargs.update(nargs="+", metavar="V")
        elif spec.kind == "pair":
            kwargs.update(nargs=2, metavar=("LO", "HI"))
        else:
            kwargs["metavar"] = "V"
        knobs.add_argument(
            "--" + name.replace("_", "-"),
            help=f"{spec.doc}; {spec.short()} (default {_default_text(default)})",
            **kwargs,
        )


def _default_text(value: Any) -> str:
    if isinstance(value, tuple) and value[0] == value[1]:
        value = value[0]
    if isinstance(value, tuple):
        return " ".join(f"{v:g}" for v in value)
    return f"{value:g}" if isinstance(value, float) else str(value)


def _parse_value(name: str, spec: Knob) -> Any:
    """An argparse ``type`` turning one command-line word into the knob's kind of value."""

    def parse(text: str) -> Any:
        if spec.kind == "choice":
            return text
        if spec.kind == "optional" and text.strip().lower() == "none":
            return None
        try:
            return int(text) if spec.kind in ("int", "irange") else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"knob {name}: must be {spec.allowed()} (got {text!r})"
            ) from None

    parse.__name__ = name  # argparse names the type in some messages
    return parse


def knob_values(args: argparse.Namespace) -> dict[str, Any]:
    """The knob values given on the command line (``{knob: value}``; a range's two words become
    a ``(lo, hi)`` tuple).

    Raises
    ------
    CliError
        A range option given more than two values.
    """
    out: dict[str, Any] = {}
    for key, value in vars(args).items():
        if not key.startswith("knob_") or value is None:
            continue
        name = key.removeprefix("knob_")
        if isinstance(value, list):
            if len(value) > 2:
                option = "--" + name.replace("_", "-")
                raise CliError(
                    f"fcplan scenario generate: {option}: takes one value or two (LO HI), "
                    f"got {len(value)}"
                )
            value = value[0] if len(value) == 1 else tuple(value)
        out[name] = value
    return out


def run_generate(args: argparse.Namespace) -> int:
    """Draw the scenario and print its TOML or write it to ``args.output``."""
    from fcplan.errors import ScenarioError
    from fcplan.scenario import GeneratorConfig, dump_scenario

    out = None if args.output in (None, "-") else args.output
    check_output(out, "-o")
    knobs = knob_values(args)
    try:
        scenario = GeneratorConfig.preset(args.preset, **knobs)(args.seed)
    except ScenarioError as exc:
        if exc.field not in GeneratorConfig.KNOB_NAMES:
            raise
        option = "--" + exc.field.replace("_", "-")
        got = f" (got {exc.got!r})" if exc.field in knobs else ""
        raise CliError(
            f"fcplan scenario generate: {option} (knob {exc.field}): {exc.problem}{got}"
        ) from None
    text = dump_scenario(scenario)
    if out is None:
        print(text, end="")
        return 0
    try:
        with open(out, "w", encoding="utf-8") as fh:
            fh.write(text)
    except OSError as exc:
        raise CliError(f"-o {out}: cannot write: {exc.strerror or exc}") from None
    print(f"{out}: {scenario.summary()}", file=sys.stderr)
    return 0


def run(args: argparse.Namespace) -> int:
    """Validate ``args.files`` in order and print one report per file."""
    from fcplan.scenario import load_scenario

    for f in args.files:
        s = load_scenario(f)
        over = s.manual_limit_violations()
        if over:
            print(f"{f}: valid; exceeds {len(over)} manual limit(s):")
            for line in over:
                print(f"  - {line}")
        else:
            print(f"{f}: valid, within the manual's limits")
    return 0
