"""Import games recorded by the original FireCommander GUI (its 13 ``.pkl`` files).

The 2020 GUI saved each game as 13 pickle files (FIRECOMMANDER.md section 7). Pickles can run
arbitrary code when loaded, so they are read here with :class:`RestrictedUnpickler`: it builds
lists, tuples, dicts, numbers and strings as usual and admits exactly the few numpy globals that
rebuild arrays, dtypes and numpy scalars; any other global (``os.system``, ``builtins.eval``, a
class) is refused with :class:`LegacyError` before it is looked up, so it is never executed.

:func:`import_legacy` converts a folder into an fcplan recording (:mod:`fcplan.recording`), so the
same replay, video and metrics tools work on old data:

* **Scenario** from ``Background_Info.pkl`` (``[environment_para, robo_team_para, set_loci,
  adv_setting, ...]``, section 3): map size, duration, fire regions (uniform or per-region
  settings), depot, facilities, lakes, team and per-agent parameters; ``Battery_Info.pkl`` gives the
  capacities when present. The pruning gate is marked ``reference`` (the 2020 rule).
* **Clock.** The GUI ran unthrottled frames against the wall clock (section 8); every event is put
  on fcplan's 10-Hz tick grid by its time: an event at ``ms`` lands in trace row
  ``ceil(ms / 100) - 1`` (the first row whose time is at or after it). Per-frame lists without a
  time (sensed maps) take the frame's time from ``Agent_Base_Loci.pkl`` (``floor(ms / 100)``).
* **Fire.** ``Fire_States.pkl`` rows ``[x, y, I, ms]``: a cell ignites at its first row.
  ``Pruned_Fire_Map.pkl`` entries ``[[x, y, I] rows, [ax, ay, ms]]``: a burning cell is pruned at
  its first such entry (later re-ignitions, a 2020 quirk, are dropped). ``Sensed_Fire_Map.pkl``:
  a cell counts as sensed at the first frame it is seen while burning (the GUI also "sensed" old
  trail and pruned cells). Counts, facility hits and the per-tick trace are derived from these
  events with fcplan's definitions, so both metric definitions apply.
* **Agents** from ``Agent_States.pkl`` (16 values per agent per frame; bit 7 is the time in ms):
  the latest state at or before each tick, ordered by time, which also absorbs the extra 16-tuples
  the GUI appended on agent-switch keys. Battery = capacity - 0.1 distance - 0.05 hover frames;
  move flag 1/0/2 -> active (idle when parked at its slot)/returning/homing; dumps counted from
  the prune entries.
* **Inputs** from ``User_Data.pkl`` (``[x, y, floor(ms / 100), action_type, goal_index]`` per agent):
  kept as the recording's input events. They cannot drive a re-simulation (no seed, and the GUI's
  physics differ), so a legacy recording has ``seed = None`` and no commands.

Examples
--------
>>> import io, pickle
>>> import numpy as np
>>> restricted_loads(pickle.dumps([1, "a", np.arange(3)]))[2].tolist()
[0, 1, 2]
>>> restricted_loads(pickle.dumps(print))
Traceback (most recent call last):
...
fcplan.legacy.LegacyError: <bytes>: refused to load builtins.print: legacy files may only hold lists, tuples, numbers, strings and numpy arrays
"""

from __future__ import annotations

import io
import os
import pickle
from typing import Any

import numpy as np

from fcplan.errors import FcplanError

__all__ = [
    "LEGACY_FILES",
    "LegacyError",
    "RestrictedUnpickler",
    "import_legacy",
    "restricted_load",
    "restricted_loads",
]

#: The 13 files the 2020 GUI wrote per game.
LEGACY_FILES = (
    "Background_Info.pkl",
    "Battery_Info.pkl",
    "User_Data.pkl",
    "Target_Loci.pkl",
    "Agent_Base_Loci.pkl",
    "Lake_info.pkl",
    "Fire_States.pkl",
    "Fire_Map.pkl",
    "Sensing_Data_CoM.pkl",
    "Sensed_Fire_Map.pkl",
    "Pruned_Fire_Map.pkl",
    "target_onFire_List.pkl",
    "Agent_States.pkl",
)
_REQUIRED = ("Background_Info.pkl", "Agent_States.pkl", "Fire_States.pkl")
_TPS = 10  # fcplan's tick rate for imported games


class LegacyError(FcplanError, ValueError):
    """A legacy file is unsafe, missing, or does not have the documented structure."""


