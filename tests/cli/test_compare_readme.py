"""The README's compare examples print what the README shows (every deterministic number)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from fcplan.cli import main

README = Path(__file__).resolve().parents[2] / "README.md"
SCORE_FIELDS = 11  # scheduler, n, err and the eight score columns before the timing columns


def _examples() -> list[tuple[str, list[str]]]:
    """(command, output lines) of each ``fcplan compare`` block of the compare section followed
    by an output block."""
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Compare schedulers") : text.index("## Sweeps, results")]
    blocks = re.findall(r"```\n(.*?)```", section, flags=re.DOTALL)
    out = []
    for cmd, output in zip(blocks, blocks[1:], strict=False):
        if cmd.startswith("fcplan compare") and not output.startswith("fcplan "):
            out.append((cmd.strip(), output.rstrip("\n").splitlines()))
    return out


def _fields(line: str) -> list[str]:
    return re.split(r"\s{2,}", line.strip())


def _same(shown: str, printed: list[str]) -> bool:
    """A shown line is printed as is; a table row (``±`` cells) up to its timing columns; the
    header up to its wall time; ``...`` stands for lines left out."""
    if shown == "...":
        return True
    if "episodes:" in shown and "wall time" in shown:
        return any(p.split("wall time")[0] == shown.split("wall time")[0] for p in printed)
    if "±" in shown:
        want = _fields(shown)[:SCORE_FIELDS]
        return any(_fields(p)[:SCORE_FIELDS] == want for p in printed if "±" in p)
    return shown in printed


@pytest.mark.slow  # 48 full episodes (about 1 min on a loaded 2-core machine)
@pytest.mark.parametrize("index", [0, 1])
def test_readme_compare_examples_print_what_the_readme_shows(index, capsys):
    """Each README compare command, run as printed (progress off), prints every line its output
    block shows: the score columns and every statistic (timing columns excepted)."""
    cmd, shown = _examples()[index]
    assert main([*shlex.split(cmd)[1:], "--quiet"]) == 0
    printed = capsys.readouterr().out.splitlines()
    missing = [line for line in shown if not _same(line, printed)]
    assert missing == [], "\n".join(missing)


def test_readme_has_both_compare_examples():
    """The section shows a fixed-seed and a --seeds auto example with their outputs."""
    cmds = [c for c, _ in _examples()]
    assert len(cmds) == 2 and "--seeds 0-1" in cmds[0] and "--seeds auto" in cmds[1]
