"""`fcplan scenario generate`: one option per generator knob, the preset's values by default,
the TOML of exactly the scenario the Python call draws, one-line errors for bad values."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fcplan.cli import main
from fcplan.cli.parser import build_parser
from fcplan.scenario import GeneratorConfig, dump_scenario, load_scenario, recipe_of
from fcplan.scenario.generate import PRESETS, generate
from fcplan.scenario.knobs import knobs_of
from tests.cli.helpers import one_line_error

ROOT = Path(__file__).resolve().parents[2]
KNOBS = knobs_of(GeneratorConfig)


def _generate_parser():
    p = build_parser()
    p.parse_args(["scenario", "generate", "--seed", "0"])  # adds the knob options
    sub = next(a for a in p._actions if a.dest == "command").choices["scenario"]
    return next(a for a in sub._actions if a.dest == "scenario_command").choices["generate"]


def test_every_knob_has_an_option_with_its_range_and_meaning():
    """Each GeneratorConfig knob is an option --<knob-with-dashes> whose help gives its meaning,
    its allowed values and its default."""
    options = {a.dest: a for a in _generate_parser()._actions}
    for name, (spec, _default) in KNOBS.items():
        action = options[f"knob_{name}"]
        assert action.option_strings == ["--" + name.replace("_", "-")]
        assert spec.doc and spec.doc in action.help and spec.short() in action.help


@pytest.mark.parametrize("preset", list(PRESETS))
def test_prints_the_toml_of_the_python_call(preset, capsys):
    """Without -o (and with -o -) the TOML printed is dump_scenario of the preset's scenario."""
    expected = dump_scenario(GeneratorConfig.preset(preset)(4))
    assert main(["scenario", "generate", "--seed", "4", "--preset", preset]) == 0
    assert capsys.readouterr().out == expected
    assert main(["scenario", "generate", "--seed", "4", "--preset", preset, "-o", "-"]) == 0
    assert capsys.readouterr().out == expected


def test_writes_a_file_that_regenerates(tmp_path, capsys):
    """-o FILE writes a valid scenario whose recorded recipe draws it again, knobs included."""
    out = tmp_path / "s.toml"
    argv = ["scenario", "generate", "--seed", "9", "--preset", "hard", "--n-regions", "2", "3",
            "--tank", "1", "--comm-range", "400", "--perception-altitude", "15", "60", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert str(out) in capsys.readouterr().err
    s = load_scenario(out)
    recipe = recipe_of(s)
    assert recipe["n_regions"] == (2, 3) and recipe["tank"] == (1, 1)
    assert recipe["comm_range"] == 400.0 and recipe["perception_altitude"] == (15.0, 60.0)
    assert recipe["battery"] == GeneratorConfig.hard().battery  # the preset's value is kept
    assert generate(**recipe) == s


def test_comm_range_none_turns_the_limit_off(capsys):
    """--comm-range none gives a team without a communication limit."""
    assert main(["scenario", "generate", "--seed", "1", "--comm-range", "none"]) == 0
    text = capsys.readouterr().out
    assert "\ncomm_range = " not in text and "comm_range=None" in text


def _bad_value(name: str) -> str:
    spec, _ = KNOBS[name]
    if spec.kind == "choice":
        return "nowhere"
    return str(int(spec.hi) + 1) if spec.kind in ("int", "irange") else str(spec.hi * 2 + 1)


@pytest.mark.parametrize("name", list(KNOBS))
def test_out_of_range_values_name_the_knob_and_its_range(name, capsys):
    """A value outside a knob's range stops the command with one line naming the option, the
    knob and its allowed values (exit 2)."""
    spec, _ = KNOBS[name]
    option = "--" + name.replace("_", "-")
    words = [_bad_value(name)] * (2 if spec.kind == "pair" else 1)
    one_line_error(
        ["scenario", "generate", "--seed", "0", option, *words],
        capsys,
        option,
        name,
        spec.allowed(),
    )


@pytest.mark.parametrize("name", [n for n, (k, _) in KNOBS.items() if k.kind != "choice"])
def test_words_that_are_not_numbers_name_the_knob(name, capsys):
    """A word that is not a number fails at parsing with the knob's allowed values."""
    spec, _ = KNOBS[name]
    words = ["many"] * (2 if spec.kind == "pair" else 1)
    option = "--" + name.replace("_", "-")
    one_line_error(
        ["scenario", "generate", "--seed", "0", option, *words], capsys, option, spec.allowed()
    )


def test_range_options_take_at_most_two_values(capsys):
    """Three values for a range knob are refused in one line."""
    one_line_error(
        ["scenario", "generate", "--seed", "0", "--fronts", "1", "2", "3"],
        capsys,
        "--fronts",
        "one value or two",
    )


def test_knobs_checked_together_and_unplaceable_layouts_fail_in_one_line(capsys):
    """Knob combinations the generator refuses (late regions after the end; more facilities than
    fit) are one-line errors naming the option to change."""
    one_line_error(
        ["scenario", "generate", "--seed", "0", "--duration-s", "50", "--late-share", "0.5"],
        capsys,
        "--late-delay-s",
        "must end before duration_s",
    )
    one_line_error(
        ["scenario", "generate", "--seed", "0", "--world-size", "800", "--n-houses", "300"],
        capsys,
        "--n-houses",
    )


def test_bad_seed_preset_and_output_fail_in_one_line(tmp_path, capsys):
    """A negative seed, an unknown preset and an output in a missing folder are one-line errors."""
    one_line_error(["scenario", "generate", "--seed", "-1"], capsys, "--seed")
    one_line_error(["scenario", "generate", "--seed", "1", "--preset", "easy"], capsys, "hard")
    missing = str(tmp_path / "no" / "s.toml")
    one_line_error(["scenario", "generate", "--seed", "1", "-o", missing], capsys, "no such")


def test_building_the_parser_does_not_import_the_generator():
    """The knob options are added only when `scenario generate` is parsed, so `fcplan --help`
    and every other command start without importing the generator (and numpy)."""
    code = (
        "import sys; from fcplan.cli.parser import build_parser; p = build_parser(); "
        "p.parse_args(['scenarios']); print('fcplan.scenario.generate' in sys.modules, "
        "'numpy' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    )
    assert out.stdout.split() == ["False", "False"]


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 2**32), regions=st.integers(1, 4))
def test_cli_and_python_draw_the_same_scenario(seed, regions):
    """For any seed and region count, the CLI's TOML is the Python call's."""
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        argv = ["scenario", "generate", "--seed", str(seed), "--n-regions", str(regions)]
        assert main(argv) == 0
    assert buf.getvalue() == dump_scenario(generate(seed, n_regions=regions))