def _numpy_globals() -> dict[tuple[str, str], Any]:
    """The only globals a pickle may name: what numpy arrays, dtypes and scalars need."""
    try:
        from numpy._core import multiarray
    except ImportError:  # pragma: no cover - numpy < 2
        from numpy.core import multiarray
    allowed: dict[tuple[str, str], Any] = {
        ("numpy", "ndarray"): np.ndarray,
        ("numpy", "dtype"): np.dtype,
        ("_codecs", "encode"): _latin1_encode,  # bytes in protocol-2 pickles
        ("builtins", "bytes"): _small_bytes,  # b"" in protocol-2 pickles
        ("__builtin__", "bytes"): _small_bytes,
    }
    for mod in ("numpy.core.multiarray", "numpy._core.multiarray"):
        allowed[(mod, "_reconstruct")] = multiarray._reconstruct
        allowed[(mod, "scalar")] = multiarray.scalar
    return allowed


def _latin1_encode(text: str, encoding: str = "latin1") -> bytes:
    if not isinstance(text, str) or encoding not in ("latin1", "latin-1"):
        raise pickle.UnpicklingError("_codecs.encode is only admitted for latin1 text")
    return text.encode("latin1")


def _small_bytes(*args: Any) -> bytes:
    if args:
        raise pickle.UnpicklingError("bytes() is only admitted without arguments")
    return b""


_ALLOWED = _numpy_globals()


class RestrictedUnpickler(pickle.Unpickler):
    """An unpickler that admits only lists, tuples, dicts, numbers, strings and numpy arrays.

    ``find_class`` is the only way a pickle reaches a callable; here it returns numpy's array,
    dtype and scalar reconstructors and refuses every other name (without importing it).
    Persistent ids are refused too.
    """

    source = "<bytes>"

    def find_class(self, module: str, name: str) -> Any:
        obj = _ALLOWED.get((module, name))
        if obj is None:
            raise LegacyError(
                f"{self.source}: refused to load {module}.{name}: legacy files may only hold "
                "lists, tuples, numbers, strings and numpy arrays"
            )
        return obj

    def persistent_load(self, pid: Any) -> Any:
        raise LegacyError(f"{self.source}: refused a persistent reference in the pickle")


def restricted_loads(data: bytes, source: str = "<bytes>") -> Any:
    """Unpickle ``data`` with :class:`RestrictedUnpickler`; refuse anything but plain data."""
    up = RestrictedUnpickler(io.BytesIO(data), encoding="latin1")
    up.source = source
    try:
        return up.load()
    except LegacyError:
        raise
    except Exception as exc:  # truncated or malformed pickles raise many types
        raise LegacyError(
            f"{source}: not a readable pickle ({type(exc).__name__}: {exc})"
        ) from None


def restricted_load(path: str | os.PathLike) -> Any:
    """Read one file with :func:`restricted_loads`."""
    from fcplan.recording import _read_bytes

    path = os.fspath(path)
    return restricted_loads(_read_bytes(path, LegacyError), source=path)


# ------------------------------------------------------------------------------------ scenario
def _per_agent(entries: Any, i: int, pair: bool = False) -> Any:
    """Agent ``i``'s value of an adv_setting entry: ``[[v]]`` (one for all) or ``[[v1], [v2]]``
    (per agent); altitude entries hold ``[lo, hi]`` pairs instead of ``[v]``."""
    seq = list(entries) if isinstance(entries, (list, tuple, np.ndarray)) else [entries]
    if not seq:
        raise ValueError("empty adv_setting entry")
    item = seq[min(i, len(seq) - 1)]
    if pair:
        return [float(v) for v in item]
    if isinstance(item, (list, tuple, np.ndarray)):
        return item[min(i, len(item) - 1)] if len(seq) == 1 else item[0]
    return item


def _num(x: Any, where: str) -> float:
    try:
        v = float(np.asarray(x).reshape(-1)[0]) if np.ndim(x) else float(x)
    except (TypeError, ValueError, IndexError):
        raise LegacyError(f"Background_Info.pkl: {where} must be a number, got {x!r}") from None
    return v


