"""Reading recordings: :func:`load_recording` opens a file from anywhere safely, within bounds.

A recording may come from outside (a colleague, a download), so the reader trusts nothing in it:

1. **The file.** Only a regular file is read (a FIFO or device is refused without blocking), and
   at most ``max_bytes`` of it.
2. **The archive.** At most :data:`MAX_ENTRIES` listed entries; only the documented entries (:data:`~fcplan.recording.schema.SCHEMA` and the
   JSON entries) are opened; any other entry is never decompressed. Each entry must be stored or
   deflated, unencrypted, and start with an ``.npy`` header (format 1.0 or 2.0) whose dtype is the
   schema's (an object dtype, i.e. a pickle, is refused without being read).
3. **Shapes before bytes.** The JSON header is read first (at most :data:`MAX_HEADER_CHARS`
   characters); its scenario and tick count fix every shape: ``T`` (at most the scenario's ticks),
   ``N`` agents, ``F`` facilities; event cells must add up to their counts (at most ``W**2``),
   commands at most ``(T + 1) N``, replans at most ``T + 1``, route points to the route lengths.
   Each entry's declared shape is checked against that, and the bytes of all entries against
   ``max_bytes``, *before* anything is allocated; then exactly the declared bytes are
   decompressed (and the entry's CRC checked).
4. **Values.** Positions, route goals and altitudes must be finite and within ``[-W, 2W]``
   (NaN altitude: not given), agent modes valid, goal indices >= -1, ticks within the episode,
   counts non-negative and adding up, cells and agent rows in range.

Any failure, however the file is damaged, is a :class:`~fcplan.recording.schema.RecordingError`
naming the file (and the entry): never another exception, a hang, or an allocation the header does
not justify.

Examples
--------
>>> import os, tempfile
>>> from fcplan import load_scenario
>>> from fcplan.mission import Mission
>>> from fcplan.recording import Recorder, load_recording
>>> sc = load_scenario("practice")
>>> rec = Recorder(sc, 0, source="human")
>>> Mission(sc, seed=0, observers=[rec]).advance(20)
20
>>> path = os.path.join(tempfile.mkdtemp(), "short.npz")
>>> _ = rec.save(path)
>>> load_recording(path).n_ticks
20
>>> with open(path, "r+b") as f:  # one flipped bit
...     _ = f.seek(300)
...     b = f.read(1)
...     _ = f.seek(300)
...     _ = f.write(bytes([b[0] ^ 4]))
>>> load_recording(path)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.recording.schema.RecordingError: ...short.npz: ...
"""

from __future__ import annotations

import io
import json
import math
import os
import stat
import warnings
import zipfile
from typing import IO, Any

import numpy as np

from fcplan.errors import FcplanError
from fcplan.recording.schema import (
    EVENTS,
    FORMAT,
    JSON_ENTRIES,
    READ_VERSIONS,
    SCHEMA,
    RecordingError,
)
from fcplan.recording.writer import Recording
from fcplan.scenario import Scenario

__all__ = [
    "MAX_BYTES",
    "MAX_ENTRIES",
    "MAX_HEADER_CHARS",
    "check_recording",
    "load_recording",
    "open_regular",
    "read_bytes",
]

#: Default bound on a recording file and on its decompressed entries (a 180-s episode of #24 is
#: about 0.1 MB on disk and 1 MB decompressed; 600 s of a 30-agent 2000-px world about 20 MB).
MAX_BYTES = 256 * 2**20
#: Bound on the entries an archive may list (a recording has 30; each listed entry costs memory
#: when the archive's directory is parsed, even if it is never read).
MAX_ENTRIES = 1024
#: Bound on the JSON header's length (a scenario with a thousand facilities is ~100 k).
MAX_HEADER_CHARS = 4 * 2**20
_ZIP_METHODS = (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED)
_MODES = 4  # fcplan.team.Mode: IDLE, ACTIVE, RETURNING, HOMING


