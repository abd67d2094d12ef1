"""The documentation site builds, strictly and offline, and its pages agree with the code."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def _missing_docs_tools() -> str | None:
    for mod in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python", "yaml"):
        try:
            __import__(mod)
        except ImportError:
            return f"{mod} is not installed (pip install -e '.[docs]')"
    return None


needs_mkdocs = pytest.mark.skipif(
    _missing_docs_tools() is not None, reason=str(_missing_docs_tools())
)


@needs_mkdocs
def test_site_builds_strictly(tmp_path):
    """`mkdocs build --strict` succeeds: every link, nav entry, included file (bench/README.md)
    and API object (mkdocstrings) resolves, with no warning and no network."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NO_MKDOCS_2_WARNING": "1"}
    site = tmp_path / "site"
    proc = subprocess.run(
        # not -q: it hides the warnings from --strict, which then passes with a broken link
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(site)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "WARNING" not in proc.stdout + proc.stderr, proc.stdout + proc.stderr
    assert (site / "index.html").is_file()
    assert "DejaVu" in (site / "reference" / "render" / "index.html").read_text(encoding="utf-8")
    bench = (site / "benchmarks" / "index.html").read_text(encoding="utf-8")
    assert "<table" in bench  # bench/README.md's tables are included
    # and its plots, linked from bench/ as ../docs/<file>, resolve on the page
    assert 'src="../vector_throughput.png"' in bench and "../docs/" not in bench
    assert (site / "vector_throughput.png").is_file()


@needs_mkdocs
def test_every_page_is_in_the_nav():
    """Every Markdown page under docs/ is reachable from the site's navigation."""
    import yaml

    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))

    def pages(node):
        if isinstance(node, str):
            yield node
        elif isinstance(node, list):
            for item in node:
                yield from pages(item)
        elif isinstance(node, dict):
            for value in node.values():
                yield from pages(value)

    listed = set(pages(config["nav"]))
    on_disk = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.md")}
    assert on_disk - listed == set()
    assert listed - on_disk == set()


def test_metric_equations_are_quoted_from_the_docstrings():
    """Each equation of docs/concepts/metrics.md (code spans with `=`) occurs word for word in
    fcplan.metrics' docstring, so the page cannot drift from the code."""
    import fcplan.metrics

    doc = fcplan.metrics.__doc__ or ""
    page = (DOCS / "concepts" / "metrics.md").read_text(encoding="utf-8")
    body = page.split("## In code")[0]
    equations = [e for e in re.findall(r"`([^`]+)`", body) if " = " in e]
    assert len(equations) >= 10
    for eq in equations:
        assert eq in doc, eq


def test_scheduler_howto_runs(monkeypatch, capsys):
    """The Python blocks of docs/howto/scheduler.md run as written (the example scheduler plays
    an episode without fallbacks and passes the conformance kit; its settings are checked by
    fcplan.settings, the error printed as the page says)."""
    from fcplan import scheduling

    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))  # registers "nearest"
    page = (DOCS / "howto" / "scheduler.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", page, flags=re.S)
    assert len(blocks) == 3
    namespace: dict = {"__name__": "docs_howto"}
    for block in blocks:
        exec(compile(block, "docs/howto/scheduler.md", "exec"), namespace)  # noqa: S102
    assert namespace["report"].failures == []
    said = re.search(r"print\(err\)  # (.*)\n", blocks[1]).group(1)
    assert capsys.readouterr().out.splitlines()[-1] == said
    assert namespace["NearestAt"]().horizon == 1


def test_benchmark_howto_runs(monkeypatch):
    """The runnable block of docs/howto/benchmark.md (```python; the hours-long study is a ```py
    block, shown and not run) plays its short comparison: the stand-in scheduler is compared in
    deterministic mode and gets a fraction of the oracle normalised by the idle team."""
    from fcplan import scheduling

    monkeypatch.setattr(scheduling, "_RUNTIME", dict(scheduling._RUNTIME))  # registers "mine"
    page = (DOCS / "howto" / "benchmark.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", page, flags=re.S)
    assert len(blocks) == 1 and "```py\n" in page
    namespace: dict = {"__name__": "docs_howto"}
    exec(compile(blocks[0], "docs/howto/benchmark.md", "exec"), namespace)  # noqa: S102
    result, stats = namespace["result"], namespace["stats"]
    assert {e["deterministic"] for e in result.episodes if e["scheduler"] == "mine"} == {True}
    (mine,) = [f for f in stats.fractions if f.scheduler == "mine"]
    assert mine.baseline == "idle" and mine.n == 4 and 0.0 < mine.fraction < 1.5