def scenario_dict_from_background(bg: Any, batteries: Any = None, name: str = "legacy") -> dict:
    """The fcplan scenario document for a ``Background_Info.pkl`` list (section 3 layout)."""
    try:
        env, team, loci, adv = bg[0], bg[1], bg[2], bg[3]
        world, duration = int(_num(env[0], "W")), _num(env[1], "duration")
        n_p, n_a, n_h = (int(_num(team[k], f"robo_team_para[{k}]")) for k in range(3))
        centres, fs, depot = loci[0], loci[1], loci[2]
        houses, hospitals, powers, lakes = loci[3], loci[4], loci[5], loci[6]
    except (IndexError, TypeError, KeyError) as exc:
        raise LegacyError(f"Background_Info.pkl: unexpected layout ({exc})") from None
    specific = int(_num(fs[9], "fire setting mode")) == 1

    def region_param(k: int, r: int) -> float:
        v = fs[k]
        return _num(v[r] if specific and isinstance(v, (list, tuple)) else v, f"fire setting {k}")

    regions = [
        {
            "center": [float(c[0]), float(c[1])],
            "fronts": max(1, int(region_param(0, r))),
            "delay_s": region_param(1, r),
            "fuel": region_param(2, r),
            "wind_speed": region_param(3, r),
            "wind_dir_deg": region_param(4, r),
        }
        for r, c in enumerate(centres)
    ]
    facilities = [
        {"kind": kind, "center": [float(c[0]), float(c[1])]}
        for kind, group in (("house", houses), ("hospital", hospitals), ("power_station", powers))
        for c in group
    ]
    a_conf, h_conf = _num(fs[7], "action confidence"), _num(fs[8], "hybrid confidence")

    def role(count, alt_k, batt_k, speed_k, tank_k, offset, conf) -> dict:
        out: dict[str, Any] = {"count": count}
        idx = range(count)
        if alt_k is not None:
            out["altitude"] = [_per_agent(adv[alt_k], i, pair=True) for i in idx]
        bats = [_per_agent(adv[batt_k], i) for i in idx]
        if batteries is not None:
            bats = [batteries[offset + i][0] for i in idx]
        out["battery"] = [float(b) for b in bats]
        out["speed"] = [float(_per_agent(adv[speed_k], i)) for i in idx]
        if tank_k is not None:
            out["tank"] = [int(_per_agent(adv[tank_k], i)) for i in idx]
            out["prune_confidence"] = conf / 100.0
        return out

    try:
        team_doc = {
            "perception": role(n_p, 0, 2, 5, None, 0, None),
            "action": role(n_a, None, 3, 6, 8, n_p, a_conf),
        }
        if n_h:
            team_doc["hybrid"] = role(n_h, 1, 4, 7, 9, n_p + n_a, h_conf)
    except (IndexError, TypeError, ValueError) as exc:
        raise LegacyError(
            f"Background_Info.pkl: adv_setting has an unexpected layout ({exc})"
        ) from None
    return {
        "name": name,
        "difficulty": "custom",
        "world_size": world,
        "duration_s": duration,
        "notes": ["Imported from a FireCommander 2020 GUI recording (fcplan import-legacy)."],
        "fire": {
            "mode": "specific" if specific else "uniform",
            "action_gate": "reference",
            "regions": regions,
        },
        "scoring": {
            "propagation_weight": _num(fs[6], "propagation weight"),
            "temporal_exponent": _num(fs[5], "temporal exponent"),
        },
        "depot": {
            "center": [float(depot[0][0]), float(depot[0][1])],
            "orientation": "vertical" if int(_num(depot[1], "depot orientation")) else "horizontal",
        },
        "facilities": facilities,
        "lakes": [{"center": [float(c[0]), float(c[1])]} for c in lakes],
        "team": team_doc,
    }


# ------------------------------------------------------------------------------------ convert
def _row_of_ms(ms: np.ndarray, n_ticks: int) -> np.ndarray:
    """Trace row of an event at ``ms``: the first row whose time (``(k + 1) / 10`` s) is at or
    after it, clipped to the episode."""
    row = np.ceil(np.asarray(ms, dtype=np.float64) / (1000 / _TPS)).astype(np.int64) - 1
    return np.clip(row, 0, n_ticks - 1)


def _rows(x: Any, width: int, where: str) -> np.ndarray:
    """A list of rows (or an array) as an (n, width) float array; [] gives (0, width)."""
    if x is None or (isinstance(x, (list, tuple)) and len(x) == 0):
        return np.zeros((0, width))
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise LegacyError(f"{where}: expected rows of {width} numbers") from None
    if a.size == 0:
        return np.zeros((0, width))
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.ndim != 2 or a.shape[1] < width:
        raise LegacyError(f"{where}: expected rows of {width} numbers, got shape {a.shape}")
    return a[:, :width]


