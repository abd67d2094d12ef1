"""Tests of the scenario's fire wind model (``[fire] wind_model``): read, default, round trip
through the TOML writer, and the one-line error for an unknown value."""

from __future__ import annotations

import pytest

from fcplan.scenario import ScenarioError, dump_scenario, load_scenario
from fcplan.scenario.parts import DEFAULT_WIND_MODEL, WIND_MODELS
from tests.scenario.designs import edit, load_error, write


def test_wind_model_defaults_to_the_default_and_is_read_from_the_fire_table(tmp_path):
    """Without ``wind_model`` a scenario has DEFAULT_WIND_MODEL, the original's "tables" model
    (issue 15: statistically the original's fire); ``[fire] wind_model`` sets it."""
    assert load_scenario(write(tmp_path, edit("[fire]", "[fire]"))).wind_model == DEFAULT_WIND_MODEL
    assert load_scenario(12).wind_model == DEFAULT_WIND_MODEL == "tables"
    for model in WIND_MODELS:
        s = load_scenario(write(tmp_path, edit("[fire]", f'[fire]\nwind_model = "{model}"')))
        assert s.wind_model == model


@pytest.mark.parametrize("model", WIND_MODELS)
def test_wind_model_survives_a_write_and_read(tmp_path, model):
    """dump_scenario always writes the wind model, the default too (the default changed once,
    from "fresh" to "tables": a file must not depend on it); loading the text gives an equal
    scenario."""
    s = load_scenario(1).replace(wind_model=model)
    text = dump_scenario(s)
    assert f'wind_model = "{model}"' in text
    path = tmp_path / "copy.toml"
    path.write_text(text, encoding="utf-8")
    assert load_scenario(path) == s


def test_unknown_wind_model_is_a_one_line_error_naming_field_and_values(tmp_path):
    """An unknown wind model is one line: the file, ``fire.wind_model``, the allowed values and
    the value given; so is a wrong type."""
    msg = load_error(tmp_path, edit("[fire]", '[fire]\nwind_model = "gusty"'))
    assert "\n" not in msg
    assert ": fire.wind_model: must be one of 'tables', 'fresh'" in msg and "gusty" in msg
    msg = load_error(tmp_path, edit("[fire]", "[fire]\nwind_model = 3"))
    assert ": fire.wind_model: must be a string" in msg
    with pytest.raises(ScenarioError, match="fire.wind_model"):
        load_scenario(1).replace(wind_model="Tables")
