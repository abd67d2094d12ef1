"""Sweep results: a folder of small Parquet files, one per finished episode.

Layout of a results folder (``fcplan sweep ... --results DIR``)::

    DIR/<key>.parquet          one row: a finished episode (completed or failed), named by its key
    DIR/manifest-<hash>.json   the normalised grid of each sweep run into this folder
    DIR/.<key>.<owner>.tmp     a write in progress (ignored; removed once its writer is dead)
    DIR/<subfolder>/           ignored (e.g. the report's default output, DIR/report/)

Crash safety. A row is written to a hidden temporary file, flushed to disk, then renamed over
``<key>.parquet`` (:func:`os.replace`, atomic on POSIX and Windows), so a reader sees either the
whole row or nothing: a killed sweep leaves no partial rows, at most a stray ``.tmp`` file. Because
the file name is the episode key, an episode is stored at most once, whatever retries happen.
A write that fails (a full disk: ``ENOSPC``) removes its temporary file and raises
:class:`ResultsError` (one line; the rows already stored are untouched).

Temporary files carry their writer (``<host>~<pid>~<random>``): :func:`remove_stale_temporaries`
deletes only those whose writer is dead (same host, no such process), never a live sweep's.
:func:`lock_results` lets one sweep at a time write into a folder (``fcntl.flock`` on the folder
itself, so nothing is left behind; on systems without ``fcntl`` the folder is not locked).

Each file carries the schema metadata key ``fcplan`` = ``{"format": "fcplan-sweep-episode",
"version": 1}``. :func:`load_results` refuses (with :class:`ResultsError` naming the file) a
Parquet file without it, a file that is not valid Parquet, and any other file in the folder.

Reading a folder from outside is bounded: only regular files are opened (a FIFO named
``x.parquet`` would block the reader forever), a row file of more than :data:`MAX_ROW_BYTES`
bytes is refused unread, and a row's Parquet footer is checked before its data are decoded: one
row, at most :data:`MAX_ROW_VALUES` values in all its columns (a 1.5 KB file can declare a list
of 10^8 values run-length encoded: a decompression bomb). A manifest must be a regular file of at
most :data:`MAX_MANIFEST_BYTES` holding a JSON object (:func:`load_manifests`).

Examples
--------
>>> import tempfile
>>> d = tempfile.mkdtemp()
>>> write_row(d, {"key": "abc123", "status": "ok", "error": "", "score": 1.5})  # doctest: +ELLIPSIS
PosixPath('.../abc123.parquet')
>>> load_results(d)[["key", "score"]].to_dict("records")
[{'key': 'abc123', 'score': 1.5}]
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import socket
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from fcplan.errors import FcplanError
from fcplan.experiments.optional import require

__all__ = [
    "MAX_MANIFEST_BYTES",
    "MAX_ROW_BYTES",
    "MAX_ROW_VALUES",
    "ResultsError",
    "load_manifests",
    "load_results",
    "lock_results",
    "hold_folder",
    "remove_stale_temporaries",
    "stored_status",
    "write_row",
    "write_manifest",
]

FORMAT: dict[str, Any] = {"format": "fcplan-sweep-episode", "version": 1}
#: Bound on one row file (a row of a 180-s episode is about 20 KB; one of a 10^6-tick episode
#: with its per-replan lists about 3 MB).
MAX_ROW_BYTES = 64 * 2**20
#: Bound on the values one row file's footer may declare, over all its columns (the per-replan
#: lists of a 10^6-tick episode replanned every second hold 3 x 10^5).
MAX_ROW_VALUES = 2**24
#: Bound on one manifest (a sweep grid of thousands of settings is a few hundred KB).
MAX_MANIFEST_BYTES = 16 * 2**20
_META_KEY = b"fcplan"
_ROW_FILE = re.compile(r"^[0-9A-Za-z_-]+\.parquet$")
_MANIFEST = re.compile(r"^manifest-[0-9a-f]+\.json$")
_TMP = re.compile(r"^\..+\.tmp$")
# the writer of a temporary file: ``.<stem>.<host>~<pid>~<random>.tmp`` (host: [A-Za-z0-9_-]);
# files of earlier versions, ``.<stem>.<pid>.<random>.tmp``, were written on this host
_OWNER = re.compile(r"^\..+\.(?P<host>[A-Za-z0-9_-]+)~(?P<pid>\d+)~[0-9a-f]+\.tmp$")
_OLD_OWNER = re.compile(r"^\..+?\.(?P<pid>\d+)(?:\.[0-9a-f]+)?\.tmp$")


def _host() -> str:
    return re.sub(r"[^A-Za-z0-9_-]", "_", socket.gethostname()) or "host"


def _temporary(directory: Path, stem: str) -> Path:
    """A fresh hidden temporary file name in ``directory`` naming its writer (this process)."""
    return directory / f".{stem}.{_host()}~{os.getpid()}~{uuid.uuid4().hex[:8]}.tmp"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True  # someone else's process (or a pid we cannot ask about): leave it
    return True


def _write_failed(path: Path, exc: OSError) -> ResultsError:
    """A one-line error for a failed write (a full disk named as such)."""
    why = exc.strerror or str(exc)
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        why = f"{why}: the disk is full; free some space and re-run the same command to resume"
    return ResultsError(f"cannot write {path}: {why} (rows already stored are intact)")


class ResultsError(FcplanError):
    """A results folder is missing, or holds a file that is not a sweep result (named)."""


def write_row(directory: str | os.PathLike[str], row: dict[str, Any]) -> Path:
    """Write ``row`` atomically as ``directory/<row["key"]>.parquet`` (replacing an older one).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ResultsError
        The write failed (e.g. a full disk); nothing is left behind.
    """
    pa = require("pyarrow", "parquet")
    pq = require("pyarrow.parquet", "parquet")
    d = Path(directory)
    key = str(row["key"])
    if not _ROW_FILE.match(f"{key}.parquet"):
        raise ResultsError(f"episode key {key!r} is not a valid file name")
    table = pa.Table.from_pylist([row])
    table = table.replace_schema_metadata({_META_KEY: json.dumps(FORMAT).encode()})
    final = d / f"{key}.parquet"
    tmp = _temporary(d, key)
    try:
        with open(tmp, "wb") as fh:
            pq.write_table(table, fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, final)
    except OSError as exc:
        raise _write_failed(final, exc) from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()
    return final


def write_manifest(directory: str | os.PathLike[str], config_hash: str, doc: dict) -> Path:
    """Write the sweep's normalised grid as ``manifest-<config_hash>.json`` (atomically)."""
    path = Path(directory) / f"manifest-{config_hash}.json"
    tmp = _temporary(Path(directory), f"manifest-{config_hash}")
    try:
        tmp.write_text(json.dumps(doc, indent=1, sort_keys=True, default=str) + "\n", "utf-8")
        os.replace(tmp, path)
    except OSError as exc:
        raise _write_failed(path, exc) from None
    finally:
        with contextlib.suppress(OSError):
            tmp.unlink()
    return path


