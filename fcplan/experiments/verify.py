"""Do stored results still hold? Play a sample of stored episodes again and compare them.

A study on a 2-core machine runs for hours and often across commits, and its results folder
keeps every finished episode. If a change alters a scheduler's behaviour (a fixed tie rule, a
new default), the folder silently mixes episodes of the old and the new code, and a leaderboard
made from it describes neither. The rows name their code (``code``,
:func:`fcplan.provenance.code_identity`), but a changed digest only says the files changed. This
module checks behaviour itself: fcplan's episodes are reproducible (the same scenario,
scheduler, settings and seed give the same trace in any process, for every scheduler in its
deterministic mode), so an episode played again by today's code must give the stored numbers
exactly, bit for bit. One that does not is *stale*.

:func:`verify_results` draws ``per_scheduler`` stored episodes of each scheduler label (seeded:
the same call on the same folder checks the same episodes), rebuilds each one from the folder's
manifests (the sweep grids, ``manifest-*.json``), accepts it only if the rebuilt episode has the
stored key
(which hashes the whole scenario document, the scheduler, its settings, the seed, the replan
period and the time limit: the inputs are the same), plays it, and compares every ``manual.*``,
``reference2020.*`` and ``outcome.*`` metric and the ``ticks``, ``replans`` and ``fallbacks``
counts (:data:`COMPARED`). NaN equals NaN; nothing else is tolerated.

The draw is among the episodes that can be checked; the others are counted by reason, never
taken as reproduced: failed episodes, episodes of the wall-time mode (``deterministic`` false:
their plans depend on the machine's load) and episodes no manifest rebuilds. A scheduler none of
whose episodes can be checked is *unverified*. A stored episode that differs may also come from
other library versions; the check says when the stored ``versions`` differ from this process's.

``fcplan verify RESULTS [--per-scheduler N]`` prints the table and exits 1 when an episode
differs or a scheduler is unverified (2 on bad input, as every command).

Examples
--------
>>> import tempfile
>>> from fcplan.experiments import sweep
>>> d = tempfile.mkdtemp()
>>> cfg = {"scenarios": ["practice"], "schedulers": ["greedy"], "seeds": [0, 1],
...        "overrides": {"duration_s": 5}}
>>> _ = sweep(cfg, d, jobs=1, progress=False)
>>> v = verify_results(d, per_scheduler=1)
>>> [(c.scheduler, c.status) for c in v.checks], v.stale
([('greedy', 'same')], [])
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.errors import FcplanError

__all__ = ["COMPARED", "Check", "Verification", "verify_results"]

#: Column prefixes and columns an episode played again must reproduce exactly.
COMPARED_PREFIXES = ("manual.", "reference2020.", "outcome.")
COMPARED = ("ticks", "replans", "fallbacks")

#: Manifest keys that are not part of the sweep document itself.
_MANIFEST_ONLY = ("config_hash", "study_hash", "source")


@dataclass(frozen=True)
class Check:
    """One stored episode checked (or not) against a replay.

    ``status`` is ``"same"`` (every compared value equal), ``"differs"`` (``differences`` lists
    ``(column, stored, now)``) or ``"not checked"`` (``reason`` says why).
    """

    key: str
    scheduler: str
    scenario: str
    seed: int
    status: str
    differences: tuple[tuple[str, Any, Any], ...] = ()
    reason: str = ""
    versions_differ: bool = False


@dataclass
class Verification:
    """The checks of :func:`verify_results`, in scheduler then key order."""

    folder: Path
    checks: list[Check] = field(default_factory=list)
    #: per scheduler label, the stored episodes that could not be checked, by reason
    skipped: dict[str, dict[str, int]] = field(default_factory=dict)

    @property
    def stale(self) -> list[str]:
        """Scheduler labels with at least one episode that today's code does not reproduce."""
        return sorted({c.scheduler for c in self.checks if c.status == "differs"})

    @property
    def unverified(self) -> list[str]:
        """Scheduler labels none of whose stored episodes could be checked."""
        checked = {c.scheduler for c in self.checks if c.status != "not checked"}
        return sorted(set(self.skipped) - checked)

    @property
    def ok(self) -> bool:
        """True when no checked episode differs and every label had one checked."""
        return not self.stale and not self.unverified

    def format(self) -> str:
        """The checks as a text table, the episodes that could not be checked, a verdict."""
        lines = [f"{'scheduler':<20} {'scenario':<28} {'seed':>5}  status"]
        for c in self.checks:
            what = c.status
            if c.status == "differs":
                col, old, new = c.differences[0]
                more = f" (+{len(c.differences) - 1} more)" if len(c.differences) > 1 else ""
                what = f"differs: {col} stored {old!r}, now {new!r}{more}"
                if c.versions_differ:
                    what += "; stored with other library versions"
            elif c.status == "not checked":
                what = f"not checked: {c.reason}"
            lines.append(f"{c.scheduler:<20} {c.scenario:<28} {c.seed:>5}  {what}")
        for label, reasons in sorted(self.skipped.items()):
            if reasons:
                why = ", ".join(f"{n} {r}" for r, n in sorted(reasons.items()))
                lines.append(f"{label}: stored episodes that cannot be checked: {why}")
        same = sum(c.status == "same" for c in self.checks)
        if self.stale:
            verdict = (
                f"STALE: today's code does not reproduce stored episodes of {', '.join(self.stale)}"
                f" ({same} reproduced); replay them (move their rows out and re-run the sweep)"
            )
        elif self.unverified:
            verdict = (
                f"UNVERIFIED: no stored episode of {', '.join(self.unverified)} can be checked"
                f" ({same} reproduced exactly)"
            )
        else:
            verdict = f"ok: {same} episode(s) reproduced exactly"
        return "\n".join([*lines, verdict])