def _first_events(cells: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Earliest row per distinct cell."""
    if cells.size == 0:
        return cells.astype(np.int64), rows.astype(np.int64)
    order = np.lexsort((rows, cells))
    cells, rows = cells[order], rows[order]
    first = np.ones(cells.size, dtype=bool)
    first[1:] = cells[1:] != cells[:-1]
    return cells[first], rows[first]


def import_legacy(folder: str | os.PathLike):
    """Convert a folder of the 2020 GUI's ``.pkl`` files into a :class:`fcplan.recording.Recording`.

    Every file present is read with the restricted unpickler (so a malicious file is refused even
    if its content is not needed). ``Background_Info.pkl``, ``Agent_States.pkl`` and
    ``Fire_States.pkl`` are required.

    Raises
    ------
    LegacyError
        Unsafe, missing or malformed files (the message names the file).
    """
    from fcplan.recording import FORMAT, FORMAT_VERSION, Recording, _cast, _versions
    from fcplan.scenario import Scenario
    from fcplan.world import World

    folder = os.fspath(folder)
    if not os.path.isdir(folder):
        raise LegacyError(f"{folder}: not a folder")
    present = [f for f in LEGACY_FILES if os.path.isfile(os.path.join(folder, f))]
    missing = [f for f in _REQUIRED if f not in present]
    if missing:
        raise LegacyError(
            f"{folder}: missing {', '.join(missing)} (not a FireCommander recording?)"
        )
    data = {f: restricted_load(os.path.join(folder, f)) for f in present}
    name = os.path.basename(os.path.normpath(folder)) or "legacy"
    doc = scenario_dict_from_background(
        data["Background_Info.pkl"], data.get("Battery_Info.pkl"), name=f"legacy {name}"
    )
    try:
        sc = Scenario.from_dict(doc, source=os.path.join(folder, "Background_Info.pkl"))
    except FcplanError as exc:
        raise LegacyError(str(exc)) from None
    t_n = sc.n_ticks
    w = sc.world_size
    n = len(sc.agents)
    world = World().reset(sc, 0)  # for the facility footprints only

    # frame clock (ms per frame index) from the depot's per-frame entries
    clock = None
    if "Agent_Base_Loci.pkl" in data:
        base = data["Agent_Base_Loci.pkl"]
        try:
            clock = _rows(base[0], 7, "Agent_Base_Loci.pkl")[:, 6] * 100.0
        except (IndexError, TypeError):
            raise LegacyError("Agent_Base_Loci.pkl: expected per depot a list of frames") from None

    # ignitions
    ig_cells, ig_rows = [], []
    for r, region in enumerate(data["Fire_States.pkl"]):
        a = _rows(region, 4, f"Fire_States.pkl region {r}")
        x, y = np.floor(a[:, 0]).astype(np.int64), np.floor(a[:, 1]).astype(np.int64)
        ok = (x >= 0) & (x < w) & (y >= 0) & (y < w)
        ig_cells.append(x[ok] * w + y[ok])
        ig_rows.append(_row_of_ms(a[ok, 3], t_n))
    ign_c, ign_r = _first_events(np.concatenate(ig_cells), np.concatenate(ig_rows))
    ign_row = np.full(w * w, np.iinfo(np.int64).max, dtype=np.int64)
    ign_row[ign_c] = ign_r

    # prunes (and dumps per action/hybrid agent)
    actors = [i for i, a in enumerate(sc.agents) if a.role.can_act]
    dump_rows: list[list[int]] = [[] for _ in range(n)]
    pr_cells, pr_rows = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for k, entries in enumerate(data.get("Pruned_Fire_Map.pkl", [])):
        if k >= len(actors):
            raise LegacyError(f"Pruned_Fire_Map.pkl: entry {k} but only {len(actors)} A/H agents")
        for e in entries:
            if e is None or len(e) < 2:
                continue
            cells = _rows(e[0], 3, "Pruned_Fire_Map.pkl")
            info = _rows(e[1], 3, "Pruned_Fire_Map.pkl")
            row = int(_row_of_ms(info[0, 2], t_n))
            dump_rows[actors[k]].append(row)
            x, y = np.floor(cells[:, 0]).astype(np.int64), np.floor(cells[:, 1]).astype(np.int64)
            ok = (x >= 0) & (x < w) & (y >= 0) & (y < w)
            pr_cells.append(x[ok] * w + y[ok])
            pr_rows.append(np.full(int(ok.sum()), row, dtype=np.int64))
    pc, prow = np.concatenate(pr_cells), np.concatenate(pr_rows)
    keep = prow >= ign_row[pc]  # only cells burning by then
    pru_c, pru_r = _first_events(pc[keep], prow[keep])
    prune_row = np.full(w * w, np.iinfo(np.int64).max, dtype=np.int64)
    prune_row[pru_c] = pru_r

    # first sensing of each burning cell
    sensors = [i for i, a in enumerate(sc.agents) if a.role.can_sense]
    se_cells, se_rows = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    sensed_maps = data.get("Sensed_Fire_Map.pkl", [])
    if len(sensed_maps) and clock is None:
        raise LegacyError("Sensed_Fire_Map.pkl needs Agent_Base_Loci.pkl for the frame times")
    for k, frames in enumerate(sensed_maps):
        if k >= len(sensors):
            raise LegacyError(f"Sensed_Fire_Map.pkl: entry {k} but only {len(sensors)} P/H agents")
        for j, fr in enumerate(frames):
            a = _rows(fr, 2, "Sensed_Fire_Map.pkl")
            if a.shape[0] == 0:
                continue
            ms = clock[min(j, len(clock) - 1)] if len(clock) else 0.0
            x, y = np.floor(a[:, 0]).astype(np.int64), np.floor(a[:, 1]).astype(np.int64)
            ok = (x >= 0) & (x < w) & (y >= 0) & (y < w)
            se_cells.append(x[ok] * w + y[ok])
            se_rows.append(np.full(int(ok.sum()), int(_row_of_ms(ms, t_n)), dtype=np.int64))
    sc_, sr_ = np.concatenate(se_cells), np.concatenate(se_rows)
    keep = (sr_ >= ign_row[sc_]) & (sr_ <= prune_row[sc_])
    sen_c, sen_r = _first_events(sc_[keep], sr_[keep])

    arrays: dict[str, np.ndarray] = {}
    for kind, cells, rows in (
        ("ignited", ign_c, ign_r),
        ("sensed", sen_c, sen_r),
        ("pruned", pru_c, pru_r),
    ):
        order = np.lexsort((cells, rows))
        arrays[f"{kind}_cells"] = cells[order]
        arrays[f"{kind}_count"] = np.bincount(rows, minlength=t_n)[:t_n]
    ic, pcn, scn = (np.cumsum(arrays[f"{k}_count"]) for k in ("ignited", "pruned", "sensed"))
    sensed_then_pruned = np.bincount(prune_row[sen_c][prune_row[sen_c] < t_n], minlength=t_n)
    arrays["active"] = ic - pcn
    arrays["pruned"] = pcn
    arrays["sensed_ever"] = scn
    arrays["sensed_active"] = scn - np.cumsum(sensed_then_pruned[:t_n])
    f_n = world.n_facilities
    lab = world.facility_labels.reshape(-1)
    fb = np.zeros((t_n, f_n), np.int64)
    fp = np.zeros((t_n, f_n), np.int64)
    if f_n:
        li = lab[ign_c]
        np.add.at(fb, (ign_r[li >= 0], li[li >= 0]), 1)
        lp = lab[pru_c]
        np.add.at(fb, (pru_r[lp >= 0], lp[lp >= 0]), -1)
        np.add.at(fp, (pru_r[lp >= 0], lp[lp >= 0]), 1)
    arrays["facility_burning"] = np.cumsum(fb, axis=0)
    arrays["facility_pruned"] = np.cumsum(fp, axis=0)
    arrays.update(_agent_arrays(data["Agent_States.pkl"], sc, world, dump_rows))
    arrays.update(
        command_tick=np.zeros(0),
        command_agent=np.zeros(0),
        command_flags=np.zeros(0),
        command_altitude=np.zeros(0),
        command_route_len=np.zeros(0),
        command_route_xy=np.zeros((0, 2)),
        replan_tick=np.zeros(0),
        replan_wall_s=np.zeros(0),
    )
    inputs, input_ticks = _inputs(data.get("User_Data.pkl", []), sc, t_n)
    arrays["input_tick"] = np.asarray(input_ticks, dtype=np.int64)
    header = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "scenario": sc.to_dict(),
        "seed": None,
        "source": "legacy",
        "settings": {
            "legacy_folder": name,
            "files": present,
            "frames": None if clock is None else int(len(clock)),
        },
        "ticks": t_n,
        "versions": _versions(),
    }
    return Recording(header, _cast(arrays), [], inputs)


#: GUI move flag 0 / 1 / 2 -> fcplan.team.Mode returning / active / homing
_MODE_OF_FLAG = np.array([2, 1, 3], dtype=np.int64)


def _agent_arrays(states: Any, sc, world, dump_rows) -> dict[str, np.ndarray]:
    t_n, n = sc.n_ticks, len(sc.agents)
    if len(states) != n:
        raise LegacyError(f"Agent_States.pkl: {len(states)} agents, the scenario has {n}")
    tick_ms = (np.arange(t_n) + 1) * (1000.0 / _TPS)
    xyz = np.zeros((t_n, n, 3))
    battery = np.zeros((t_n, n))
    tank = np.zeros((t_n, n), np.int64)
    mode = np.zeros((t_n, n), np.int64)
    cap = world.team.battery_capacity
    home = world.team.home
    for i, flat in enumerate(states):
        a = np.asarray(flat, dtype=np.float64).reshape(-1)
        if a.size == 0 or a.size % 16:
            raise LegacyError(
                f"Agent_States.pkl: agent {i} holds {a.size} values, not 16 per frame"
            )
        a = a.reshape(-1, 16)
        a = a[np.argsort(a[:, 7], kind="stable")]
        k = np.clip(np.searchsorted(a[:, 7], tick_ms, side="right") - 1, 0, len(a) - 1)
        s = a[k]
        xyz[:, i] = s[:, 0:3]
        battery[:, i] = np.maximum(cap[i] - 0.1 * s[:, 10] - 0.05 * s[:, 11], 0.0)
        tank[:, i] = s[:, 12] if sc.agents[i].role.can_act else 0
        m = _MODE_OF_FLAG[np.clip(s[:, 13].astype(np.int64), 0, 2)]
        parked = (m == 1) & np.all(s[:, 0:2] == home[i], axis=1)
        mode[:, i] = np.where(parked, 0, m)
    dumps = np.zeros((t_n, n), np.int64)
    for i, rows in enumerate(dump_rows):
        if rows:
            dumps[:, i] = np.cumsum(np.bincount(rows, minlength=t_n)[:t_n])
    return {
        "agent_xyz": xyz,
        "agent_battery": battery,
        "agent_tank": tank,
        "agent_mode": mode,
        "agent_dumps": dumps,
        "agent_goal_index": np.full((t_n, n), -1),
    }


_ACTIONS = {0: "click", 1: "up", -1: "down"}


def _inputs(user_data: Any, sc, t_n: int) -> tuple[list[dict], list[int]]:
    events = []
    ids = [a.id for a in sc.agents]
    for i, rows in enumerate(user_data):
        a = _rows(rows, 5, "User_Data.pkl")
        for x, y, ds, kind, goal in a:
            events.append(
                {
                    "agent": ids[i] if i < len(ids) else str(i),
                    "action": _ACTIONS.get(int(kind), str(int(kind))),
                    "x": float(x),
                    "y": float(y),
                    "time_s": float(ds) / 10.0,
                    "goal_index": int(goal),
                }
            )
    events.sort(key=lambda e: e["time_s"])  # stable: per-agent order kept at equal times
    ticks = [int(_row_of_ms(e["time_s"] * 1000.0, t_n)) for e in events]
    return events, ticks


def add_parser(sub) -> None:
    """Add ``fcplan import-legacy``."""
    p = sub.add_parser(
        "import-legacy", help="convert a FireCommander 2020 GUI recording (13 .pkl files)"
    )
    p.add_argument("folder", help="folder holding Background_Info.pkl, Agent_States.pkl, ...")
    p.add_argument("--out", metavar="PATH", help="recording to write (default ./<folder>.npz)")
    p.set_defaults(run=_run)


def _run(args) -> int:
    from fcplan.cliutil import check_output
    from fcplan.metrics import format_metrics

    out = args.out or f"{os.path.basename(os.path.normpath(args.folder)) or 'legacy'}.npz"
    check_output(out, "--out")
    rec = import_legacy(args.folder)
    rec.save(out)
    a = rec.arrays
    print(
        f"wrote {out}: {rec.n_ticks} ticks ({rec.n_ticks / _TPS:g} s), {len(rec.scenario.agents)} "
        f"agents, {len(a['ignited_cells'])} cells burned, {len(a['pruned_cells'])} pruned, "
        f"{len(rec.inputs)} inputs"
    )
    print()
    print(format_metrics(rec.metrics()))
    return 0