def remove_stale_temporaries(directory: str | os.PathLike[str]) -> int:
    """Delete the ``.tmp`` files of dead writers (killed sweeps); returns how many.

    A temporary file names its writer (host and pid). It is stale when the writer ran on this
    host and no process has its pid any more; a live writer's file (another sweep writing now)
    and another host's are left alone.
    """
    here, n = _host(), 0
    for p in Path(directory).iterdir():
        m = _OWNER.match(p.name) or _OLD_OWNER.match(p.name)
        if m is None or not p.is_file():
            continue
        if m.groupdict().get("host", here) != here or _alive(int(m.group("pid"))):
            continue
        with contextlib.suppress(FileNotFoundError):
            p.unlink()
            n += 1
    return n


@contextlib.contextmanager
def lock_results(directory: str | os.PathLike[str]) -> Iterator[None]:
    """Hold the results folder ``directory`` for one sweep (an exclusive ``flock`` on it).

    Raises
    ------
    ResultsError
        Another process holds it (another sweep is writing into the folder).

    Examples
    --------
    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> with lock_results(d):
    ...     with lock_results(d):
    ...         pass  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fcplan.experiments.results.ResultsError: ...: another sweep is writing into this results folder...
    """
    busy = (f"{directory}: another sweep is writing into this results folder; wait for it "
            "to finish (then re-run to resume) or choose another --results folder")  # fmt: skip
    with hold_folder(directory, lambda: ResultsError(busy)):
        yield


