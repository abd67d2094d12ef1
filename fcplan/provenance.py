"""Where a stored result came from: the libraries it ran on and the code that produced it.

Every result fcplan stores (a sweep's episode row, a recording's header, a demonstration
dataset's metadata) names the versions of Python and of the libraries that can change a number
(:func:`library_versions`), and sweep rows also name the code (:func:`code_identity`):

* ``source``: a digest (SHA-256, 16 hex digits) of the Python files of the ``fcplan`` and
  ``solvers`` packages as imported, paths and bytes, in a fixed order. It identifies the exact
  code whether it runs from a checkout or an installed wheel; any edit changes it, a comment
  included, so two digests that differ say the code differed, not that behaviour did;
* ``commit``: the git commit the packages were imported from when they live in a git work tree
  and ``git`` can be run (else ``None``), and ``dirty``: whether their files differ from it
  (modified or new files under ``fcplan/`` and ``solvers/``; ``None`` without a commit).

Neither proves that stored numbers still hold for today's code: a study that spans commits may
mix episodes of a scheduler played before and after a change of its behaviour. That is what
:func:`fcplan.experiments.verify.verify_results` checks, by playing stored episodes again.

Both are computed once per process (the work tree does not change under a running study; a
test that needs a fresh value calls ``code_identity.cache_clear()``).

Examples
--------
>>> sorted(code_identity())
['commit', 'dirty', 'source']
>>> len(code_identity()["source"])
16
>>> sorted(library_versions(("numpy", "no-such-library")))
['numpy', 'python']
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import json
import platform
import subprocess
from collections.abc import Iterable
from importlib import metadata
from pathlib import Path

__all__ = ["PACKAGES", "code_identity", "count_code_versions", "library_versions", "source_files"]

#: The packages whose code decides a result (the simulator, metrics and the built-in schedulers).
PACKAGES = ("fcplan", "solvers")

#: Seconds a ``git`` call may take before the commit is reported as unknown.
_GIT_TIMEOUT_S = 10.0


def library_versions(libraries: Iterable[str]) -> dict[str, str]:
    """The Python version and the installed versions of ``libraries`` (missing ones left out).

    Parameters
    ----------
    libraries : iterable of str
        Distribution names, e.g. ``("fcplan", "numpy")``.

    Returns
    -------
    dict
        ``{"python": "3.11.7", "numpy": "2.4.6", ...}``.
    """
    out = {"python": platform.python_version()}
    for lib in libraries:
        try:
            out[lib] = metadata.version(lib)
        except metadata.PackageNotFoundError:
            continue
    return out


def _package_dirs() -> list[Path]:
    """The folders of :data:`PACKAGES`, found without importing them."""
    out: list[Path] = []
    for name in PACKAGES:
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.submodule_search_locations:
            out.extend(Path(p).resolve() for p in spec.submodule_search_locations)
    return out


def source_files() -> list[Path]:
    """The Python files of :data:`PACKAGES` as imported, in the digest's order."""
    files: list[Path] = []
    for d in _package_dirs():
        files.extend(sorted(p for p in d.rglob("*.py") if "__pycache__" not in p.parts))
    return files


def _digest(files: list[Path]) -> str:
    h = hashlib.sha256()
    for d in _package_dirs():
        for p in files:
            if d in p.parents:
                h.update(f"{d.name}/{p.relative_to(d).as_posix()}\0".encode())
                h.update(p.read_bytes())
                h.update(b"\0")
    return h.hexdigest()[:16]


def _git(root: Path, *args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "-C", str(root), *args],
            capture_output=True,
            text=True,
            timeout=_GIT_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


@functools.cache
def code_identity() -> dict[str, str | bool | None]:
    """The code behind this process's results: ``{"source", "commit", "dirty"}`` (see above).

    Returns
    -------
    dict
        ``source`` (16 hex digits), ``commit`` (40 hex digits or ``None``), ``dirty`` (bool or
        ``None``).
    """
    dirs = _package_dirs()
    source = _digest(source_files())
    root = dirs[0].parent
    top = _git(root, "rev-parse", "--show-toplevel")
    commit = dirty = None
    # only the work tree that holds the packages themselves (not one that merely contains an
    # installed copy, e.g. a virtualenv inside a checkout)
    if top is not None and all(_git(d, "ls-files", "--error-unmatch", "__init__.py") for d in dirs):
        commit = _git(root, "rev-parse", "HEAD")
        if commit is not None:
            try:
                rel = [d.relative_to(Path(top).resolve()).as_posix() for d in dirs]
            except ValueError:  # the packages in different work trees: no single commit
                return {"source": source, "commit": None, "dirty": None}
            status = _git(Path(top), "status", "--porcelain", "--", *rel)
            dirty = None if status is None else bool(status)
    return {"source": source, "commit": commit, "dirty": dirty}


def count_code_versions(codes: Iterable[object]) -> dict[str, int]:
    """How many results came from each code version, most first.

    Parameters
    ----------
    codes : iterable
        The results' ``code`` values (JSON text of :func:`code_identity`; anything else, e.g.
        a missing value of a row written before the column existed, counts as not recorded).

    Returns
    -------
    dict
        ``{name: count}``: the commit's first 10 digits (``+dirty`` when its files differed),
        else ``source <digest>``, else ``not recorded``.

    Examples
    --------
    >>> count_code_versions(['{"commit": "0123456789abcdef", "dirty": true}', None, None])
    {'not recorded': 2, '0123456789+dirty': 1}
    """
    out: dict[str, int] = {}
    for code in codes:
        name = "not recorded"
        if isinstance(code, str):
            doc = json.loads(code)
            if doc.get("commit"):
                name = str(doc["commit"])[:10] + ("+dirty" if doc.get("dirty") else "")
            elif doc.get("source"):
                name = f"source {doc['source']}"
        out[name] = out.get(name, 0) + 1
    return dict(sorted(out.items(), key=lambda kv: (-kv[1], kv[0])))
