"""mkdocs hook: the Benchmarks page includes ``bench/README.md`` with its links into ``docs/``
rewritten for the page's place in the site.

``bench/README.md`` links its plots as ``../docs/<file>``, the path from the ``bench/`` folder
(what GitHub shows). Included verbatim into ``docs/benchmarks.md`` (``pymdownx.snippets``), the
same link points above the site and the image is missing there; ``mkdocs build --strict``
reports it. The snippet extension cannot rewrite what it includes, and mkdocs checks links while
it converts the Markdown, so the rewrite happens before: this hook expands the page's one
``--8<-- "bench/README.md"`` line itself, with ``](../docs/`` made ``](``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

INCLUDE = '--8<-- "bench/README.md"'


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """The page's Markdown, with the bench README expanded on the Benchmarks page."""
    if page.file.src_uri != "benchmarks.md" or INCLUDE not in markdown:
        return markdown
    root = Path(config["config_file_path"]).parent
    text = (root / "bench" / "README.md").read_text(encoding="utf-8")
    return markdown.replace(INCLUDE, text.replace("](../docs/", "]("))
