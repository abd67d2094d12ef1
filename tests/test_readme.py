"""The README's "Writing a scheduler" example runs as printed and says what it does."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from fcplan import scheduling

README = Path(__file__).resolve().parents[1] / "README.md"


def python_block_after(marker: str) -> str:
    """The first fenced ``python`` code block of the README after ``marker``."""
    text = README.read_text()
    found = re.search(r"```python\n(.*?)```", text[text.index(marker) :], flags=re.DOTALL)
    assert found, f"no python block after {marker!r}"
    return found.group(1)


def test_writing_a_scheduler_example_never_falls_back(monkeypatch):
    """The example scheduler, which only picks tasks from ``graph.reachable``, makes no plan
    that validation rejects on scenario #12 (0 fallbacks), the number the README shows."""
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))  # registers "nearest"
    code = python_block_after("**Writing a scheduler.**")
    assert "result.fallbacks  # 0" in code
    namespace: dict[str, Any] = {}
    exec(compile(code, str(README), "exec"), namespace)
    result = namespace["result"]
    assert result.fallbacks == 0
    assert all(s.status != "fallback" for s in result.solves)
