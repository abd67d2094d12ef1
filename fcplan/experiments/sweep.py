"""Sweeps: expand a grid into episodes, run them anywhere, store each result as it finishes.

:func:`sweep` reads a sweep file (:mod:`fcplan.experiments.config`), skips the episodes already
stored in the results folder, runs the rest on a backend (:mod:`fcplan.experiments.backends`:
in-process, a local process pool, or Dask) and writes every finished episode at once as its own
Parquet file (:mod:`fcplan.experiments.results`). ``fcplan sweep CONFIG.toml`` is a thin layer
over it.

Resume and failures.

* Re-running the same sweep (or an extended one) into the same folder skips every episode whose
  key is stored, so an interrupted sweep (Ctrl-C, a crash, a killed machine) resumes where it
  stopped, having lost at most the episodes that were in flight.
* An episode that raises is stored as a *failed* row (``status = "failed"`` and the ``error``
  text) and the sweep runs on. Episodes are deterministic, so by default a re-run does **not**
  retry failed episodes (it would fail again); ``retry_failed=True`` (``--retry-failed``) plays
  them again, e.g. after fixing a scheduler, and the new row replaces the failed one.
* An episode whose worker process died (killed, out of memory) is *lost*: nothing is stored and
  a re-run plays it. :attr:`SweepSummary.lost` counts them.

Order. The episodes play seed by seed: the first seed of every scenario, override, setting and
scheduler, then the second, and so on (within a seed, in the grid's expansion order). A long
study stopped half-way therefore holds whole (scenario, seed) instances, every scheduler played
on them, spread over every scenario, rather than every seed of its first scenarios: its paired
comparisons already cover the whole grid on fewer seeds.

Processes and files.

* One sweep at a time writes into a results folder (:func:`~fcplan.experiments.results.lock_results`);
  a second one into the same folder stops at once with a one-line
  :class:`~fcplan.experiments.results.ResultsError`. Temporary files of dead sweeps are removed at
  the start; a live sweep's never are.
* Pool workers die with the sweep: they ask the kernel for SIGKILL when their parent dies
  (Linux ``PR_SET_PDEATHSIG``) and a watchdog thread checks the parent every second elsewhere
  (:func:`~fcplan.experiments.workers.init_worker`), so ``kill -9`` of the sweep leaves no worker
  behind. SIGTERM is handled like Ctrl-C by ``fcplan`` (the workers are stopped, every row
  stored so far is kept).
* A write that fails (a full disk) stops the sweep with a one-line
  :class:`~fcplan.experiments.results.ResultsError`; the rows stored so far are intact and a
  re-run resumes.
* Schedulers with a deterministic mode run in it unless ``deterministic=False`` (``fcplan sweep
  --wall-time``), see :mod:`fcplan.experiments.config`.

Studies. Every row carries its sweep's ``config_hash`` (the grid) and ``study_hash`` (the grid
without its seeds, :attr:`~fcplan.experiments.config.SweepConfig.study_hash`): re-running a sweep
with more seeds into its folder extends the same study, while a different grid written into the
same folder is another study, which :func:`~fcplan.experiments.report` refuses to pool without
``allow_mixed``. The folder keeps one ``manifest-<study_hash>.json`` per study (the grid of its
latest run).

Seeds auto. ``seeds="auto"`` (``fcplan sweep --seeds auto``) replaces the file's seeds by 0, 1,
2, ... played in batches of ``seed_batch`` until every pair of schedulers is resolved on
``metric`` over the whole study (the report's paired table, pooled over settings; the
``oracle`` left out) or ``max_seeds`` seeds are played (:mod:`fcplan.experiments.autoseeds`);
:attr:`SweepSummary.stopped` says why it stopped. A re-run resumes: stored episodes are skipped.

Progress is one ``tqdm`` bar counted in episodes (:mod:`fcplan.experiments.progress`), on stderr.

Examples
--------
>>> import tempfile
>>> config = {"scenarios": ["practice"], "schedulers": ["greedy", "idle"], "seeds": [0],
...           "overrides": {"duration_s": 5}}
>>> out = tempfile.mkdtemp()
>>> s = sweep(config, out, jobs=1, progress=False)
>>> s.ran, s.skipped, s.failed
(2, 0, 0)
>>> sweep(config, out, jobs=1, progress=False).skipped  # resumed: nothing left to do
2
>>> sorted(s.load()["scheduler"])
['greedy', 'idle']
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fcplan.errors import FcplanError
from fcplan.experiments.analysis import paired_table, results_pair_key
from fcplan.experiments.autoseeds import AutoSeeds
from fcplan.experiments.backends import select_backend
from fcplan.experiments.config import SweepConfig, load_sweep_config
from fcplan.experiments.progress import EpisodeBar, Progress, ProgressCallback, episode_progress
from fcplan.experiments.results import (
    ResultsError,
    load_results,
    lock_results,
    remove_stale_temporaries,
    stored_status,
    write_manifest,
    write_row,
)
from fcplan.experiments.tables import check_metric
from fcplan.experiments.workers import check_dask, check_jobs, default_jobs, runtime_factories

__all__ = ["SweepSummary", "sweep"]


@dataclass
class SweepSummary:
    """What one :func:`sweep` call did.

    Attributes
    ----------
    results : Path
        The results folder.
    config_hash : str
    backend : str
        ``serial``, ``pool`` or ``dask:<address>``.
    total : int
        Episodes in the grid.
    skipped : int
        Already stored (not run again).
    ran : int
        Played and stored now (completed or failed).
    failed : int
        Of ``ran``, episodes stored as failed.
    lost : list of str
        ``"<label> <scenario> seed <n>: <why>"`` for episodes that produced nothing.
    errors : list of str
        ``"<label> <scenario> seed <n>: <error>"`` for the failed episodes.
    wall_time_s : float
    stopped : str
        Why a ``seeds="auto"`` sweep stopped (``""`` otherwise).
    """

    results: Path
    config_hash: str
    backend: str
    total: int
    skipped: int = 0
    ran: int = 0
    failed: int = 0
    lost: list[str] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    wall_time_s: float = 0.0
    stopped: str = ""

    def load(self) -> Any:
        """:func:`~fcplan.experiments.load_results` of the results folder."""
        return load_results(self.results)

    def format(self) -> str:
        """One paragraph for the terminal."""
        rate = 60 * self.ran / self.wall_time_s if self.wall_time_s > 0 else 0.0
        text = (
            f"sweep {self.config_hash}: {self.total} episodes; {self.skipped} already stored, "
            f"{self.ran} run now ({self.failed} failed, {len(self.lost)} lost) on {self.backend} "
            f"in {self.wall_time_s:.1f} s ({rate:.1f} episodes/min); results in {self.results}"
        )
        if self.lost:
            text += (
                f"\n{len(self.lost)} episode(s) lost, re-run to play them; first: {self.lost[0]}"
            )
        if self.stopped:
            text += f"\nseeds auto: {self.stopped}"
        return text


def _describe(spec: Any) -> str:
    extra = f" {spec.overrides}" if spec.overrides else ""
    return f"{spec.label} {spec.base_scenario} seed {spec.seed}{extra}"


def sweep(
    config: str | os.PathLike[str] | Mapping[str, Any] | SweepConfig,
    results: str | os.PathLike[str] = "results",
    *,
    jobs: int | None = None,
    dask: str | None = None,
    retry_failed: bool = False,
    progress: Progress = True,
    deterministic: bool = True,
    seeds: str | None = None,
    max_seeds: int = 50,
    seed_batch: int = 5,
    metric: str = "manual.final_score",
) -> SweepSummary:
    """Run a sweep, storing each finished episode in ``results`` at once.

    Parameters
    ----------
    config : path, dict or SweepConfig
        A sweep TOML file, the same document as a dict, or a loaded config (validated before
        anything runs; :class:`~fcplan.experiments.config.SweepConfigError` otherwise).
    results : path
        The results folder (created if needed). Episodes already in it are skipped.
    jobs : int, optional
        Worker processes (default: one per core). ``jobs=1`` without ``dask`` plays in this
        process.
    dask : str, optional
        ``"local"`` to start a Dask LocalCluster of ``jobs`` workers, or the address of an
        existing Dask scheduler (``"tcp://host:8786"``).
    retry_failed : bool
        Also re-run episodes stored as failed (see the module docstring).
    progress : bool or callable
        ``True``: a progress bar on stderr (:mod:`fcplan.experiments.progress`); ``False``:
        silent; or a ``progress(done, total, row)`` callback.
    deterministic : bool
        Run schedulers that have a deterministic mode in it (default); False is the wall-time
        mode (:func:`~fcplan.experiments.config.load_sweep_config`).
    seeds : ``"auto"``, optional
        Replace the file's seeds by batches of ``seed_batch`` until every pair of schedulers is
        resolved on ``metric`` or ``max_seeds`` are played (module docstring).
    max_seeds, seed_batch : int
    metric : str
        The headline metric of ``seeds="auto"``.

    Returns
    -------
    SweepSummary

    Raises
    ------
    SweepConfigError, ResultsError
        A bad config; a results folder holding damaged or foreign files, in use by another
        sweep, or a failed write (a full disk).
    KeyboardInterrupt
        On Ctrl-C, after stopping the workers; everything finished so far is stored.
    """
    cfg = load_sweep_config(config, deterministic=deterministic)
    _check_backend_args(jobs, dask)
    auto = None
    if seeds is not None:
        if not (isinstance(seeds, str) and seeds.strip().lower() == "auto"):
            raise FcplanError(f"seeds: 'auto' or None (the file's seeds), got {seeds!r}")
        auto = AutoSeeds(seed_batch, max_seeds, check_metric(metric))
    jobs = jobs or default_jobs()
    out = _results_folder(results)
    report = episode_progress(progress, "sweep")
    try:
        with lock_results(out):
            remove_stale_temporaries(out)

            def run(step: SweepConfig, rep: ProgressCallback | None) -> SweepSummary:
                return _run(step, out, jobs, dask, retry_failed, rep)

            if auto is None:
                return run(cfg, report)
            return _auto(cfg, auto, out, run, report)
    finally:
        if isinstance(report, EpisodeBar):
            report.close()


def _run(
    cfg: SweepConfig,
    out: Path,
    jobs: int,
    dask: str | None,
    retry_failed: bool,
    report: ProgressCallback | None,
) -> SweepSummary:
    """Play the episodes of ``cfg`` not stored in ``out`` (which this process has locked)."""
    specs = list({s.key: s for s in cfg.episodes()}.values())
    status = stored_status(out)
    todo = [s for s in specs if s.key not in status or (retry_failed and status[s.key] != "ok")]
    rounds = {seed: k for k, seed in enumerate(cfg.seeds)}
    todo.sort(key=lambda s: rounds.get(s.seed, len(rounds)))  # seed by seed (stable: grid order)
    h = cfg.config_hash
    doc = {"config_hash": h, "study_hash": cfg.study_hash, "source": cfg.source, **cfg.to_dict()}
    write_manifest(out, cfg.study_hash, doc)
    runtime = runtime_factories([v.name for v in cfg.schedulers])
    backend, outcomes = select_backend(todo, jobs, runtime, dask=dask)
    summary = SweepSummary(out, h, backend, total=len(specs), skipped=len(specs) - len(todo))
    t0 = time.perf_counter()
    try:
        for done, (spec, row, lost) in enumerate(outcomes, 1):
            row = _store(out, cfg, spec, row, lost, summary)
            if report is not None:
                report(done, len(todo), row)
    finally:
        outcomes.close()
        summary.wall_time_s = time.perf_counter() - t0
    return summary


def _auto(
    cfg: SweepConfig,
    auto: AutoSeeds,
    out: Path,
    run: Callable[[SweepConfig, ProgressCallback | None], SweepSummary],
    report: ProgressCallback | None,
) -> SweepSummary:
    """Sweep seeds ``0 .. k batch - 1`` for k = 1, 2, ... until :meth:`AutoSeeds.decide` stops
    (``run(config, progress)`` plays the episodes of a config not stored yet)."""
    policies = [v.label for v in cfg.schedulers if v.name != "oracle"]
    played = planned = 0

    def batch_report(done: int, total: int, row: dict[str, Any]) -> None:
        if report is not None:
            report(played + done, planned + total, row)

    total = SweepSummary(out, cfg.config_hash, "", total=0)
    look = 0
    while True:
        look += 1
        step = dataclasses.replace(cfg, seeds=tuple(auto.seeds(look)))
        s = run(step, batch_report)
        played, planned = played + s.ran + len(s.lost), planned + s.total - s.skipped
        total = dataclasses.replace(
            total,
            config_hash=s.config_hash,
            backend=s.backend,
            total=s.total,
            ran=total.ran + s.ran,
            failed=total.failed + s.failed,
            lost=total.lost + s.lost,
            errors=total.errors + s.errors,
            wall_time_s=total.wall_time_s + s.wall_time_s,
        )
        rows = _study_rows(out, cfg.study_hash, step.seeds)
        pairs = paired_table(
            rows,
            policies,
            auto.metric,
            results_pair_key,
            confidence=auto.look_confidence,
            alpha=auto.look_alpha,
        )
        decision = auto.decide(pairs, look)
        if decision.stop or s.lost:  # lost episodes: stop, a re-run plays them and goes on
            total.skipped = total.total - total.ran - len(total.lost)
            total.stopped = decision.reason if decision.stop else "stopped: episodes were lost"
            return total


def _study_rows(out: Path, study: str, seeds: tuple[int, ...]) -> list[dict[str, Any]]:
    """The completed episodes of ``study`` and ``seeds`` stored in ``out`` (episodes of later
    seeds, stored by an earlier run, do not count before their look)."""
    df = load_results(out)
    if df.empty or "study_hash" not in df:
        return []
    keep = (df["study_hash"] == study) & (df["status"] == "ok") & df["seed"].isin(seeds)
    return df[keep].to_dict("records")


def _check_backend_args(jobs: Any, dask: Any) -> None:
    """One-line errors for a bad ``jobs`` or ``dask`` argument."""
    if jobs is not None:
        check_jobs(jobs)
    check_dask(dask)


def _results_folder(results: str | os.PathLike[str]) -> Path:
    """The results folder, created if needed."""
    out = Path(results)
    if out.exists() and not out.is_dir():
        raise ResultsError(f"{out}: exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ResultsError(f"{out}: cannot create the results folder: {exc}") from None
    return out


def _store(
    out: Path,
    cfg: SweepConfig,
    spec: Any,
    row: dict[str, Any] | None,
    lost: str | None,
    summary: SweepSummary,
) -> dict[str, Any]:
    """Write a finished episode's row (or count a lost one) and return the row for progress."""
    if row is None:
        summary.lost.append(f"{_describe(spec)}: {lost}")
        return {"error": lost}
    row["config_hash"] = cfg.config_hash
    row["study_hash"] = cfg.study_hash
    row["sweep"] = cfg.name
    try:
        write_row(out, row)
    except ResultsError as exc:
        raise ResultsError(f"{exc}; {summary.ran} episode(s) stored by this run") from None
    summary.ran += 1
    if row.get("status") != "ok":
        summary.failed += 1
        summary.errors.append(f"{_describe(spec)}: {row.get('error')}")
    return row
