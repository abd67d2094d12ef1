"""Studies in a results folder: which episodes may be pooled in one report.

A *study* is a sweep grid without its seeds (scenario documents after overrides, scheduler
variants and settings, replan periods, time limits, mode): its episodes are comparable, and
running more seeds into the folder extends it. Every row a sweep writes carries its
``study_hash`` (:attr:`fcplan.experiments.config.SweepConfig.study_hash`). Two studies written
into one folder (a small notebook run next to the full study, a changed override) must not be
pooled silently: per-scheduler means would mix different episode sets. :func:`select_study`
returns the episodes of the one study in a folder, or of the study asked for, and refuses a mix
with a one-line error naming the studies, unless ``allow_mixed`` (then the report says so).

Rows written before study hashes existed have none: they are read as one study of their own,
and the report says so once (it cannot check them for mixing).

Examples
--------
>>> import pandas as pd
>>> df = pd.DataFrame({"study_hash": ["aa", "aa", "bb"], "sweep": ["x", "x", "y"]})
>>> select_study(df, "results")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.FcplanError: results: episodes of 2 studies in one folder: aa 'x' (2 episodes), bb 'y' (1 episode); ...
>>> sel = select_study(df, "results", study="bb")
>>> len(sel.rows), sel.note
(1, '')
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fcplan.errors import FcplanError

__all__ = ["Selection", "Study", "select_study", "studies"]

LEGACY = "(no study hash)"
"""How rows written before study hashes are named."""


@dataclass(frozen=True)
class Study:
    """One study of a results folder: its hash (:data:`LEGACY` for old rows), name, episodes."""

    hash: str
    name: str
    episodes: int

    def describe(self) -> str:
        """``"<hash> '<name>' (<n> episodes)"``."""
        name = f" '{self.name}'" if self.name else ""
        return f"{self.hash}{name} ({self.episodes} episode{'s' if self.episodes != 1 else ''})"


@dataclass(frozen=True)
class Selection:
    """The episodes a report may pool.

    Attributes
    ----------
    rows : DataFrame
        The selected episodes.
    studies : list of Study
        The studies they come from.
    note : str
        What the report must say about them (``""`` for one hashed study).
    """

    rows: Any
    studies: list[Study]
    note: str


def _hashes(df: Any) -> Any:
    """The study hash of every row (:data:`LEGACY` where there is none)."""
    if "study_hash" not in df:
        return df.index.to_series().map(lambda _: LEGACY)
    return df["study_hash"].map(lambda h: h if isinstance(h, str) and h else LEGACY)


def _names(results: str | os.PathLike[str] | None) -> dict[str, str]:
    """Study hash -> name or source file, from the folder's manifests."""
    out: dict[str, str] = {}
    if results is None or not Path(results).is_dir():
        return out
    for p in sorted(Path(results).glob("manifest-*.json")):
        try:
            doc = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(doc, dict) and isinstance(doc.get("study_hash"), str):
            out[doc["study_hash"]] = str(doc.get("name") or doc.get("source") or "")
    return out


def studies(df: Any, results: str | os.PathLike[str] | None = None) -> list[Study]:
    """The studies of the rows ``df`` (in order of first appearance)."""
    hashes = _hashes(df)
    names = _names(results)
    sweep = df.get("sweep")
    out = []
    for h in dict.fromkeys(hashes):
        mask = hashes == h
        name = names.get(h, "")
        if not name and sweep is not None and h != LEGACY:
            name = next((str(s) for s in sweep[mask] if isinstance(s, str) and s), "")
        out.append(Study(h, name, int(mask.sum())))
    return out


def select_study(
    df: Any,
    results: str | os.PathLike[str] | None,
    *,
    study: str | None = None,
    allow_mixed: bool = False,
) -> Selection:
    """The episodes of ``df`` a report may pool (module docstring).

    Parameters
    ----------
    df : DataFrame
        Every episode of a results folder (:func:`~fcplan.experiments.load_results`).
    results : path, optional
        The folder (for the studies' names in its manifests, and the messages).
    study : str, optional
        Keep only this study (its hash, or a unique prefix of it).
    allow_mixed : bool
        Pool several studies anyway (the note says so).

    Raises
    ------
    fcplan.FcplanError
        Several studies without ``study`` or ``allow_mixed``; an unknown or ambiguous
        ``study`` (one line naming the studies).
    """
    found = studies(df, results)
    where = str(results) if results is not None else "results"
    listing = ", ".join(s.describe() for s in found)
    if study is not None:
        match = [s for s in found if s.hash.startswith(study)]
        if len(match) != 1:
            why = "matches no study" if not match else "is ambiguous"
            raise FcplanError(f"{where}: study {study!r} {why}; the folder holds: {listing}")
        rows = df[_hashes(df) == match[0].hash]
        return Selection(rows, match, _legacy_note(match))
    if len(found) > 1 and not allow_mixed:
        raise FcplanError(
            f"{where}: episodes of {len(found)} studies in one folder: {listing}; choose one "
            "with --study HASH, or pool them with --allow-mixed"
        )
    note = _legacy_note(found)
    if len(found) > 1:
        note = (
            f"This report pools {len(found)} different studies at the user's request "
            f"(allow_mixed): {listing}. Per-scheduler means mix different sets of episodes; "
            "paired comparisons pair episodes within a study only."
        )
    return Selection(df, found, note)


def _legacy_note(found: list[Study]) -> str:
    if any(s.hash == LEGACY for s in found):
        return (
            "Episodes written before study hashes were recorded are treated as one study "
            "(they cannot be checked for mixed studies)."
        )
    return ""
