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


def python_blocks_after(marker: str, count: int) -> list[str]:
    """The first ``count`` fenced ``python`` code blocks of the README after ``marker``."""
    text = README.read_text()
    found = re.findall(r"```python\n(.*?)```", text[text.index(marker) :], flags=re.DOTALL)
    assert len(found) >= count, f"fewer than {count} python blocks after {marker!r}"
    return found[:count]


def test_python_block_runs_a_mission_like_run_episode():
    """The README's Python block runs; its hand-written Mission loop scores exactly what
    ``run_episode`` scores for the same scenario, scheduler and seed."""
    namespace: dict[str, Any] = {}
    exec(compile(python_block_after("### Python"), str(README), "exec"), namespace)
    mission, result = namespace["mission"], namespace["result"]
    from fcplan import compute_all

    assert mission.done and mission.world.tick == result.ticks
    manual = compute_all(mission.world.trace())["manual"]
    assert manual.final_score == result.metrics["manual"].final_score


def test_conformance_block_reports_what_the_readme_says(monkeypatch):
    """The README's check_scheduler block passes the example scheduler and prints the graph
    count and the empty failure list it shows."""
    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))
    nearest, check = python_blocks_after("**Writing a scheduler.**", 2)
    assert "# (54, [])" in check
    namespace: dict[str, Any] = {}
    exec(compile(nearest.split("result = run_episode")[0], str(README), "exec"), namespace)
    exec(compile(check, str(README), "exec"), namespace)
    assert (namespace["report"].graphs, namespace["report"].failures) == (54, [])