def open_regular(
    path: str | os.PathLike[str], error: type[FcplanError], max_bytes: float = math.inf
) -> IO[bytes]:
    """``path`` opened for binary reading if it is a regular file of at most ``max_bytes``.

    The file is opened without blocking (a FIFO has no writer to wait for) and checked with
    ``fstat`` before anything is read, so neither a special file nor a huge one costs time or
    memory. Failures raise ``error`` naming the file.
    """
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise error(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{path}: not a regular file (a FIFO, socket, device or folder)")
        if st.st_size > max_bytes:
            raise error(f"{path}: {st.st_size:,} bytes exceeds the bound of {max_bytes:,}")
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_bytes(
    path: str, error: type[FcplanError] = RecordingError, max_bytes: int | None = None
) -> bytes:
    """The bytes of ``path`` if it is a regular file (of at most ``max_bytes`` bytes), opened
    with :func:`open_regular` and read up to one byte past the bound (a file that grows while
    read is refused too). Failures raise ``error`` naming the file.

    The first read asks for the file's size plus one byte, not for the bound: a buffered read
    allocates what it is asked for before reading, so asking for the bound would reserve it for
    every small file. A file that grew while read is read on in chunks of at most 1 MiB.
    """
    cap = math.inf if max_bytes is None else max_bytes
    with open_regular(path, error, cap) as fh:
        try:
            want = int(min(os.fstat(fh.fileno()).st_size, cap)) + 1
            data = fh.read(want)
            if len(data) == want:  # it grew while read: on, in bounded chunks, past the bound
                parts, total = [data], len(data)
                while total <= cap and (chunk := fh.read(int(min(1 << 20, cap + 1 - total)))):
                    parts.append(chunk)
                    total += len(chunk)
                data = b"".join(parts)
        except OSError as exc:
            raise error(f"{path}: cannot read: {exc.strerror or exc}") from None
    if len(data) > cap:
        raise error(f"{path}: grew past the bound of {max_bytes} bytes while read")
    return data


def load_recording(path: str | os.PathLike[str], *, max_bytes: int = MAX_BYTES) -> Recording:
    """Read and check a recording written by :meth:`Recorder.save
    <fcplan.recording.Recorder.save>` (never unpickles anything; see the module docstring).

    Parameters
    ----------
    path : str or PathLike
        The ``.npz`` file.
    max_bytes : int
        Bound on the file's size and on the total decompressed size of its entries.

    Raises
    ------
    RecordingError
        If the file is missing or special, not an npz archive, damaged, holds object arrays, is
        not an fcplan recording, has an unknown format version, or an entry has the wrong dtype,
        shape or values.
    """
    path = os.fspath(path)
    data = read_bytes(path, RecordingError, max_bytes)
    if not data.startswith(b"PK"):
        raise RecordingError(f"{path}: not a readable npz archive (not a zip file)")
    if _listed_entries(data) > MAX_ENTRIES:
        raise RecordingError(f"{path}: the archive lists more than {MAX_ENTRIES} entries")
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            return _Archive(zf, path, max_bytes).recording()
    except RecordingError:
        raise
    except Exception as exc:  # a damaged archive raises many types; none may escape
        raise RecordingError(
            f"{path}: not a readable npz archive ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None


def _listed_entries(data: bytes) -> int:
    """The entry count the archive's end record declares (0 when there is none: the zip reader
    then refuses the file), read before the directory is parsed."""
    end = data.rfind(b"PK\x05\x06", max(0, len(data) - 65_557))
    if end < 0 or end + 22 > len(data):
        return 0
    count = int.from_bytes(data[end + 10 : end + 12], "little")
    if count == 0xFFFF:  # zip64: the count is in the zip64 end record
        z64 = data.rfind(b"PK\x06\x06", 0, end)
        if z64 >= 0 and z64 + 40 <= len(data):
            count = int.from_bytes(data[z64 + 32 : z64 + 40], "little")
    return count


def check_recording(rec: Recording, source: str = "<recording>") -> None:
    """Check an in-memory recording as :func:`load_recording` checks a file (shapes, dtypes,
    values); :class:`RecordingError` naming ``source`` if it is not one the reader would load."""
    sc = _scenario(rec.header, source)
    dims = _dims(rec.header, sc, len(rec.arrays["active"]), source)
    dims.update(
        C=len(rec.arrays["command_tick"]),
        R=len(rec.arrays["replan_tick"]),
        K=len(rec.arrays["input_tick"]),
    )
    for name, f in SCHEMA.items():
        arr = rec.arrays[name]
        if not f.fits(arr, dims):
            shown = ["*" if w is None else w for w in f.shape(dims)]
            raise RecordingError(
                f"{source}: entry {name!r} is {arr.dtype}{list(arr.shape)}, expected "
                f"{f.dtype}{shown}"
            )
    _check_values(rec, sc, dims, source)


# ------------------------------------------------------------------------------- the archive
class _Archive:
    """One open archive: its documented entries, read in dependency order under a byte budget."""

    def __init__(self, zf: zipfile.ZipFile, path: str, max_bytes: int) -> None:
        self.zf, self.path, self.budget = zf, path, max_bytes
        wanted = {*SCHEMA, *JSON_ENTRIES}
        self.infos: dict[str, zipfile.ZipInfo] = {}
        for info in zf.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else None
            if name in wanted:
                if name in self.infos:
                    raise RecordingError(f"{path}: entry {name!r} appears twice")
                self.infos[name] = info
        if "header" not in self.infos:
            raise RecordingError(f"{path}: not an fcplan recording (no 'header' entry)")

    def recording(self) -> Recording:
        header = self._json("header", MAX_HEADER_CHARS)
        _check_header(header, self.path)
        missing = [k for k in (*SCHEMA, *JSON_ENTRIES) if k not in self.infos]
        if missing:
            raise RecordingError(f"{self.path}: missing entries {', '.join(missing)}")
        sc = _scenario(header, self.path)
        a: dict[str, np.ndarray] = {}
        a["active"] = self._array("active", _at_most(sc.n_ticks))
        dims = _dims(header, sc, len(a["active"]), self.path)
        t_n, n_agents, w = dims["T"], dims["N"], sc.world_size
        for name, f in SCHEMA.items():
            if all(isinstance(d, int) or d in dims for d in f.axes) and name not in a:
                a[name] = self._array(name, _exactly(f.shape(dims)))
        for k in EVENTS:
            total = _nonneg_sum(a[f"{k}_count"], f"{k}_count", self.path)
            if total > w * w:
                raise RecordingError(f"{self.path}: {k}_count adds up to more than W**2 cells")
            a[f"{k}_cells"] = self._array(f"{k}_cells", _exactly((total,)))
        a["command_tick"] = self._array("command_tick", _at_most((t_n + 1) * n_agents))
        a["replan_tick"] = self._array("replan_tick", _at_most(t_n + 1))
        a["input_tick"] = self._array("input_tick", _at_most(2**31))
        dims.update(C=len(a["command_tick"]), R=len(a["replan_tick"]), K=len(a["input_tick"]))
        for name, f in SCHEMA.items():
            if name not in a and name != "command_route_xy":
                a[name] = self._array(name, _exactly(f.shape(dims)))
        n_goals = _nonneg_sum(a["command_route_len"], "command_route_len", self.path)
        a["command_route_xy"] = self._array("command_route_xy", _exactly((n_goals, 2)))
        replans = self._json("replans", 64 * 1024 * (dims["R"] + 16))
        inputs = self._json("inputs", 4 * 1024 * (dims["K"] + 16))
        for name, value in (("replans", replans), ("inputs", inputs)):
            if not (isinstance(value, list) and all(isinstance(v, dict) for v in value)):
                raise RecordingError(f"{self.path}: entry {name!r} must be a JSON list of objects")
        rec = Recording(header, a, replans, inputs)
        _check_values(rec, sc, dims, self.path)
        return rec

    def _open(self, name: str) -> tuple[IO[bytes], tuple[int, ...], bool, np.dtype]:
        """The entry's stream positioned at its data, and its declared shape, order and dtype."""
        info = self.infos[name]
        if info.flag_bits & 0x1 or info.compress_type not in _ZIP_METHODS:
            raise RecordingError(
                f"{self.path}: entry {name!r} is encrypted or uses compression method "
                f"{info.compress_type} (recordings are stored or deflated)"
            )
        f = self.zf.open(info)
        try:
            version = np.lib.format.read_magic(f)
            if version not in ((1, 0), (2, 0)):
                raise RecordingError(f"{self.path}: entry {name!r} has .npy version {version}")
            with warnings.catch_warnings():  # (odd headers warn; they are refused or read)
                warnings.simplefilter("ignore")
                read = np.lib.format.read_array_header_1_0
                if version == (2, 0):
                    read = np.lib.format.read_array_header_2_0
                shape, fortran, dtype = read(f)
        except BaseException:
            f.close()
            raise
        if dtype.hasobject:
            f.close()
            raise RecordingError(
                f"{self.path}: holds an object (pickled) array in {name!r}; recordings never do, "
                "refusing to load it"
            )
        return f, shape, fortran, dtype

    def _array(self, name: str, shape: _Shape) -> np.ndarray:
        """Entry ``name`` if its dtype is the schema's and its shape fits ``shape``; only then are
        its bytes (charged to the budget) decompressed."""
        f, declared, fortran, dtype = self._open(name)
        with f:
            want = np.dtype(SCHEMA[name].dtype)
            if dtype != want or any(d < 0 for d in declared) or not shape.fits(declared):
                raise RecordingError(
                    f"{self.path}: entry {name!r} is declared {dtype}{list(declared)}; this "
                    f"recording's header allows {want}{shape}"
                )
            return self._read(f, name, declared, fortran, dtype)

    def _read(
        self, f: IO[bytes], name: str, shape: tuple[int, ...], fortran: bool, dtype: np.dtype
    ) -> np.ndarray:
        nbytes = math.prod(shape) * dtype.itemsize
        if nbytes > self.budget:
            raise RecordingError(
                f"{self.path}: entry {name!r} of {nbytes} bytes exceeds what is left of the "
                f"bound on decompressed bytes ({self.budget})"
            )
        self.budget -= nbytes
        out = np.empty(shape, dtype=dtype, order="F" if fortran else "C")
        view = out.reshape(-1, order="A").view(np.uint8)  # (a view: out is contiguous)
        done = 0
        while done < nbytes:
            chunk = f.read(min(1 << 20, nbytes - done))
            if not chunk:
                raise RecordingError(f"{self.path}: entry {name!r} is truncated")
            view[done : done + len(chunk)] = np.frombuffer(chunk, np.uint8)
            done += len(chunk)
        if f.read(1):  # (reading to the end also checks the entry's CRC)
            raise RecordingError(f"{self.path}: entry {name!r} is longer than its shape")
        return out

    def _json(self, name: str, max_chars: int) -> Any:
        if name not in self.infos:
            raise RecordingError(f"{self.path}: missing entries {name}")
        f, shape, fortran, dtype = self._open(name)
        with f:
            if dtype.kind != "U" or shape != () or dtype.itemsize > 4 * max_chars:
                raise RecordingError(
                    f"{self.path}: entry {name!r} must be a JSON string of at most {max_chars} "
                    f"characters"
                )
            text = self._read(f, name, shape, fortran, dtype)
        try:
            return json.loads(str(text))
        except (ValueError, RecursionError) as exc:
            reason = getattr(exc, "msg", type(exc).__name__)
            raise RecordingError(
                f"{self.path}: entry {name!r} is not valid JSON ({reason})"
            ) from None


class _Shape:
    """The shapes an entry may declare: ``want`` (None: any length), its one length at most
    ``most``."""

    def __init__(self, want: tuple[int | None, ...], most: int | None = None) -> None:
        self.want, self.most = want, most

    def fits(self, s: tuple[int, ...]) -> bool:
        if len(s) != len(self.want):
            return False
        if self.most is not None and s[0] > self.most:
            return False
        return all(w is None or w == d for w, d in zip(self.want, s, strict=True))

    def __str__(self) -> str:
        if self.most is not None:
            return f"[<= {self.most}]"
        return str(["*" if w is None else w for w in self.want])


def _exactly(want: tuple[int | None, ...]) -> _Shape:
    return _Shape(want)


def _at_most(n: int) -> _Shape:
    return _Shape((None,), n)


def _nonneg_sum(a: np.ndarray, name: str, path: str) -> int:
    if a.size and a.min() < 0:
        raise RecordingError(f"{path}: {name} holds a negative length")
    return int(a.sum(dtype=np.int64))


# ------------------------------------------------------------------------------- the checks
def _check_header(header: Any, path: str) -> None:
    """The header's format, version and the types of the fields the reader and replay use; a
    version-1 header's scenario gets the wind model it was played with ("fresh") if it names none."""
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise RecordingError(f"{path}: not an fcplan recording (header.format is not {FORMAT!r})")
    version = header.get("format_version")
    if type(version) is not int or version not in READ_VERSIONS:
        raise RecordingError(
            f"{path}: header.format_version {version!r:.40} is not supported (this fcplan "
            f"reads versions {', '.join(map(str, READ_VERSIONS))})"
        )
    if not isinstance(header.get("scenario"), dict):
        raise RecordingError(f"{path}: header.scenario is missing or not a JSON object")
    fire = header["scenario"].get("fire")
    if version == 1 and isinstance(fire, dict):  # version 1's default wind model, said out loud
        fire.setdefault("wind_model", "fresh")
    checks = (
        ("seed", lambda v: v is None or (type(v) is int and v >= 0), "an integer >= 0 or null"),
        ("ticks", lambda v: v is None or (type(v) is int and v >= 0), "an integer >= 0"),
        ("source", lambda v: isinstance(v, str), "a string"),
        ("settings", lambda v: isinstance(v, dict), "a JSON object"),
    )
    for key, ok, what in checks:
        if key in header and not ok(header[key]):
            raise RecordingError(f"{path}: header.{key} must be {what}, got {header[key]!r:.40}")


def _scenario(header: dict[str, Any], path: str) -> Scenario:
    try:
        return Scenario.from_dict(header["scenario"], source="recording header")
    except FcplanError as exc:
        raise RecordingError(f"{path}: header.scenario: {exc}") from None
    except Exception as exc:  # a hostile scenario document must not escape as a traceback
        raise RecordingError(
            f"{path}: header.scenario: unreadable ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None


def _dims(header: dict[str, Any], sc: Scenario, t_n: int, path: str) -> dict[str, int]:
    """The axes the header fixes: T (checked against header.ticks and the scenario), N, F."""
    if (header_t := header.get("ticks")) is not None and header_t != t_n:
        raise RecordingError(f"{path}: header.ticks is {header_t} but 'active' has {t_n}")
    if t_n > sc.n_ticks:
        raise RecordingError(f"{path}: {t_n} ticks, more than the scenario's {sc.n_ticks}")
    return {"T": t_n, "N": len(sc.agents), "F": len(sc.scored_facilities)}


def _in(a: np.ndarray, lo: float, hi: float, nan_ok: bool = False) -> bool:
    ok = (a >= lo) & (a <= hi)
    return bool((ok | np.isnan(a)).all() if nan_ok else ok.all())


def _check_values(rec: Recording, sc: Scenario, dims: dict[str, int], path: str) -> None:
    """Cross-entry consistency and value ranges (so replay, metrics and video stay bounded)."""
    a, t_n, w = rec.arrays, dims["T"], sc.world_size
    for k in EVENTS:
        cells, count = a[f"{k}_cells"], a[f"{k}_count"]
        if int(count.sum(dtype=np.int64)) != len(cells) or (count < 0).any():
            raise RecordingError(f"{path}: {k}_count does not add up to len({k}_cells)")
        if cells.size and (cells.min() < 0 or cells.max() >= w * w):
            raise RecordingError(f"{path}: {k}_cells holds a cell outside 0..{w * w - 1}")
    if int(a["command_route_len"].sum(dtype=np.int64)) != len(a["command_route_xy"]):
        raise RecordingError(f"{path}: command_route_len does not add up to command_route_xy")
    if (a["command_route_len"] < 0).any():
        raise RecordingError(f"{path}: command_route_len holds a negative length")
    if dims["C"] and not _in(a["command_agent"], 0, dims["N"] - 1):
        raise RecordingError(f"{path}: command_agent holds a row outside 0..{dims['N'] - 1}")
    if len(rec.inputs) != dims["K"] or len(rec.replans) != dims["R"]:
        raise RecordingError(f"{path}: inputs/replans JSON lengths disagree with their tick arrays")
    ranges = (
        ("agent_xyz", -w, 2 * w, False, f"finite and within [-W, 2W] = [{-w}, {2 * w}] px"),
        ("command_route_xy", -w, 2 * w, False, f"finite and within [{-w}, {2 * w}] px"),
        ("command_altitude", -w, 2 * w, True, f"NaN or within [{-w}, {2 * w}]"),
        ("agent_battery", -1e12, 1e12, False, "finite"),
        ("replan_wall_s", 0.0, 1e9, True, "NaN or a duration >= 0"),
        ("agent_mode", 0, _MODES - 1, False, f"a mode 0..{_MODES - 1}"),
        ("agent_goal_index", -1, 2**15, False, ">= -1"),
        ("command_tick", 0, t_n, False, f"a tick in 0..{t_n}"),
        ("replan_tick", 0, t_n, False, f"a tick in 0..{t_n}"),
        ("input_tick", 0, t_n, False, f"a tick in 0..{t_n}"),
    )
    for name, lo, hi, nan_ok, what in ranges:
        if a[name].size and not _in(a[name], lo, hi, nan_ok):
            raise RecordingError(f"{path}: entry {name!r} holds values that are not {what}")
