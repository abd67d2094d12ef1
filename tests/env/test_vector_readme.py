"""The README's batched-environment examples run as printed and print what their comments say."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"
SECTION = "### Batched environments: many worlds per step"


def _blocks() -> list[str]:
    text = README.read_text()
    start = text.index(SECTION)
    section = text[start : text.index("\n### ", start + 1)]
    return re.findall(r"```python\n(.*?)```", section, flags=re.DOTALL)


def test_the_batched_section_comes_first():
    """The learning section opens with the batched API."""
    text = README.read_text()
    learning = text.index("## Learning:")
    assert text.index("\n### ", learning) == text.index(SECTION) - 1


def test_examples_print_what_they_say(capsys):
    """Both blocks run; each prints the shapes (or values) its last comment shows."""
    for code in _blocks():
        exec(compile(code, str(README), "exec"), {})
        shown = code.rstrip().rsplit("# ", 1)[1]
        assert capsys.readouterr().out.strip() == shown
