"""Tests of fcplan.cli.schedulers: `fcplan schedulers` describes every registered scheduler from
the registry (descriptions, settings, defaults, documentation)."""

from __future__ import annotations

import inspect
import json

import pytest

from fcplan import scheduling
from fcplan.cli import main
from fcplan.cli.schedulers import describe
from fcplan.errors import FcplanError
from fcplan.scheduling import available_schedulers, register_scheduler, scheduler_factory
from tests.cli.helpers import one_line_error


def test_every_registered_scheduler_is_listed_with_its_settings(capsys):
    """The listing has one block per registered scheduler, its description, and every keyword
    setting of its factory with the factory's default."""
    assert main(["schedulers"]) == 0
    out = capsys.readouterr().out
    for name in available_schedulers():
        factory = scheduler_factory(name)
        assert f"\n{name} " in f"\n{out}", name
        for p in inspect.signature(factory).parameters.values():
            if p.kind is p.VAR_KEYWORD:
                assert f"**{p.name}" in out, (name, p.name)
            elif p.default is not p.empty:
                assert f"{p.name}={p.default!r}" in out, (name, p.name)


def test_descriptions_are_one_plain_sentence():
    """Each description is non-empty plain text: no reST roles or literals, no pointer to a
    module docstring the command line cannot show."""
    for name in available_schedulers():
        text = describe(name)["description"]
        assert text and text.endswith(".") and "\n" not in text, name
        assert "``" not in text and ":class:" not in text and "docstring" not in text, name


def test_named_schedulers_show_each_setting_documented(capsys):
    """`fcplan schedulers greedy` documents every setting greedy's docstring documents."""
    assert main(["schedulers", "greedy"]) == 0
    out = capsys.readouterr().out
    assert "route_length=3" in out
    lines = out.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.strip() == "route_length=3")
    assert lines[k + 1].startswith("      ") and lines[k + 1].strip()


def test_json_and_runtime_registrations(capsys, monkeypatch):
    """A scheduler registered at run time appears with its settings; --json is one document
    with the same content as :func:`describe`."""
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))

    class Mine:
        """Plans nothing at all."""

        name = "mine"

        def __init__(self, depth: int = 2) -> None:
            self.depth = depth

    register_scheduler("mine", Mine)
    assert main(["schedulers", "mine", "--json"]) == 0
    (doc,) = json.loads(capsys.readouterr().out)
    assert doc == describe("mine")
    assert doc["description"] == "Plans nothing at all."
    assert doc["settings"] == {"depth": {"default": 2, "doc": ""}}
    assert doc["deterministic"] is False


def test_unknown_names_and_broken_plugins(capsys, monkeypatch):
    """An unknown name is a one-line error listing the known ones; a plug-in that fails to load
    is listed with the reason instead of failing the listing."""
    one_line_error(["schedulers", "nope"], capsys, "nope", "greedy")
    real = scheduler_factory

    def factory(name: str):
        if name == "idle":
            raise FcplanError("scheduler 'idle' cannot be loaded: ImportError: gone")
        return real(name)

    monkeypatch.setattr(scheduling, "scheduler_factory", factory)
    assert main(["schedulers"]) == 0
    out = capsys.readouterr().out
    assert "cannot be loaded" in out and "ImportError: gone" in out and "greedy" in out


#: Phrases of Python's own errors that a user should never read instead of "must be ...".
LEAKS = ("not supported between", "invalid literal", "could not convert", "unexpected keyword")


@pytest.mark.parametrize("name", available_schedulers())
def test_a_mistyped_setting_is_named_with_what_is_allowed(name, capsys):
    """``fcplan run 1 -s NAME:KEY=x`` for every numeric setting of every scheduler is one line
    naming the setting and its value, never a Python error's text (``-s milp:slots=x`` used to
    print "'<' not supported between instances of 'str' and 'int'")."""
    numeric = [
        key
        for key, info in describe(name)["settings"].items()
        if isinstance(info["default"], (int, float)) and not isinstance(info["default"], bool)
    ]
    for key in numeric:
        assert main(["run", "1", "-s", f"{name}:{key}=x"]) == 2
        err = capsys.readouterr().err
        assert f"{key}=x" in err and not any(leak in err for leak in LEAKS), err
