"""The generator's knob table is written once: the GeneratorConfig docstring holds exactly the
table generated from the knobs' metadata (default, allowed values, meaning)."""

from __future__ import annotations

import inspect

from fcplan.scenario.generate import GeneratorConfig
from fcplan.scenario.knobs import knob_table, knobs_of


def test_docstring_table_is_the_generated_one():
    """The knob table in GeneratorConfig's docstring equals knob_table(GeneratorConfig), so a
    knob's range, default or meaning cannot change without its documentation (and the CLI help,
    built from the same metadata) changing too."""
    doc = inspect.cleandoc(GeneratorConfig.__doc__ or "")
    assert knob_table(GeneratorConfig) in doc


def test_every_knob_says_what_it_means():
    """Every knob has a short meaning (with its unit where it has one): the CLI help shows it."""
    docs = {name: spec.doc for name, (spec, _) in knobs_of(GeneratorConfig).items()}
    assert docs and all(docs.values())
    assert list(docs) == list(GeneratorConfig.KNOB_NAMES)
