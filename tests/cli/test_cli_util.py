"""Tests of fcplan.cli.util: argument types, the raising parser and the output check."""

from __future__ import annotations

import argparse

import pytest

from fcplan.cli.util import (
    CliError,
    Parser,
    check_output,
    name_list,
    positive_float,
    positive_int,
    scenario_list,
    seed,
    seed_list,
)
from fcplan.errors import FcplanError


@pytest.mark.parametrize(
    "convert, good, bad",
    [
        (positive_float, {"0.5": 0.5, "3": 3.0}, ["0", "-1", "nan", "inf", "x"]),
        (positive_int, {"1": 1, "12": 12}, ["0", "-2", "1.5", "x"]),
        (seed, {"0": 0, "7": 7}, ["-1", "0.5", "x"]),
    ],
)
def test_numbers_outside_their_range_are_argument_errors(convert, good, bad):
    """Each number type accepts its range and names the range and the text otherwise."""
    for text, value in good.items():
        assert convert(text) == value
    for text in bad:
        with pytest.raises(argparse.ArgumentTypeError, match=repr(text)):
            convert(text)


def test_lists_of_names_scenarios_and_seeds():
    """Names drop duplicates and empty items are errors; scenarios take names and ranges; seeds
    only numbers."""
    assert name_list("greedy, idle,greedy") == ["greedy", "idle"]
    for text in ("", "a,,b", " "):
        with pytest.raises(argparse.ArgumentTypeError, match="comma-separated"):
            name_list(text)
    assert scenario_list("practice,1,3-4") == ["practice", 1, 3, 4]
    assert seed_list("0-2,7") == [0, 1, 2, 7]
    with pytest.raises(argparse.ArgumentTypeError):
        seed_list("practice")


def test_parser_errors_raise_one_line_cli_errors():
    """Parser.error raises a CliError (an FcplanError) prefixed with the program name."""
    p = Parser(prog="fcplan x")
    p.add_argument("--n", type=positive_int)
    with pytest.raises(CliError, match=r"^fcplan x: argument --n: expected an integer >= 1"):
        p.parse_args(["--n", "0"])
    assert issubclass(CliError, FcplanError)


def test_check_output_fails_before_a_run(tmp_path):
    """An output path that is a folder or lies in a missing folder is refused; None and a
    writable path pass."""
    check_output(None, "--out")
    check_output(str(tmp_path / "a.json"), "--out")
    with pytest.raises(CliError, match="is a directory"):
        check_output(str(tmp_path), "--out")
    with pytest.raises(CliError, match="no such directory"):
        check_output(str(tmp_path / "no" / "a.json"), "--json")