def _equal(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


def _compared(row: dict[str, Any]) -> list[str]:
    return sorted(k for k in row if k.startswith(COMPARED_PREFIXES) or k in COMPARED)


def _specs(folder: Path) -> dict[str, Any]:
    """Every episode the folder's manifests describe, by key."""
    from fcplan.experiments.config import SweepConfigError, load_sweep_config
    from fcplan.experiments.results import load_manifests

    out: dict[str, Any] = {}
    for doc in load_manifests(folder):
        doc = {k: v for k, v in doc.items() if k not in _MANIFEST_ONLY}
        deterministic = bool(doc.pop("deterministic", True))
        if all(t is None for t in doc.get("time_limit") or [None]):
            doc.pop("time_limit", None)  # the schedulers' own limits: the file's default
        try:
            cfg = load_sweep_config(doc, deterministic=deterministic)
        except SweepConfigError:
            continue  # a grid this version cannot rebuild (a scenario file no longer there)
        out.update({s.key: s for s in cfg.episodes()})
    return out


def _sample(rows: list[dict[str, Any]], n: int, rng: np.random.Generator) -> list[dict[str, Any]]:
    rows = sorted(rows, key=lambda r: str(r["key"]))
    if len(rows) <= n:
        return rows
    pick = rng.choice(len(rows), size=n, replace=False)
    return [rows[i] for i in sorted(pick.tolist())]


def _check(
    stored: dict[str, Any], now: dict[str, Any], extra: tuple[tuple[str, Any, Any], ...] = ()
) -> Check:
    diffs = extra + tuple(
        (k, stored.get(k), now.get(k))
        for k in _compared(stored)
        if k in now and not _equal(stored.get(k), now.get(k))
    )
    return Check(
        key=str(stored["key"]),
        scheduler=str(stored["scheduler"]),
        scenario=str(stored["scenario"]),
        seed=int(stored["seed"]),
        status="differs" if diffs else "same",
        differences=diffs,
        versions_differ=stored.get("versions") != now.get("versions"),
    )


def verify_results(
    results: str | os.PathLike[str],
    *,
    per_scheduler: int = 1,
    schedulers: Iterable[str] | None = None,
    seed: int = 0,
    jobs: int = 1,
    progress: Callable[[int, int, dict[str, Any]], None] | None = None,
) -> Verification:
    """Play ``per_scheduler`` stored episodes of each scheduler again and compare them.

    Parameters
    ----------
    results : path
        A results folder of ``fcplan sweep``.
    per_scheduler : int
        Episodes drawn per scheduler label (at least 1); all of them if fewer are stored.
    schedulers : iterable of str, optional
        Only these labels (default: every label in the folder).
    seed : int
        Seed of the draw (the same seed on the same folder checks the same episodes).
    jobs : int
        Worker processes for the replays.
    progress : callable, optional
        ``progress(done, total, row)`` after each replay.

    Returns
    -------
    Verification

    Raises
    ------
    FcplanError
        No such folder, a bad ``per_scheduler``, or a label with no episode in the folder (one
        line).
    """
    from fcplan.experiments.backends import select_backend
    from fcplan.experiments.results import load_results
    from fcplan.experiments.workers import runtime_factories

    folder = Path(results)
    if not folder.is_dir():
        raise FcplanError(f"{folder}: no such results folder")
    if isinstance(per_scheduler, bool) or not isinstance(per_scheduler, int) or per_scheduler < 1:
        raise FcplanError(f"per_scheduler: an integer >= 1, got {per_scheduler!r}")
    rows = [dict(r) for r in load_results(folder).to_dict("records")]
    labels = sorted({str(r["scheduler"]) for r in rows})
    wanted = labels if schedulers is None else list(schedulers)
    for w in wanted:
        if w not in labels:
            raise FcplanError(
                f"{folder}: no episodes of scheduler {w!r} (has: {', '.join(labels)})"
            )
    specs = _specs(folder)
    rng = np.random.default_rng(seed)
    out = Verification(folder)
    todo: list[tuple[dict[str, Any], Any]] = []
    for label in wanted:
        playable, reasons = [], out.skipped.setdefault(label, {})
        for r in (r for r in rows if r["scheduler"] == label):
            why = _unplayable(r, specs)
            if why:
                reasons[why] = reasons.get(why, 0) + 1
            else:
                playable.append(r)
        todo.extend((r, specs[str(r["key"])]) for r in _sample(playable, per_scheduler, rng))
    stored = {spec.key: r for r, spec in todo}
    runtime = runtime_factories(sorted({spec.scheduler for _, spec in todo}))
    _, outcomes = select_backend([spec for _, spec in todo], jobs, runtime)
    try:
        for done, (spec, row, lost) in enumerate(outcomes, 1):
            r = stored[spec.key]
            if lost or row is None:
                out.checks.append(_not_checked(r, "the replay was lost (a worker died)"))
            elif row.get("status") != "ok":  # it ran before: failing now is a change too
                out.checks.append(_check(r, row, extra=(("status", "ok", row.get("error")),)))
            else:
                out.checks.append(_check(r, row))
            if progress is not None:
                progress(done, len(todo), row or {})
    finally:
        outcomes.close()
    out.checks.sort(key=lambda c: (c.scheduler, c.key))
    return out


def _unplayable(row: dict[str, Any], specs: dict[str, Any]) -> str:
    """Why a stored episode cannot be checked ("" when it can)."""
    if row.get("status") != "ok":
        return "failed"
    if not bool(row.get("deterministic")):
        return "played in the wall-time mode (plans depend on the machine's load)"
    if str(row["key"]) not in specs:
        return "no manifest in the folder rebuilds them"
    return ""


def _not_checked(row: dict[str, Any], reason: str) -> Check:
    return Check(
        key=str(row["key"]),
        scheduler=str(row["scheduler"]),
        scenario=str(row["scenario"]),
        seed=int(row["seed"]),
        status="not checked",
        reason=reason,
    )


def as_json(v: Verification) -> str:
    """The verification as JSON text (every check, then ``stale``)."""
    return json.dumps(
        {
            "folder": str(v.folder),
            "checks": [
                {
                    "key": c.key,
                    "scheduler": c.scheduler,
                    "scenario": c.scenario,
                    "seed": c.seed,
                    "status": c.status,
                    "differences": [list(d) for d in c.differences],
                    "reason": c.reason,
                    "versions_differ": c.versions_differ,
                }
                for c in v.checks
            ],
            "skipped": v.skipped,
            "stale": v.stale,
            "unverified": v.unverified,
        },
        indent=1,
        default=str,
    )