@contextlib.contextmanager
def hold_folder(directory: str | os.PathLike[str], busy: Any) -> Iterator[None]:
    """Hold ``directory`` for this process (an exclusive, non-blocking ``flock`` on it), or
    raise ``busy()`` when another process holds it; no locking where ``flock`` is missing (not
    POSIX, some network mounts). The one folder lock of sweeps' results and demonstrations'
    checkpoints."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX: no locking
        yield
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise busy() from None
        except OSError:  # a file system without flock (some network mounts): no locking
            pass
        yield
    finally:
        os.close(fd)  # releases the lock


def _row_files(directory: str | os.PathLike[str]) -> Iterator[Path]:
    d = Path(directory)
    if not d.exists():
        raise ResultsError(f"{d}: no such results folder")
    if not d.is_dir():
        raise ResultsError(f"{d}: not a folder (results are a folder of Parquet files)")
    for p in sorted(d.iterdir()):
        if p.is_dir() or _TMP.match(p.name):
            continue
        if _MANIFEST.match(p.name):
            _manifest(p)
            continue
        if not _ROW_FILE.match(p.name):
            raise ResultsError(
                f"{p}: foreign file in a results folder (expected <key>.parquet episode files "
                "and manifest-*.json); move it elsewhere"
            )
        if not p.is_file():  # a FIFO, socket or device would block or never end: never opened
            raise ResultsError(f"{p}: not a regular file (a FIFO, socket or device?); remove it")
        yield p


def _open_regular(path: Path, cap: int) -> IO[bytes]:
    """``path`` opened if it is a regular file of at most ``cap`` bytes (never blocking on a
    FIFO or device: :func:`fcplan.recording.reader.open_regular`)."""
    from fcplan.recording.reader import open_regular

    return open_regular(path, ResultsError, cap)


def _manifest(path: Path) -> dict[str, Any]:
    """The sweep grid a manifest holds (a JSON object), or a one-line ResultsError."""
    try:
        with _open_regular(path, MAX_MANIFEST_BYTES) as fh:
            data = fh.read(MAX_MANIFEST_BYTES + 1)
    except OSError as exc:
        raise ResultsError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        doc = json.loads(data[:MAX_MANIFEST_BYTES].decode("utf-8"))
    except (ValueError, RecursionError) as exc:
        reason = getattr(exc, "msg", type(exc).__name__)
        doc = f"not valid JSON ({reason})"
    if not isinstance(doc, dict):
        why = doc if isinstance(doc, str) else "not a JSON object"
        raise ResultsError(
            f"{path}: damaged sweep manifest: {why}; delete it (the next sweep of this grid "
            "writes it again)"
        )
    return doc


def load_manifests(directory: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The sweep grids (``manifest-*.json``) stored in a results folder, oldest first.

    Raises
    ------
    ResultsError
        A manifest that is not a regular file, is larger than :data:`MAX_MANIFEST_BYTES` or does
        not hold a JSON object (named).

    Examples
    --------
    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> _ = write_manifest(d, "0a", {"schedulers": [{"label": "greedy"}]})
    >>> load_manifests(d)
    [{'schedulers': [{'label': 'greedy'}]}]
    """
    found = [p for p in Path(directory).iterdir() if _MANIFEST.match(p.name)]
    return [_manifest(p) for p in sorted(found, key=lambda p: (p.lstat().st_mtime, p.name))]


