"""The README's integration examples (Gymnasium ids, SuperSuit recipe) run as printed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[2] / "README.md"
SECTION = "### Standard integrations: Gymnasium ids, PettingZoo modules, SuperSuit"


def _blocks() -> list[str]:
    text = README.read_text()
    start = text.index(SECTION)
    section = text[start : text.index("\n## ", start)]
    return re.findall(r"```python\n(.*?)```", section, flags=re.DOTALL)


def test_gymnasium_example_runs():
    """The Gymnasium block makes fcplan/Task-v1 on scenario 24 and resets it."""
    ns: dict = {}
    exec(compile(_blocks()[0], str(README), "exec"), ns)
    assert ns["env"].spec.id == "fcplan/Task-v1"


def test_supersuit_recipe_runs_and_prints_what_it_says(capsys):
    """The SuperSuit block vectorises the motion level and prints the shapes its comment
    shows."""
    pytest.importorskip("supersuit")
    code = _blocks()[1]
    exec(compile(code, str(README), "exec"), {})
    shown = re.search(r"# (\(\d+, \d+\) \(\d+,\))", code).group(1)
    assert capsys.readouterr().out.strip() == shown