def _check_footer(pf: Any, path: Path) -> None:
    """Refuse, from its footer alone, a row file that is too big to decode (see the module)."""
    md = pf.metadata
    if md.num_rows != 1:
        raise ResultsError(f"{path}: expected one episode row, found {md.num_rows}")
    values = sum(
        md.row_group(g).column(c).num_values
        for g in range(md.num_row_groups)
        for c in range(md.num_columns)
    )
    if values > MAX_ROW_VALUES:
        raise ResultsError(
            f"{path}: declares {values:,} values, more than the {MAX_ROW_VALUES:,} of an "
            "episode row; not written by fcplan sweep: move it elsewhere"
        )


def _read(path: Path, columns: list[str] | None = None) -> Any:
    pq = require("pyarrow.parquet", "parquet")
    fh = _open_regular(path, MAX_ROW_BYTES)
    try:
        pf = pq.ParquetFile(fh)
        _check_footer(pf, path)
        meta = pf.schema_arrow.metadata or {}
        table = pf.read(columns=columns, use_threads=False)
    except ResultsError:
        raise
    except Exception as exc:  # noqa: BLE001 - any reader failure means a damaged file
        raise ResultsError(
            f"{path}: not a readable Parquet file ({type(exc).__name__}: {exc}); delete it to "
            "re-run that episode"
        ) from None
    finally:
        fh.close()
    try:
        fmt = json.loads(meta.get(_META_KEY, b"{}"))
    except (ValueError, RecursionError):
        fmt = {}
    if not isinstance(fmt, dict) or fmt.get("format") != FORMAT["format"]:
        raise ResultsError(f"{path}: a Parquet file not written by fcplan sweep (foreign file)")
    version = fmt.get("version", 0)
    newest: int = FORMAT["version"]
    if not isinstance(version, int) or version > newest:
        raise ResultsError(
            f"{path}: results format version {version!r:.40} is not one this fcplan reads "
            f"(1..{FORMAT['version']}; written by a newer fcplan?)"
        )
    if table.num_rows != 1:
        raise ResultsError(f"{path}: expected one episode row, found {table.num_rows}")
    return table


def stored_status(directory: str | os.PathLike[str]) -> dict[str, str]:
    """``{key: status}`` (``ok`` or ``failed``) of every episode stored in ``directory``.

    An absent folder has no episodes (``{}``); damaged or foreign files raise
    :class:`ResultsError`.
    """
    if not Path(directory).exists():
        return {}
    out = {}
    for p in _row_files(directory):
        t = _read(p, ["key", "status"])
        out[t.column("key")[0].as_py()] = t.column("status")[0].as_py()
    return out


def load_results(directory: str | os.PathLike[str]) -> Any:
    """All episodes in a results folder as a :class:`pandas.DataFrame` (one row per episode).

    Rows are sorted by ``finished_at`` when present (then by key). Columns are those of
    :mod:`fcplan.experiments.play`; a failed episode has ``status = "failed"``, its ``error``,
    and NaN metrics.

    Raises
    ------
    ResultsError
        The folder does not exist, or a file in it is damaged or foreign (named in the message).

    Examples
    --------
    >>> import tempfile
    >>> len(load_results(tempfile.mkdtemp()))
    0
    """
    pd = require("pandas", "parquet")
    pa = require("pyarrow", "parquet")
    tables = [_read(p) for p in _row_files(directory)]
    if not tables:
        return pd.DataFrame({"key": pd.Series(dtype=str), "status": pd.Series(dtype=str)})
    try:
        table = pa.concat_tables(
            [t.replace_schema_metadata(None) for t in tables], promote_options="permissive"
        )
        df = table.to_pandas(use_threads=False)
        order = [c for c in ("finished_at", "key") if c in df.columns]
        return df.sort_values(order, kind="stable").reset_index(drop=True)
    except (pa.ArrowException, TypeError, ValueError) as exc:
        raise ResultsError(
            f"{directory}: episode files with incompatible columns: {str(exc)[:200]}"
        ) from None
